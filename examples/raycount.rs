use glam::Vec3A;
use tracelab::math::Ray;
use tracelab::sampling::hash::{hash_combine, to_unit_float};
use tracelab::scene::Scene;
fn main() {
    let scene = Scene::load(std::path::Path::new("scenes/cornell_box.toml")).unwrap();
    let n = 2_000_000u64;
    let mut rays = Vec::new();
    for i in 0..n {
        let o = Vec3A::new(50.0 + 450.0 * to_unit_float(hash_combine(1, i)), 10.0 + 500.0 * to_unit_float(hash_combine(2, i)), 10.0 + 500.0 * to_unit_float(hash_combine(3, i)));
        let d = tracelab::sampling::warp::square_to_uniform_sphere(glam::Vec2::new(to_unit_float(hash_combine(4, i)), to_unit_float(hash_combine(5, i))));
        rays.push(Ray::new(o, d));
    }
    let t = std::time::Instant::now();
    let mut hits = 0;
    for r in &rays { if scene.geometry.intersect(r).is_some() { hits += 1; } }
    let dt = t.elapsed().as_secs_f64();
    println!("closest: {:.2} Mrays/s hits {} tests/ray {}", n as f64 / dt * 1e-6, hits, 0);
    let t = std::time::Instant::now();
    let mut occ = 0;
    for r in &rays { if scene.geometry.occluded(&Ray { t_max: 100.0, ..*r }) { occ += 1; } }
    let dt = t.elapsed().as_secs_f64();
    println!("occluded: {:.2} Mrays/s occ {}", n as f64 / dt * 1e-6, occ);
}
