//! Camera samples splatted through the pixel filter (`FilterSampling::Splat`,
//! Mitsuba's film) against the same filter importance-sampled, on
//! Bitterli's Cornell box (tent filter), path tracing.
//!
//! Tolerances: the spread of 40 seeds' estimates is compared with what
//! the films said of themselves. A pixel's variance over 40 seeds has 39
//! degrees of freedom (relative standard deviation 0.23); over 1 024
//! pixels whose neighbours share samples (about 9 a sample), the sum's is
//! about 0.23 / √(1024 / 9) = 2%, and the weighted mean's delta-method
//! variance is exact to O(1 / n) at about 36 effective samples (3%): 12%
//! covers both with room. The image mean's variance over 40 seeds is a
//! χ² of 39 degrees of freedom: its ratio to the prediction lies in
//! [0.47, 1.75] with probability 0.999, and without the correlation it
//! would be about 2.25.

use crate::common::{reference, repo_path};
use std::sync::Arc;
use tracelab::film::FilmSnapshot;
use tracelab::filter::FilterSampling;
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::render::{RenderSettings, Session};
use tracelab::sampling::SamplerKind;
use tracelab::scene::{LoadOptions, Scene};

fn cornell_box(size: u32) -> Scene {
    let options = LoadOptions {
        defines: vec![
            ("resx".into(), size.to_string()),
            ("resy".into(), size.to_string()),
        ],
        ..Default::default()
    };
    Scene::load_with(&repo_path("scenes/cornell-box/scene.xml"), &options)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Arc<Scene>, sampling: FilterSampling, spp: u32, seed: u64) -> FilmSnapshot {
    let settings = RenderSettings {
        integrator: Integrator::from(PathTracer {
            max_depth: scene
                .hints
                .max_depth
                .unwrap_or(PathTracer::default().max_depth),
            ..Default::default()
        }),
        sampler: SamplerKind::Independent,
        seed,
        planned_spp: spp,
        threads: 0,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: sampling,
    };
    let session = Session::new(scene.clone(), settings).expect("session starts");
    // Passes of 4: a pixel's weights arrive in groups, as in the viewer.
    for _ in 0..spp / 4 {
        assert!(session.render_pass(4));
    }
    session.snapshot()
}

