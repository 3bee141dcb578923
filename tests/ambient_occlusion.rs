//! Ambient occlusion against cases solved by hand. Each sample is 1 when its
//! cosine-distributed probe ray is unblocked and 0 otherwise: a Bernoulli
//! variable of variance AO (1 - AO), so the mean over n samples has standard
//! error sqrt(AO (1 - AO) / n), at most 0.5 / sqrt(n).

use crate::common::{load_scene_text, render_with};
use tracelab::integrator::{IntegratorKind, IntegratorOptions};
use tracelab::sampling::SamplerKind;

/// A camera looking straight down at the floor (y = 0) near x = 0; a wall in
/// the plane x = `wall_x` facing -x when `wall` is set. Both are 2000 units
/// across, a thousand times the distance of the floor points to the wall.
fn floor_scene(wall: bool) -> String {
    let wall = if wall {
        r#"
[[quad]]
corner = [1.0, 0.0, 1000.0]
u = [0.0, 0.0, -2000.0]
v = [0.0, 1000.0, 0.0]
material = "white"
"#
    } else {
        ""
    };
    format!(
        r#"
[camera]
eye = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov_y = 20.0
width = 16
height = 16

[materials.white]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[quad]]
corner = [-1000.0, 0.0, 1000.0]
u = [2000.0, 0.0, 0.0]
v = [0.0, 0.0, -2000.0]
material = "white"
{wall}
[[point_light]]
position = [0.0, 10.0, 0.0]
intensity = [1.0, 1.0, 1.0]
"#
    )
}

fn ambient_occlusion(ao_distance: f32) -> tracelab::integrator::Integrator {
    let mut options = IntegratorOptions::of(IntegratorKind::AmbientOcclusion);
    options.ao.distance = ao_distance;
    options.build()
}

#[test]
fn an_open_plane_is_unoccluded() {
    let scene = load_scene_text("ao-plane", &floor_scene(false));
    let (film, stats) = render_with(
        scene,
        ambient_occlusion(0.0),
        SamplerKind::Sobol,
        16,
        1,
        2,
        16,
    );
    // Nothing can block a probe: every sample is exactly 1.
    assert!(
        film.image.pixels.iter().all(|p| *p == [1.0; 3]),
        "{:?}",
        &film.image.pixels[..4]
    );
    assert_eq!(stats.rays.shadow, 16 * 16 * 16);
}

#[test]
fn a_floor_before_a_wall_is_half_open() {
    // Points on the floor between x = -0.53 and 0.53 (the camera's view),
    // 0.47 to 1.53 from the wall at x = 1: the half of the hemisphere that
    // faces the wall is blocked whatever the distance, the other half is
    // open, so AO = 1/2 (the wall's finite size leaves out less than 1e-3).
    let scene = load_scene_text("ao-wall", &floor_scene(true));
    let spp = 256;
    let (film, _) = render_with(
        scene,
        ambient_occlusion(0.0),
        SamplerKind::Independent,
        spp,
        3,
        2,
        64,
    );
    let n = film.image.pixels.len() as f64 * f64::from(spp);
    let mean = film
        .image
        .pixels
        .iter()
        .map(|p| f64::from(p[0]))
        .sum::<f64>()
        / film.image.pixels.len() as f64;
    // Independent samples: standard error 0.5 / sqrt(n) = 0.0020 for n = 65536;
    // 4 standard errors plus the wall's 1e-3.
    let tolerance = 4.0 * 0.5 / n.sqrt() + 1e-3;
    assert!(
        (mean - 0.5).abs() < tolerance,
        "AO {mean}, expected 0.5 +- {tolerance}"
    );
}

#[test]
fn a_distance_limit_ignores_far_occluders() {
    // The limit is 1e-4 of the diagonal (0.3 units): the wall, 0.47
    // or more away, blocks nothing, so the floor is fully open again.
    let scene = load_scene_text("ao-limit", &floor_scene(true));
    let (film, _) = render_with(
        scene,
        ambient_occlusion(1e-4),
        SamplerKind::Independent,
        16,
        3,
        2,
        16,
    );
    assert!(film.image.pixels.iter().all(|p| *p == [1.0; 3]));
}
