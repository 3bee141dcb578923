//! Different estimators of the same integral must agree: next-event
//! estimation on and off, MIS with the balance heuristic, the power heuristic
//! or none, Russian roulette on and off, all on the Cornell box; and lights
//! seen directly integrated over the pixel or sampled, behind an occluder.
//!
//! Tolerance: the image is cut into 8x8 blocks of 8x8 pixels; each block mean
//! has a standard error sqrt(sum se_i^2) / 64 from the per-pixel standard
//! errors. For two renders the block difference divided by the combined
//! standard error is a z-score; all 192 (64 blocks x 3 channels) must lie
//! within 4.5 (Bonferroni at 1% would be 3.9; the margin covers the heavy
//! tail of BSDF-only sampling, whose standard error is itself noisy).

use crate::common::{cornell_box, load_scene_text, render};
use tracelab::accel::NO_LIGHT;
use tracelab::film::FilmSnapshot;
use tracelab::integrator::{Integrator, MisHeuristic, PathTracer};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

pub(crate) const SIZE: u32 = 64;
const BLOCK: u32 = 8;

fn render_small(tracer: PathTracer, spp: u32, seed: u64) -> FilmSnapshot {
    render_scene(cornell_box(), tracer, spp, seed)
}

fn render_scene(mut scene: Scene, tracer: PathTracer, spp: u32, seed: u64) -> FilmSnapshot {
    scene.set_resolution(SIZE, SIZE);
    let (snapshot, stats) = render(
        scene,
        Integrator::from(tracer),
        SamplerKind::Independent,
        spp,
        seed,
    );
    assert_eq!(stats.non_finite, 0);
    snapshot
}

/// Block means and their squared standard errors: the pixels' summed as
/// independent, times the film's correlation where samples were splatted
/// through a filter (a block's edge pixels share samples with the next
/// block too, so this overstates a little).
pub(crate) fn blocks(s: &FilmSnapshot) -> Vec<([f64; 3], [f64; 3])> {
    let per_side = SIZE / BLOCK;
    let mut out = vec![([0.0; 3], [0.0; 3]); (per_side * per_side) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let b = &mut out[((y / BLOCK) * per_side + x / BLOCK) as usize];
            for c in 0..3 {
                b.0[c] += s.image.pixels[i][c] as f64;
                b.1[c] += (s.standard_error.pixels[i][c] as f64).powi(2);
            }
        }
    }
    let n = (BLOCK * BLOCK) as f64;
    out.into_iter()
        .map(|(m, v)| (m.map(|x| x / n), v.map(|x| x * s.correlation / (n * n))))
        .collect()
}

/// The largest |z| of the block differences of two 64x64 renders.
pub(crate) fn largest_block_z(a: &FilmSnapshot, b: &FilmSnapshot) -> f64 {
    let mut worst = 0.0f64;
    for (ba, bb) in blocks(a).iter().zip(blocks(b).iter()) {
        for c in 0..3 {
            let z = (ba.0[c] - bb.0[c]) / (ba.1[c] + bb.1[c]).sqrt().max(1e-12);
            worst = worst.max(z.abs());
        }
    }
    worst
}

pub(crate) fn assert_agree(name: &str, a: &FilmSnapshot, b: &FilmSnapshot) {
    let worst = largest_block_z(a, b);
    eprintln!("{name}: largest block z-score {worst:.2}");
    assert!(
        worst < 4.5,
        "{name}: a block differs by {worst:.2} standard errors"
    );
}

#[test]
fn nee_and_mis_variants_converge_to_the_same_image() {
    let base = PathTracer::default();
    let reference = render_small(base, 256, 1);
    let variants = [
        (
            "balance heuristic",
            PathTracer {
                mis: MisHeuristic::Balance,
                ..base
            },
            256,
        ),
        (
            "light sampling only for direct light",
            PathTracer {
                mis: MisHeuristic::None,
                ..base
            },
            256,
        ),
        (
            "BSDF sampling only (no NEE)",
            PathTracer { nee: false, ..base },
            1024,
        ),
        (
            "no Russian roulette",
            PathTracer {
                russian_roulette: false,
                ..base
            },
            256,
        ),
    ];
    for (k, (name, tracer, spp)) in variants.into_iter().enumerate() {
        let image = render_small(tracer, spp, 10 + k as u64);
        assert_agree(name, &reference, &image);
    }
}

/// A tilted light facing the camera, a wall behind it, and a quad in front
/// hiding part of it.
const HIDDEN_LIGHT: &str = r#"
[camera]
eye = [0.0, 0.0, -5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
width = 64
height = 64

[materials.grey]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[materials.lamp]
type = "diffuse"
albedo = [0.3, 0.3, 0.3]
emission = [8.0, 8.0, 8.0]

[[quad]]
corner = [-2.0, -2.0, 1.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 4.0, 0.0]
material = "grey"

[[quad]]
corner = [-0.8, -0.6, 0.0]
u = [0.0, 1.2, 0.0]
v = [1.6, 0.0, 0.3]
material = "lamp"

[[quad]]
corner = [-1.0, -1.0, -1.0]
u = [0.0, 2.0, 0.0]
v = [1.2, 0.0, 0.0]
material = "grey"
"#;

#[test]
fn lights_seen_directly_agree_integrated_or_sampled_behind_an_occluder() {
    let load = || load_scene_text("hidden-light", HIDDEN_LIGHT);
    // Both kinds of pixel occur: the light integrated exactly, and the light
    // left to sampling where the quad in front may hide it.
    let scene = load();
    let lists = scene
        .primary_candidates()
        .expect("a pinhole soup gets lists");
    let (mut exact, mut fell_back) = (0, 0);
    for p in 0..SIZE * SIZE {
        let pixel = lists.pixel(p);
        let sees_light = pixel
            .candidates
            .unwrap_or_default()
            .iter()
            .any(|&i| scene.geometry.triangle_light(i as usize) != NO_LIGHT);
        match (sees_light, pixel.seen_emission) {
            (true, Some(_)) => exact += 1,
            (true, None) => fell_back += 1,
            _ => {}
        }
    }
    assert!(
        exact > 50 && fell_back > 20,
        "{exact} exact, {fell_back} sampled"
    );

    let base = PathTracer::default();
    let integrated = render_scene(load(), base, 256, 1);
    let sampled = PathTracer {
        exact_seen_emitters: false,
        ..base
    };
    let sampled = render_scene(load(), sampled, 256, 2);
    assert_agree(
        "lights seen directly, integrated / sampled",
        &integrated,
        &sampled,
    );
}

#[test]
fn a_wrong_estimator_is_caught() {
    // The same comparison must reject a biased render: light 3% too bright.
    let base = PathTracer::default();
    let a = render_small(base, 256, 1);
    let mut b = render_small(base, 256, 2);
    for p in &mut b.image.pixels {
        for v in p.iter_mut() {
            *v *= 1.03;
        }
    }
    let worst = blocks(&a)
        .iter()
        .zip(blocks(&b).iter())
        .flat_map(|(x, y)| {
            (0..3).map(move |c| ((x.0[c] - y.0[c]) / (x.1[c] + y.1[c]).sqrt()).abs())
        })
        .fold(0.0f64, f64::max);
    assert!(
        worst > 4.5,
        "a 3% bias went unnoticed (largest z {worst:.2})"
    );
}
