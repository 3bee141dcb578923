//! The estimators of issue 3 on scenes small enough to check by hand: the
//! branching factor of MC ray tracing, and Whitted ray tracing's values for
//! single pixels, computed here from the geometry with pencil-and-paper
//! formulas (Lambert, inverse square law, Fresnel at normal incidence).

use crate::common::{load_scene_text as load, render_with};
use std::f32::consts::PI;
use tracelab::integrator::{GlassShadows, IntegratorKind, IntegratorOptions};
use tracelab::sampling::SamplerKind;

/// Six inward-facing diffuse walls around a point light: every ray hits a
/// scattering surface and every light sample is in front of it.
const CLOSED_BOX: &str = r#"
[camera]
eye = [0.0, 0.0, 0.5]
look_at = [0.0, 0.0, -1.0]
fov_y = 60.0
width = 8
height = 8

[materials.white]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[quad]]
corner = [-1.0, -1.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "white"
[[quad]]
corner = [-1.0, -1.0, 1.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "white"
[[quad]]
corner = [-1.0, -1.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [2.0, 0.0, 0.0]
material = "white"
[[quad]]
corner = [-1.0, 1.0, -1.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "white"
[[quad]]
corner = [-1.0, -1.0, -1.0]
u = [0.0, 2.0, 0.0]
v = [0.0, 0.0, 2.0]
material = "white"
[[quad]]
corner = [1.0, -1.0, -1.0]
u = [0.0, 0.0, 2.0]
v = [0.0, 2.0, 0.0]
material = "white"

[[point_light]]
position = [0.0, 0.5, 0.0]
intensity = [1.0, 1.0, 1.0]
"#;

#[test]
fn mc_ray_tracing_casts_186_rays_per_pixel_with_two_branching_levels_and_5_by_5_branching() {
    // Cook's tree with D = 2 levels of branching gathers light of three
    // bounces: --max-depth counts bounces, so it is max_depth 3.
    let mut options = IntegratorOptions::of(IntegratorKind::Mcrt);
    (
        options.mcrt.max_depth,
        options.mcrt.shadow_rays,
        options.mcrt.glossy_rays,
    ) = (3, 5, 5);
    let tracelab::integrator::Integrator::Camera(tracelab::integrator::CameraIntegrator::Mcrt(
        mcrt,
    )) = options.build()
    else {
        unreachable!()
    };
    assert_eq!(mcrt.rays_per_sample_closed(), 186);
    let (snapshot, stats) = render_with(
        load("mcrt-count", CLOSED_BOX),
        options.build(),
        SamplerKind::Independent,
        1,
        3,
        1,
        1,
    );
    let pixels = 64;
    assert_eq!(stats.rays.camera, pixels);
    assert_eq!(stats.rays.shadow, pixels * (5 + 25 + 125));
    assert_eq!(stats.rays.bounce, pixels * (5 + 25));
    assert_eq!(stats.rays.total(), pixels * 186);
    assert!(snapshot.image.mean()[0] > 0.0);
}

/// Camera on the +z axis looking at the origin; 101 pixels so that the
/// centre pixel's ray runs exactly along the axis.
fn whitted_scene(extra: &str, light: [f32; 3]) -> String {
    format!(
        r#"
[camera]
eye = [0.0, 0.0, 10.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
width = 101
height = 101

[materials.wall]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[materials.glass]
type = "dielectric"
ior = 1.5
tint = [0.9, 0.8, 0.7]
[materials.mirror]
type = "mirror"
reflectance = [0.8, 0.8, 0.8]

[[point_light]]
position = {light:?}
intensity = [10.0, 10.0, 10.0]
{extra}
"#
    )
}

const WALL: &str = r#"
[[quad]]
corner = [-5.0, -5.0, 0.0]
u = [10.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "wall"
"#;

/// A glass slab between z = 3 and z = 4 in front of the wall's centre.
const SLAB: &str = r#"
[[quad]]
corner = [-1.0, -1.0, 4.0]
u = [2.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "glass"
[[quad]]
corner = [-1.0, -1.0, 3.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "glass"
"#;

fn whitted(text: &str, glass_shadows: GlassShadows, max_depth: u32) -> Vec<[f32; 3]> {
    let mut options = IntegratorOptions::of(IntegratorKind::Whitted);
    (options.whitted.max_depth, options.whitted.glass_shadows) = (max_depth, glass_shadows);
    let (a, _) = render_with(
        load("whitted", text),
        options.build(),
        SamplerKind::Independent,
        1,
        1,
        1,
        1,
    );
    // Deterministic: another seed and more samples change nothing.
    let (b, _) = render_with(
        load("whitted", text),
        options.build(),
        SamplerKind::Stratified,
        3,
        99,
        2,
        2,
    );
    assert_eq!(a.image.pixels, b.image.pixels);
    a.image.pixels
}

/// Radiance of the diffuse wall (albedo 0.5) at `p` with normal `n`, lit by
/// the 10 W/sr point light at `light`: (rho / pi) I cos / d^2.
fn lambert(p: [f32; 3], n: [f32; 3], light: [f32; 3]) -> f32 {
    let d = [light[0] - p[0], light[1] - p[1], light[2] - p[2]];
    let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let cos = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / d2.sqrt();
    0.5 / PI * 10.0 * cos / d2
}

fn assert_close(got: [f32; 3], want: [f32; 3], what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= 1e-5 + 1e-4 * want[c].abs(),
            "{what}: got {got:?}, want {want:?}"
        );
    }
}

const CENTRE: usize = 50 * 101 + 50;

#[test]
fn whitted_diffuse_wall_under_a_point_light_matches_lambert() {
    let light = [0.0, 3.0, 5.0];
    let image = whitted(&whitted_scene(WALL, light), GlassShadows::Opaque, 8);
    let centre = lambert([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], light);
    assert_close(image[CENTRE], [centre; 3], "centre pixel");
    // Pixel (75, 50): its ray leaves at tan(15 deg) * ndc_x off the axis and
    // meets the wall 10 units away; image right is +x.
    let ndc_x = 2.0 * 75.5 / 101.0 - 1.0;
    let x = 10.0 * ndc_x * 15f32.to_radians().tan();
    let off_axis = lambert([x, 0.0, 0.0], [0.0, 0.0, 1.0], light);
    assert_close(image[50 * 101 + 75], [off_axis; 3], "pixel (75, 50)");
}

#[test]
fn whitted_sees_the_wall_through_glass_with_fresnel_losses() {
    // Normal incidence: F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04 at each face;
    // the (eta_i/eta_t)^2 factors of entering and leaving cancel. Depth 2
    // stops the internal reflections, which would add F^2 (1 - F)^2 terms.
    let tint = [0.9f32, 0.8, 0.7];
    let through = (1.0f32 - 0.04).powi(2);
    let light = [0.0, 3.0, 5.0];
    let image = whitted(
        &whitted_scene(&format!("{WALL}{SLAB}"), light),
        GlassShadows::Opaque,
        2,
    );
    let wall = lambert([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], light);
    assert_close(
        image[CENTRE],
        tint.map(|t| t * t * through * wall),
        "wall seen through the slab",
    );

    // Light behind the slab as seen from the wall: opaque shadows make the
    // wall black; tinted shadows let tint^2 through, without refraction.
    let light = [0.0, 0.5, 8.0];
    let text = whitted_scene(&format!("{WALL}{SLAB}"), light);
    let opaque = whitted(&text, GlassShadows::Opaque, 2);
    assert_close(opaque[CENTRE], [0.0; 3], "opaque glass shadow");
    let tinted = whitted(&text, GlassShadows::Tinted, 2);
    let wall = lambert([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], light);
    assert_close(
        tinted[CENTRE],
        tint.map(|t| t.powi(4) * through * wall),
        "tinted glass shadow",
    );
}

#[test]
fn whitted_mirror_shows_the_wall_behind_the_camera() {
    let mirror = r#"
[[quad]]
corner = [-5.0, -5.0, 0.0]
u = [10.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "mirror"
[[quad]]
corner = [-50.0, -50.0, 20.0]
u = [0.0, 100.0, 0.0]
v = [100.0, 0.0, 0.0]
material = "wall"
"#;
    let light = [0.0, 3.0, 15.0];
    let image = whitted(&whitted_scene(mirror, light), GlassShadows::Opaque, 8);
    let wall = lambert([0.0, 0.0, 20.0], [0.0, 0.0, -1.0], light);
    assert_close(image[CENTRE], [0.8 * wall; 3], "mirror reflection");
}

/// A diffuse floor of albedo 0.5 under one sphere light of radius `radius`,
/// 20 above the floor's centre, seen straight down through a 2° lens. Below
/// a sphere of radiance L at distance d the irradiance is π L (r / d)²
/// exactly, so with L = (d / r)² every pixel reads 0.5, less the falloff
/// towards the frame's corners (below 3e-5: they are 0.09 off the axis).
fn small_sphere_light(radius: f32) -> String {
    let radiance = (20.0 / radius).powi(2);
    format!(
        r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 2.0
width = 16
height = 16

[lights]
sphere_sampling = "solid-angle"

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[materials.bulb]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [{radiance}, {radiance}, {radiance}]

[[quad]]
corner = [-10.0, -10.0, 0.0]
u = [20.0, 0.0, 0.0]
v = [0.0, 20.0, 0.0]
material = "floor"

[[sphere]]
center = [0.0, 0.0, 20.0]
radius = {radius}
material = "bulb"
"#
    )
}

#[test]
fn a_small_or_distant_sphere_light_gives_its_closed_form() {
    // 1 − cos θ_max computed as 1 − √(1 − sin²) lost 4.6% of the light at
    // an angular radius of 5e-4 and all of it below 2.4e-4 (f32 rounds
    // 1 − sin² to 1). Tolerance 1e-4 of the value: the frame's falloff is
    // under 3e-5, and the estimator's standard error, from the pixels'
    // spread (6e-6 for path tracing and BDPT, 2.3e-5 for VCM, measured) over
    // 256 pixels of 16 samples, under 2e-6.
    for radius in [0.1, 0.01, 1e-3, 1e-4] {
        for kind in [
            IntegratorKind::Path,
            IntegratorKind::Bdpt,
            IntegratorKind::Vcm,
        ] {
            let mut options = IntegratorOptions::of(kind);
            *options.max_depth_mut().expect("a depth") = 1;
            let (snapshot, stats) = render_with(
                load("small-sphere-light", &small_sphere_light(radius)),
                options.build(),
                SamplerKind::Independent,
                16,
                1,
                0,
                8,
            );
            assert_eq!(stats.non_finite, 0);
            let mean = snapshot.image.mean()[0];
            assert!(
                (mean / 0.5 - 1.0).abs() < 1e-4,
                "{kind:?}, radius {radius}: mean {mean}, closed form 0.5"
            );
        }
    }
}

/// A floor of albedo 0.5 under a spot of intensity 1 at height 20 aimed
/// straight down, cut off at `cutoff` degrees (beam at 3/4 of it), seen
/// from height 5 by a lens whose view of the floor is a square 3.2 times
/// the lit disc's radius: the whole footprint lies in the frame.
fn narrow_spot(cutoff: f64) -> (String, f64) {
    let half_width = 20.0 * cutoff.to_radians().tan() * 1.6;
    let fov = 2.0 * (half_width / 5.0).atan().to_degrees();
    let text = format!(
        r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = {fov}
width = 32
height = 32

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[quad]]
corner = [-100.0, -100.0, 0.0]
u = [200.0, 0.0, 0.0]
v = [0.0, 200.0, 0.0]
material = "floor"

[[spot_light]]
position = [0.0, 0.0, 20.0]
target = [0.0, 0.0, 0.0]
intensity = [1.0, 1.0, 1.0]
cutoff_angle = {cutoff}
"#
    );
    // The flux on the floor is I ∫ falloff dω, with the falloff linear in
    // angle from the beam θb to the cutoff θc: 2π (1 − (sin θc − sin θb) /
    // (θc − θb)). The pixels' mean is the albedo over π times that flux
    // over the floor's area in view.
    let (c, b) = (cutoff.to_radians(), 0.75 * cutoff.to_radians());
    let half_sum_cos = (0.5 * (c + b)).cos();
    let flux =
        2.0 * std::f64::consts::PI * (1.0 - 2.0 * half_sum_cos * (0.5 * (c - b)).sin() / (c - b));
    (
        text,
        0.5 / std::f64::consts::PI * flux / (2.0 * half_width).powi(2),
    )
}

#[test]
fn a_narrow_spot_gives_its_closed_form_in_every_technique() {
    // The falloff's angle came from acos of a cosine near 1, in steps of
    // 3.5e-4 rad, and the cone's density from 1 − cos(cutoff): a spot of
    // 0.02° read 22% high in path tracing, 6.6% in light tracing, 10% in
    // BDPT. Tolerance: see `check_spot`.
    for cutoff in [10.0, 0.1, 0.02] {
        let (text, expected) = narrow_spot(cutoff);
        for kind in [
            IntegratorKind::Path,
            IntegratorKind::Light,
            IntegratorKind::Bdpt,
        ] {
            let mut options = IntegratorOptions::of(kind);
            *options.max_depth_mut().expect("a depth") = 1;
            check_spot(
                &text,
                expected,
                options,
                &format!("{kind:?}, cutoff {cutoff}°"),
            );
        }
    }
}

/// Renders a [`narrow_spot`] scene at 64 spp and checks its mean against
/// the closed form: within 4 standard errors of the mean (from the pixels'
/// own) plus 2e-4 of the value for the pixel grid's edges across the
/// footprint (path tracing, nearly noiseless, lands 2e-5 off).
fn check_spot(text: &str, expected: f64, options: IntegratorOptions, what: &str) {
    let (snapshot, stats) = render_with(
        load("narrow-spot", text),
        options.build(),
        SamplerKind::Independent,
        64,
        1,
        0,
        8,
    );
    assert_eq!(stats.non_finite, 0);
    let (mean, error) = crate::common::mean_and_standard_error(&snapshot);
    let tolerance = 4.0 * error[0] + 2e-4 * expected;
    assert!(
        (mean[0] - expected).abs() < tolerance,
        "{what}: mean {} against {expected} (tolerance {tolerance})",
        mean[0]
    );
}

#[test]
fn merging_says_when_its_radius_is_wider_than_the_view_and_meets_the_closed_form_when_not() {
    // The 0.1° spot's footprint is 0.11 wide in a scene 283 across: the
    // default radius (0.002 of the diagonal) spans about 320 pixels, and
    // VCM's merges blurred 96% of the light out of view. The summary says
    // so; at a radius of about one pixel VCM meets the closed form
    // (tolerance as in the spot test above).
    let (text, expected) = narrow_spot(0.1);
    for kind in [IntegratorKind::Vcm, IntegratorKind::Sppm] {
        let options = IntegratorOptions::of(kind);
        let said = options
            .build()
            .for_scene(&load("wide-radius", &text))
            .describe();
        assert!(said.contains("more than an eighth of the frame"), "{said}");
        let cornell = options
            .build()
            .for_scene(&crate::common::cornell_box())
            .describe();
        assert!(
            cornell.contains("pixels at the median first hit"),
            "{cornell}"
        );
        assert!(!cornell.contains("more than an eighth"), "{cornell}");
    }
    let mut options = IntegratorOptions::of(IntegratorKind::Vcm);
    *options.max_depth_mut().expect("a depth") = 1;
    options.vcm.radius = 2e-5;
    check_spot(&text, expected, options, "VCM at a radius of 3 pixels");
}