/// A floor that fills the frame under a large square light out of it:
/// a smooth image whose noise is the paths' alone.
const FLOOR: &str = r#"
[camera]
eye = [0.0, -2.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_y = 30.0
width = 32
height = 32
filter = "tent"

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [4.0, 4.0, 4.0]

[[quad]]
corner = [-20.0, -20.0, 0.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "floor"

[[quad]]
corner = [1.5, -1.0, 2.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "lamp"
"#;

/// Per pixel, the spread over 40 seeds against the mean squared standard
/// error the films gave (green), and the image mean's spread over seeds
/// against its prediction (summed pixel errors times the correlation).
fn spread_against_errors(scene: &Arc<Scene>, sampling: FilterSampling) -> (f64, f64, f64) {
    let seeds = 40;
    let films: Vec<FilmSnapshot> = (0..seeds)
        .map(|seed| render(scene, sampling, 16, 100 + seed))
        .collect();
    let pixels = films[0].image.pixels.len();
    let r = seeds as f64;
    let (mut spread, mut said) = (0.0f64, 0.0f64);
    for p in 0..pixels {
        let values: Vec<f64> = films
            .iter()
            .map(|f| f64::from(f.image.pixels[p][1]))
            .collect();
        let mean = values.iter().sum::<f64>() / r;
        spread += values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (r - 1.0);
        said += films
            .iter()
            .map(|f| f64::from(f.standard_error.pixels[p][1]).powi(2))
            .sum::<f64>()
            / r;
    }
    let means: Vec<f64> = films.iter().map(|f| f.image.mean()[1]).collect();
    let mean = means.iter().sum::<f64>() / r;
    let mean_spread = means.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (r - 1.0);
    let correlation = films.iter().map(|f| f.correlation).sum::<f64>() / r;
    let predicted = said * correlation / (pixels as f64).powi(2);
    (spread / said, mean_spread / predicted, correlation)
}

/// On a smooth image the weighted mean's standard error is its spread
/// over seeds, pixel by pixel, and the film's correlation makes the image
/// mean's; without the correlation that ratio would be about 2.25.
#[test]
fn a_splatted_films_errors_are_its_spread_over_seeds() {
    let scene = Arc::new(crate::common::load_scene_text("splatted_floor", FLOOR));
    let (pixels, mean, correlation) = spread_against_errors(&scene, FilterSampling::Splat);
    eprintln!("floor: pixels {pixels:.3}, image mean {mean:.3}, correlation {correlation:.3}");
    assert!(
        (pixels - 1.0).abs() < 0.12,
        "pixels' variance ratio {pixels:.3}"
    );
    assert!(
        (1.9..2.6).contains(&correlation),
        "a tent's splats count in about 2.25 pixels: {correlation:.3}"
    );
    assert!(
        (0.47..1.75).contains(&mean),
        "image mean's variance ratio {mean:.3}"
    );
    // The same test holds importance sampling's plain errors.
    let (pixels, _, correlation) = spread_against_errors(&scene, FilterSampling::Importance);
    assert!(
        (pixels - 1.0).abs() < 0.12,
        "importance: variance ratio {pixels:.3}"
    );
    assert_eq!(correlation, 1.0);
}

/// Where the image changes sharply within a pixel's footprint (the Cornell
/// box's light against its ceiling), the error overstates the spread: a
/// neighbour's samples differ from the pixel by a fixed amount, which the
/// delta method counts with their weights' full square, E[w²], where only
/// their weights' variance, E[w²] − E[w]², moves the mean (about 0.64 of
/// it for a tent's side neighbours). The error is never below the spread.
#[test]
fn a_splatted_films_errors_are_conservative_at_sharp_edges() {
    let (pixels, mean, _) =
        spread_against_errors(&Arc::new(cornell_box(32)), FilterSampling::Splat);
    eprintln!("Cornell box: pixels {pixels:.3}, image mean {mean:.3}");
    assert!(
        (0.5..1.12).contains(&pixels),
        "pixels' variance ratio {pixels:.3}"
    );
    assert!(
        (0.3..1.75).contains(&mean),
        "image mean's variance ratio {mean:.3}"
    );
}

/// At equal samples, splatting's error against Mitsuba 3's render of the
/// file is well below importance sampling's: a pixel averages about 2.25
/// pixels' samples, so its variance is about 0.44 of the other's where
/// the image is smooth and the noise is the paths' (bound 0.6); and its
/// border pixels weigh only what falls inside the image, as Mitsuba's
/// film does, where importance sampling draws rays outside it.
#[test]
fn splatting_halves_the_error_at_equal_samples() {
    let scene = Arc::new(cornell_box(128));
    let mitsuba = reference("bitterli/cornell-box_mitsuba.exr");
    let variance = reference("bitterli/cornell-box_mitsuba_var.exr");
    let floor: f64 = variance
        .pixels
        .iter()
        .flat_map(|p| p.iter().map(|&v| f64::from(v)))
        .sum::<f64>()
        / (variance.pixels.len() * 3) as f64;
    let mse = |sampling| {
        let film = render(&scene, sampling, 16, 5);
        film.image.compare(&mitsuba).unwrap().rmse.powi(2) - floor
    };
    let (splat, importance) = (mse(FilterSampling::Splat), mse(FilterSampling::Importance));
    eprintln!("MSE less the reference's own: splat {splat:.6}, importance {importance:.6}");
    assert!(
        splat < 0.6 * importance,
        "splat {splat:.6} against {importance:.6}"
    );
}
