//! Micro benchmarks (divan): `cargo bench --bench micro`. A benchmark, never
//! a test. BVH build over 10k, 100k and 1M triangles; closest-hit and
//! any-hit rays, coherent and incoherent, on the 100k mesh; BSDF sampling;
//! sample generation by each sampler.

mod shared;

use divan::{Bencher, black_box};
use glam::{Vec2, Vec3A};
use shared::{coherent_rays, incoherent_rays, unit, uv_sphere};
use tracelab::accel::{AccelChoice, Geometry};
use tracelab::math::{Ray, Rgb};
use tracelab::sampling::{Sampler, SamplerKind};
use tracelab::scene::material::Bsdf;

fn main() {
    divan::main();
}

#[divan::bench(args = [71, 224, 708], sample_count = 5)]
fn bvh_build(bencher: Bencher, n: usize) {
    let triangles = uv_sphere(n);
    bencher
        .counter(divan::counter::ItemsCount::new(triangles.len()))
        .bench(|| Geometry::build_with(black_box(&triangles), vec![], AccelChoice::Bvh));
}

mod rays_100k {
    use super::*;
    use std::sync::LazyLock;

    static MESH: LazyLock<Geometry> =
        LazyLock::new(|| Geometry::build_with(&uv_sphere(224), vec![], AccelChoice::Bvh));
    static INCOHERENT: LazyLock<Vec<Ray>> = LazyLock::new(|| incoherent_rays(100_000));
    static COHERENT: LazyLock<Vec<Ray>> = LazyLock::new(|| coherent_rays(316));

    fn run(bencher: Bencher, rays: &[Ray], any: bool) {
        let mesh = &*MESH;
        bencher
            .counter(divan::counter::ItemsCount::new(rays.len()))
            .bench(|| {
                let mut hits = 0usize;
                for r in rays {
                    hits += usize::from(if any {
                        mesh.occluded(r)
                    } else {
                        mesh.intersect(r).is_some()
                    });
                }
                hits
            });
    }

    #[divan::bench(sample_count = 10)]
    fn closest_incoherent(bencher: Bencher) {
        run(bencher, &INCOHERENT, false);
    }

    #[divan::bench(sample_count = 10)]
    fn any_incoherent(bencher: Bencher) {
        run(bencher, &INCOHERENT, true);
    }

    #[divan::bench(sample_count = 10)]
    fn closest_coherent(bencher: Bencher) {
        run(bencher, &COHERENT, false);
    }

    #[divan::bench(sample_count = 10)]
    fn any_coherent(bencher: Bencher) {
        run(bencher, &COHERENT, true);
    }
}

#[divan::bench(args = ["diffuse", "glossy", "mirror", "dielectric"])]
fn bsdf_sample(bencher: Bencher, kind: &str) {
    let bsdf = match kind {
        "diffuse" => Bsdf::Diffuse {
            albedo: Rgb::splat(0.5),
        },
        "glossy" => Bsdf::glossy(Rgb::splat(0.3), Rgb::splat(0.5), 50.0),
        "mirror" => Bsdf::Mirror {
            reflectance: Rgb::ONE,
        },
        _ => Bsdf::Dielectric {
            eta: 1.5,
            tint: Rgb::ONE,
        },
    };
    let wo = Vec3A::new(0.3, 0.2, 0.9).normalize();
    let inputs: Vec<(f32, Vec2)> = (0..1024u64).map(|i| (unit(i, 7).x, unit(i, 8))).collect();
    bencher
        .counter(divan::counter::ItemsCount::new(inputs.len()))
        .bench(|| {
            let mut pdf = 0.0;
            for &(u_lobe, u) in &inputs {
                if let Some(s) = bsdf.sample(black_box(wo), u_lobe, u) {
                    pdf += s.pdf;
                }
            }
            pdf
        });
}

#[divan::bench(args = [SamplerKind::Independent, SamplerKind::Stratified, SamplerKind::MultiJittered, SamplerKind::Sobol])]
fn sampler_2d(bencher: Bencher, kind: SamplerKind) {
    let mut sampler = Sampler::new(kind, 7, 64);
    bencher
        .counter(divan::counter::ItemsCount::new(64usize * 16))
        .bench_local(|| {
            let mut sum = Vec2::ZERO;
            for s in 0..64 {
                sampler.start(12_345, s);
                for _ in 0..16 {
                    sum += sampler.next_2d();
                }
            }
            sum
        });
}

/// One environment sample and its irradiance term on an upward plane, under
/// the tests' sky (its sun 800 times the sky): by the map's density, and by
/// uniform directions. With the variance per sample that
/// `tests/materials.rs` reports, the cost per sample gives the error at
/// equal time (`docs/performance.md`).
#[divan::bench(args = ["importance", "uniform"])]
fn environment_sample(bencher: Bencher, kind: &str) {
    use tracelab::scene::environment::{Environment, Radiance};
    use tracelab::texture::Bitmap;
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/materials/sky.exr");
    let sky = std::sync::Arc::new(Bitmap::read(&path, false).expect("the tests' sky"));
    let mut env = Environment::new(Radiance::Map(sky), 1.0, glam::Mat3A::IDENTITY);
    if kind == "uniform" {
        env = env.with_uniform_sampling();
    }
    let us: Vec<Vec2> = (0..1024u64).map(|i| unit(i, 0x5eed)).collect();
    bencher
        .counter(divan::counter::ItemsCount::new(us.len()))
        .bench_local(|| {
            let mut sum = 0.0f32;
            for &u in &us {
                if let Some((d, le, pdf)) = env.sample(black_box(u)) {
                    sum += le.x * d.y.max(0.0) / pdf;
                }
            }
            sum
        });
}
