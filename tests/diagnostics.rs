//! Sample diagnostics: replaying a sample gives exactly what the render
//! added to the film, extreme samples are flagged with a replayable index,
//! and clamping bounds every sample (and says how often it acted).

use crate::common::{cornell_box, repo_path};
use std::sync::Arc;
use tracelab::film::NOT_FLAGGED;
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::math::luminance;
use tracelab::render::{RenderSettings, Session};
use tracelab::replay::replay_sample;
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

fn settings(sampler: SamplerKind, spp: u32, clamp: Option<f32>) -> RenderSettings {
    RenderSettings {
        integrator: Integrator::from(PathTracer::default()),
        sampler,
        seed: 11,
        planned_spp: spp,
        threads: 0,
        adaptive: None,
        domains: Default::default(),
        clamp,
        filter_sampling: Default::default(),
    }
}

#[test]
fn replayed_samples_are_the_rendered_ones() {
    let mut scene = cornell_box();
    scene.set_resolution(16, 16);
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let s = settings(sampler, 8, None);
        let session = Session::new(Arc::new(scene.clone()), s.clone()).unwrap();
        session.render_pass(8);
        let film = session.snapshot();
        for (x, y) in [(3, 12), (8, 8), (15, 0)] {
            let mut sum = glam::DVec3::ZERO;
            for index in 0..8 {
                let (value, lines) = replay_sample(&scene, &s, x, y, index).unwrap();
                assert!(lines.len() >= 2 && lines[0].contains("camera ray"));
                sum += value.as_dvec3();
            }
            let replayed = sum / 8.0;
            let rendered = film.image.pixels[(y * 16 + x) as usize];
            for c in 0..3 {
                assert!(
                    (replayed[c] - rendered[c] as f64).abs() <= 1e-5 * (1.0 + replayed[c].abs()),
                    "{sampler:?} pixel ({x}, {y}): replayed {replayed:?}, rendered {rendered:?}"
                );
            }
        }
    }
}

/// The caustic scene with its lamp made 10^5 times brighter: paths that
/// reach it through the glass ball are extreme.
fn blinding_caustic() -> Scene {
    let text = std::fs::read_to_string(repo_path("scenes/caustic.toml"))
        .unwrap()
        .replace(
            "emission = [300.0, 280.0, 250.0]",
            "emission = [3e7, 2.8e7, 2.5e7]",
        );
    assert!(text.contains("3e7"), "the caustic scene's lamp changed");
    let path = repo_path("scenes/blinding_caustic_test.toml");
    let input = tracelab::scene::load::parse_scene(&path, &text, &Default::default()).unwrap();
    let mut scene = Scene::build(input).unwrap();
    scene.set_resolution(32, 24);
    scene
}

#[test]
fn extreme_samples_are_flagged_and_replayable() {
    let scene = blinding_caustic();
    let s = settings(SamplerKind::Independent, 16, None);
    let session = Session::new(Arc::new(scene.clone()), s.clone()).unwrap();
    session.render_pass(16);
    let film = session.snapshot();
    assert!(session.stats().extreme > 0);
    let pixel = film
        .first_flagged
        .iter()
        .position(|&i| i != NOT_FLAGGED)
        .expect("some sample is extreme");
    assert!(film.extreme_pixels[pixel] > 0);
    let (x, y) = (pixel as u32 % 32, pixel as u32 / 32);
    let (value, _) = replay_sample(&scene, &s, x, y, film.first_flagged[pixel]).unwrap();
    assert!(
        luminance(value) > tracelab::film::EXTREME_LUMINANCE,
        "{value:?}"
    );
}

#[test]
fn clamping_bounds_every_sample_and_is_counted() {
    let scene = blinding_caustic();
    let limit = 5.0;
    let session = Session::new(
        Arc::new(scene),
        settings(SamplerKind::Independent, 16, Some(limit)),
    )
    .unwrap();
    session.render_pass(16);
    assert!(session.stats().clamped > 0);
    let film = session.snapshot();
    // A pixel is a mean of clamped samples, so it cannot exceed the limit.
    for p in &film.image.pixels {
        assert!(p.iter().all(|&c| c <= limit * (1.0 + 1e-6)), "{p:?}");
    }
}
