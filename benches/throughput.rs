//! Throughput benchmarks (a benchmark, never a test): `cargo bench --bench throughput`.
//!
//! 1. Camera paths/s: the Cornell box, 256x256, up to 8 bounces, NEE + MIS,
//!    independent sampler, with 1 and 2 threads (median of 5 renders).
//! 2. Incoherent closest-hit and any-hit rays/s on UV spheres of about 100k
//!    and 1M triangles (CWBVH), 1 and 2 threads: rays start on a sphere of
//!    radius 2 around the mesh and aim at uniform points inside the unit
//!    ball, so neighbouring rays share nothing.
//! 3. The same on the Cornell box, with its 8-wide triangle soup and with a BVH.
//! 4. Coherent rays (one origin, a scanline grid of directions) on the spheres.

mod shared;

use glam::{Vec2, Vec3A};
use rayon::prelude::*;
use shared::{coherent_rays, uv_sphere};
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tracelab::accel::{AccelChoice, Geometry, TriangleInput};
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::math::Ray;
use tracelab::render::{RenderSettings, Session};
use tracelab::sampling::SamplerKind;
use tracelab::sampling::hash::{hash_combine, to_unit_float};
use tracelab::sampling::warp::square_to_uniform_sphere;
use tracelab::scene::Scene;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// `general`: force the general path loop instead of the one specialised for
/// the Cornell box (Lambertian only, no specular surfaces).
fn paths_per_second_with(threads: usize, general: bool) -> f64 {
    median(path_runs(threads, general))
}

/// Paths/s of 5 renders of 32 spp each, in run order.
fn path_runs(threads: usize, general: bool) -> Vec<f64> {
    let scene = Arc::new(
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml"))
            .unwrap(),
    );
    (0..5)
        .map(|seed| {
            let settings = RenderSettings {
                integrator: Integrator::from(PathTracer {
                    general,
                    ..PathTracer::default()
                }),
                sampler: SamplerKind::Independent,
                seed,
                planned_spp: 32,
                threads,
                adaptive: None,
                domains: Default::default(),
                clamp: None,
                filter_sampling: Default::default(),
            };
            let session = Session::new(scene.clone(), settings).unwrap();
            for _ in 0..4 {
                session.render_pass(8);
            }
            let stats = session.stats();
            stats.samples as f64 / stats.render_time.as_secs_f64()
        })
        .collect()
}

fn incoherent_rays(count: u64, radius: f32, center: Vec3A, spread: f32) -> Vec<Ray> {
    (0..count)
        .map(|i| {
            let u = |k| to_unit_float(hash_combine(k, i));
            let origin = center + radius * square_to_uniform_sphere(Vec2::new(u(1), u(2)));
            let target =
                center + spread * u(5).cbrt() * square_to_uniform_sphere(Vec2::new(u(3), u(4)));
            Ray::new(origin, (target - origin).normalize())
        })
        .collect()
}

fn rays_per_second(rays: &[Ray], threads: usize, trace: impl Fn(&Ray) -> bool + Sync) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let runs = (0..3)
        .map(|_| {
            let start = Instant::now();
            let hits: usize = pool.install(|| {
                rays.par_chunks(4096)
                    .map(|c| c.iter().filter(|r| trace(r)).count())
                    .sum()
            });
            std::hint::black_box(hits);
            rays.len() as f64 / start.elapsed().as_secs_f64()
        })
        .collect();
    median(runs)
}

fn report_geometry(name: &str, geometry: &Geometry, rays: &[Ray], build: Duration) {
    for threads in [1, 2] {
        let closest = rays_per_second(rays, threads, |r| geometry.intersect(r).is_some());
        let any = rays_per_second(rays, threads, |r| geometry.occluded(r));
        println!(
            "{name:<34} {threads} thread(s): closest hit {:6.2} M rays/s, any hit {:6.2} M rays/s (build {:.0} ms)",
            closest * 1e-6,
            any * 1e-6,
            build.as_secs_f64() * 1e3
        );
    }
}

fn main() {
    // `cargo bench --bench throughput -- NAME` runs the sections whose name
    // contains NAME: paths, specialisation, rays.
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let wanted = |section: &str| filter.is_empty() || filter.iter().any(|f| section.contains(f));
    println!(
        "machine: {} logical CPUs",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    if wanted("paths") {
        paths();
    }
    if wanted("specialisation") {
        specialisation();
    }
    if wanted("rays") {
        rays();
    }
}

/// The median with the range of the runs beside it: on a shared machine
/// single renders scatter by 5-10%, and the range says how much.
fn paths() {
    for threads in [1, 2] {
        let mut runs = path_runs(threads, false);
        runs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!(
            "Cornell box 256x256, path tracing (8 bounces, NEE+MIS), {threads} thread(s): {:.3} M paths/s (median of {}; range {:.3}-{:.3})",
            median(runs.clone()) * 1e-6,
            runs.len(),
            runs[0] * 1e-6,
            runs[runs.len() - 1] * 1e-6
        );
    }
}

/// The loop specialised for the Cornell box against the general one, in
/// interleaved runs so that drift hits both alike; each run is itself the
/// median of 5 renders.
fn specialisation() {
    let (mut special, mut general) = (Vec::new(), Vec::new());
    for _ in 0..7 {
        special.push(paths_per_second_with(2, false));
        general.push(paths_per_second_with(2, true));
    }
    let ratios: Vec<f64> = special.iter().zip(&general).map(|(s, g)| s / g).collect();
    let (special, general) = (median(special), median(general));
    println!(
        "Cornell box, 2 threads: specialised loop {:.3} M paths/s, general loop {:.3} M paths/s ({:+.1}%; per-pair ratios {})",
        special * 1e-6,
        general * 1e-6,
        100.0 * (special / general - 1.0),
        ratios
            .iter()
            .map(|r| format!("{:+.1}%", 100.0 * (r - 1.0)))
            .collect::<Vec<_>>()
            .join(" ")
    );
}

fn rays() {
    let cornell =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml"))
            .unwrap();
    let cornell_tris: Vec<TriangleInput> = (0..cornell.geometry.triangle_count())
        .map(|i| TriangleInput {
            vertices: cornell.geometry.triangles()[i],
            material: 0,
            uvs: None,
            normals: None,
        })
        .collect();
    let rays = incoherent_rays(2_000_000, 250.0, Vec3A::new(278.0, 274.0, 280.0), 250.0);
    for (name, choice) in [
        ("Cornell box (32 tris), soup", AccelChoice::Soup),
        ("Cornell box (32 tris), 8-wide BVH", AccelChoice::Bvh),
    ] {
        let start = Instant::now();
        let g = Geometry::build_with(&cornell_tris, vec![], choice);
        report_geometry(name, &g, &rays, start.elapsed());
    }
    for n in [224, 708] {
        let triangles = uv_sphere(n);
        let start = Instant::now();
        let g = Geometry::build_with(&triangles, vec![], AccelChoice::Bvh);
        let build = start.elapsed();
        let rays = incoherent_rays(2_000_000, 2.0, Vec3A::ZERO, 1.0);
        report_geometry(
            &format!("UV sphere ({} tris), incoherent", triangles.len()),
            &g,
            &rays,
            build,
        );
        let rays = coherent_rays(1414);
        report_geometry(
            &format!("UV sphere ({} tris), coherent", triangles.len()),
            &g,
            &rays,
            build,
        );
    }
}
