//! Motion blur against a case solved by hand. A black sphere of radius 1
//! crosses the view 10 units in front of the camera, moving 10 units over the
//! shutter interval, in front of a uniform emitter of radiance 1. A camera ray
//! near the axis is blocked while the sphere's centre is within 1 of it, which
//! lasts 2 / 10 of the exposure, so every pixel of the middle row sees
//! 1 - 0.2 = 0.8. (The narrow field of view keeps each pixel's footprint
//! within 0.02 of the axis: the chord shortens by under 2e-4.)
//!
//! Tolerance: each sample is 0 or 1 with p = 0.8, variance 0.16, so the mean
//! of the row's n samples has standard error sqrt(0.16 / n); the test allows
//! 4 of them. Rendering without a time dimension (the sphere at its shutter
//! opening position) gives 1.0, which the test rejects by 48 of them.

use crate::common::{load_scene_text, render, temp_dir};
use tracelab::integrator::{Integrator, PathTracer, WhittedTracer};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

const WIDTH: u32 = 9;

fn crossing_scene(shutter: [f32; 2]) -> Scene {
    let text = format!(
        r#"
[camera]
eye = [0, 0, 0]
look_at = [0, 0, 1]
fov_y = 2.0
width = {WIDTH}
height = {WIDTH}
shutter = [{}, {}]

[materials.glow]
type = "diffuse"
albedo = [0, 0, 0]
emission = [1, 1, 1]

[materials.black]
type = "diffuse"
albedo = [0, 0, 0]

# Faces the camera: u x v points along -z.
[[quad]]
corner = [-50, -50, 20]
u = [0, 100, 0]
v = [100, 0, 0]
material = "glow"

[[sphere]]
center = [-5, 0, 10]
radius = 1
velocity = [10, 0, 0]
material = "black"
"#,
        shutter[0], shutter[1]
    );
    load_scene_text("motion", &text)
}

/// Mean of the middle row's red channel.
fn middle_row_mean(image: &tracelab::image::Image) -> f64 {
    let y = (WIDTH / 2) as usize;
    let row = &image.pixels[y * WIDTH as usize..(y + 1) * WIDTH as usize];
    row.iter().map(|p| p[0] as f64).sum::<f64>() / WIDTH as f64
}

#[test]
fn moving_sphere_blocks_the_light_for_its_share_of_the_exposure() {
    let spp = 1024;
    let standard_error = (0.16 / (spp * WIDTH) as f64).sqrt();
    for sampler in [SamplerKind::Independent, SamplerKind::Stratified] {
        let scene = crossing_scene([0.0, 1.0]);
        assert!(scene.features.motion);
        let (film, _) = render(
            scene,
            Integrator::from(PathTracer::default()),
            sampler,
            spp,
            7,
        );
        let mean = middle_row_mean(&film.image);
        assert!(
            (mean - 0.8).abs() < 4.0 * standard_error,
            "{sampler:?}: middle row {mean}, expected 0.8 ± {}",
            4.0 * standard_error
        );
    }
}

#[test]
fn shutter_interval_sets_the_time_range() {
    // The same sweep over [2, 3]: the sphere starts at x = 15 and moves on,
    // never crossing the view.
    let scene = crossing_scene([2.0, 3.0]);
    let (film, _) = render(
        scene,
        Integrator::from(PathTracer::default()),
        SamplerKind::Independent,
        64,
        7,
    );
    assert_eq!(middle_row_mean(&film.image), 1.0);
}

#[test]
fn instantaneous_shutter_has_no_time_dimension() {
    let scene = crossing_scene([0.0, 0.0]);
    assert!(!scene.features.motion);
    assert!(
        scene
            .features
            .skipped(false, false, scene.geometry.is_plain())
            .contains(&"time dimension (static scene)")
    );
    // At time 0 the sphere is 5 units off the axis: nothing is blocked.
    let (film, _) = render(
        scene,
        Integrator::from(PathTracer::default()),
        SamplerKind::Independent,
        64,
        7,
    );
    assert_eq!(middle_row_mean(&film.image), 1.0);
}

#[test]
fn whitted_sees_the_middle_of_the_exposure() {
    // At time 0.5 the sphere is centred on the axis and covers the row.
    let (film, _) = render(
        crossing_scene([0.0, 1.0]),
        Integrator::from(WhittedTracer::default()),
        SamplerKind::Independent,
        1,
        7,
    );
    assert_eq!(middle_row_mean(&film.image), 0.0);
}

#[test]
fn moving_emitters_are_refused_with_the_line() {
    let dir = temp_dir("moving-emitter");
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        r#"[camera]
eye = [0, 0, 0]
look_at = [0, 0, 1]
fov_y = 40
width = 8
height = 8

[materials.glow]
type = "diffuse"
emission = [1, 1, 1]

[[sphere]]
center = [0, 0, 5]
radius = 1
velocity = [1, 0, 0]
material = "glow"
"#,
    )
    .unwrap();
    let message = Scene::load(&path).unwrap_err().to_string();
    assert!(message.contains("bad.toml:12"), "{message}");
    assert!(message.contains("emitters cannot move"), "{message}");
}
