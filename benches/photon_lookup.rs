//! Photon lookups (divan): `cargo bench --bench photon_lookup`. The photon
//! mappers' hash grid (`src/integrator/photon_map.rs`) against a k-d tree
//! from a well-kept crate (kiddo's `ImmutableKdTree`), on what an iteration
//! of tracelab's photon mappers does with the Cornell box: build a map of
//! the photons that landed, then look up the photons within the radius
//! (SPPM) or the k nearest within it (Jensen's method) at points where
//! camera paths land. The query points are a second, independent photon
//! shoot's landing points: they lie on the same surfaces, denser where the
//! light is. A benchmark, never a test; results in `docs/performance.md`.

use divan::{Bencher, black_box};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZero;
use std::path::Path;
use std::sync::LazyLock;
use tracelab::integrator::RayCounts;
use tracelab::integrator::photon_map::{self, MAX_K, Photon, PhotonMap, Side};
use tracelab::math::Rgb;
use tracelab::scene::Scene;

fn main() {
    divan::main();
}

/// Photons per iteration (SPPM's default at 256 x 256 is one per pixel).
const PHOTONS: u32 = 65_536;
/// Jensen's k.
const K: usize = 50;

struct Setup {
    photons: Vec<Photon>,
    queries: Vec<Photon>,
    radius: f32,
}

static SETUP: LazyLock<Setup> = LazyLock::new(|| {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml");
    let scene = Scene::load(&path).expect("the Cornell box loads");
    let mut counts = RayCounts::default();
    let mut shoot =
        |key| photon_map::shoot(&scene, PHOTONS, key, 8, |_| (true, false), &mut counts).0;
    Setup {
        photons: shoot(1),
        queries: shoot(2),
        // SPPM's first radius (0.002 of the diagonal) and a 4x larger one,
        // where a query finds about 16x the photons.
        radius: photon_map::of_diagonal(&scene, 0.002),
    }
});

fn points(photons: &[Photon]) -> Vec<[f32; 3]> {
    photons.iter().map(|p| p.point.to_array()).collect()
}

fn tree(photons: &[Photon]) -> ImmutableKdTree<f32, 3> {
    ImmutableKdTree::new_from_slice(&points(photons)).expect("a tree of the photons")
}

#[divan::bench(sample_count = 10)]
fn build_hash_grid(bencher: Bencher) {
    let setup = &*SETUP;
    bencher
        .counter(divan::counter::ItemsCount::new(setup.photons.len()))
        .bench(|| PhotonMap::build(black_box(setup.photons.clone()), setup.radius));
}

#[divan::bench(sample_count = 10)]
fn build_kiddo(bencher: Bencher) {
    let setup = &*SETUP;
    bencher
        .counter(divan::counter::ItemsCount::new(setup.photons.len()))
        .bench(|| tree(black_box(&setup.photons)));
}

/// The flux within `scale` x the radius of every query point, photons on the
/// query's side of the surface only: SPPM's density estimate.
#[divan::bench(args = [1.0, 4.0], sample_count = 10)]
fn radius_hash_grid(bencher: Bencher, scale: f32) {
    let setup = &*SETUP;
    let map = PhotonMap::build(setup.photons.clone(), setup.radius * scale);
    bencher
        .counter(divan::counter::ItemsCount::new(setup.queries.len()))
        .bench(|| {
            let mut flux = Rgb::ZERO;
            for q in &setup.queries {
                map.for_each_near(q.point, Side::Facing(q.normal), |p| flux += p.power);
            }
            flux
        });
}

#[divan::bench(args = [1.0, 4.0], sample_count = 10)]
fn radius_kiddo(bencher: Bencher, scale: f32) {
    let setup = &*SETUP;
    let tree = tree(&setup.photons);
    let r2 = (setup.radius * scale).powi(2);
    bencher
        .counter(divan::counter::ItemsCount::new(setup.queries.len()))
        .bench(|| {
            let mut flux = Rgb::ZERO;
            for q in &setup.queries {
                let found = tree
                    .query(&q.point.to_array())
                    .within::<SquaredEuclidean<f32>>(r2)
                    .unsorted()
                    .execute();
                for found in found {
                    let p = &setup.photons[found.item as usize];
                    if p.normal.dot(q.normal) > 0.0 {
                        flux += p.power;
                    }
                }
            }
            flux
        });
}

/// The k nearest photons within 4 x the radius: Jensen's lookup.
#[divan::bench(sample_count = 10)]
fn nearest_hash_grid(bencher: Bencher) {
    let setup = &*SETUP;
    let map = PhotonMap::build(setup.photons.clone(), setup.radius * 4.0);
    let mut nearest = [(0.0f32, 0u32); MAX_K];
    bencher
        .counter(divan::counter::ItemsCount::new(setup.queries.len()))
        .bench_local(|| {
            let mut area = 0.0f32;
            for q in &setup.queries {
                area += map
                    .nearest(q.point, Side::Facing(q.normal), K, |_| true, &mut nearest)
                    .1;
            }
            area
        });
}

#[divan::bench(sample_count = 10)]
fn nearest_kiddo(bencher: Bencher) {
    let setup = &*SETUP;
    let tree = tree(&setup.photons);
    let r2 = (setup.radius * 4.0).powi(2);
    let k = NonZero::new(K).expect("k > 0");
    bencher
        .counter(divan::counter::ItemsCount::new(setup.queries.len()))
        .bench(|| {
            let mut area = 0.0f32;
            for q in &setup.queries {
                // kiddo cannot filter by side while it searches: ask for the
                // k nearest, then drop the far side's (the hash grid's
                // answer can hold more of the near side's).
                let found = tree
                    .query(&q.point.to_array())
                    .nearest_n::<SquaredEuclidean<f32>>(k)
                    .within(r2)
                    .execute();
                let mut near_side = found
                    .iter()
                    .filter(|f| setup.photons[f.item as usize].normal.dot(q.normal) > 0.0);
                area += near_side.next_back().map_or(r2, |f| f.distance);
            }
            area
        });
}
