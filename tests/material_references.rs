//! Each material model against Mitsuba 3: one object per model on a grey
//! floor under a 2 m square area light (large, so that the caustics of Dirac
//! spheres are not rare events), 64 x 64 (the floor fills the frame: at
//! its edges against the void the two renderers' pixels differ by a few
//! hundredths of a pixel's coverage, z-scores up to 70), path tracing at 256 spp
//! against Mitsuba's `path` at 32 768 spp (tests/data/materials, made by
//! `make_references.py` there, which writes the same scene).
//!
//! Tolerances as `reference.rs`: for independent estimates the expected
//! MSE is the mean of var(ours) + var(ref) per pixel and channel; the RMSE
//! may exceed its square root by 10%. The image means must agree within
//! 0.5% per channel (their standard errors are about 0.1%).

use crate::common::{load_scene_text, reference, render};
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::sampling::SamplerKind;

/// The reference scene around one object (TOML), as `make_references.py`.
fn material_scene(material: &str, object: &str) -> String {
    format!(
        r#"
[camera]
eye = [0.0, -4.0, 2.5]
look_at = [0.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
fov_y = 35.0
width = 64
height = 64

[materials.floor]
type = "diffuse"
albedo = [0.4, 0.4, 0.4]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [3.0, 3.0, 3.0]

[materials.sample]
{material}

[[quad]]
corner = [-20.0, -20.0, 0.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "floor"

[[quad]]
corner = [0.2, -2.2, 3.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "lamp"

{object}
"#
    )
}

const SPHERE: &str = r#"
[[sphere]]
center = [0.0, 0.0, 0.6]
radius = 0.6
material = "sample"
"#;

/// Lying on the floor, normal +z, tangent +x.
const PANEL: &str = r#"
[[quad]]
corner = [-0.8, -0.8, 0.01]
u = [1.6, 0.0, 0.0]
v = [0.0, 1.6, 0.0]
material = "sample"
"#;

/// Standing, facing away from the camera (+y): the camera sees its back.
const BEHIND: &str = r#"
[[quad]]
corner = [-0.8, 0.0, 0.0]
u = [0.0, 0.0, 1.6]
v = [1.6, 0.0, 0.0]
material = "sample"
"#;

fn check(name: &str, material: &str, object: &str) {
    check_with_camera(name, name, material, object, "");
}

/// Checks the render of `material` on `object`, with `camera` lines added
/// to the camera table, against reference `reference`; returns RMSE /
/// its expected value.
fn check_with_camera(
    name: &str,
    reference_name: &str,
    material: &str,
    object: &str,
    camera: &str,
) -> f64 {
    let text = material_scene(material, object)
        .replace("height = 64\n", &format!("height = 64\n{camera}\n"));
    check_scene_against(name, reference_name, &text)
}

/// Checks the scene `text` against reference `name`; returns RMSE / its
/// expected value.
fn check_scene(name: &str, text: &str) -> f64 {
    check_scene_against(name, name, text)
}

fn check_scene_against(name: &str, reference_name: &str, text: &str) -> f64 {
    let scene = load_scene_text(name, text);
    assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
    let (snapshot, stats) = render(
        scene,
        Integrator::from(PathTracer::default()),
        SamplerKind::Independent,
        256,
        1,
    );
    assert_eq!(stats.non_finite, 0);
    let reference = reference(&format!("materials/{reference_name}.exr"));
    let variance = crate::common::reference(&format!("materials/{reference_name}_var.exr"));
    let rmse = snapshot.image.compare(&reference).unwrap().rmse;
    let mut expected_mse = 0.0f64;
    for (se, var_ref) in snapshot.standard_error.pixels.iter().zip(&variance.pixels) {
        for c in 0..3 {
            expected_mse += (se[c] as f64).powi(2) + var_ref[c] as f64;
        }
    }
    let expected = (expected_mse / (snapshot.image.pixels.len() * 3) as f64).sqrt();
    let (ours, theirs) = (snapshot.image.mean(), reference.mean());
    eprintln!(
        "{name}: RMSE {rmse:.5} (expected {expected:.5}); mean {ours:.5?} vs Mitsuba {theirs:.5?}"
    );
    if name == reference_name {
        assert!(
            rmse <= 1.10 * expected,
            "{name}: RMSE {rmse:.5} against {expected:.5} expected from the variances"
        );
    }
    for c in 0..3 {
        assert!(
            (ours[c] - theirs[c]).abs() <= 0.005 * theirs[c].max(1e-3),
            "{name}: channel {c} mean {} vs Mitsuba {}",
            ours[c],
            theirs[c]
        );
    }
    rmse / expected
}

#[test]
fn rough_conductors_match_mitsuba() {
    check(
        "roughconductor_ggx",
        "type = \"roughconductor\"\nconductor = \"Cu\"\ndistribution = \"ggx\"\nalpha = 0.2",
        SPHERE,
    );
    check(
        "roughconductor_beckmann",
        "type = \"roughconductor\"\nconductor = \"Cr\"\ndistribution = \"beckmann\"\nalpha = 0.3",
        SPHERE,
    );
    check(
        "roughconductor_anisotropic",
        "type = \"roughconductor\"\nconductor = \"Al\"\ndistribution = \"ggx\"\nalpha_u = 0.05\nalpha_v = 0.4",
        PANEL,
    );
    check(
        "conductor_gold",
        "type = \"conductor\"\nconductor = \"Au\"",
        SPHERE,
    );
}

#[test]
fn dielectrics_match_mitsuba() {
    check(
        "roughdielectric",
        "type = \"roughdielectric\"\nint_ior = \"bk7\"\ndistribution = \"ggx\"\nalpha = 0.15",
        SPHERE,
    );
    check(
        "thindielectric",
        "type = \"thindielectric\"\nint_ior = \"bk7\"",
        SPHERE,
    );
}

#[test]
fn plastic_matches_mitsuba() {
    check(
        "plastic",
        "type = \"plastic\"\ndiffuse_reflectance = [0.7, 0.1, 0.05]",
        SPHERE,
    );
}

/// Rough plastic, linear and nonlinear: the coating's transmittance table
/// is Mitsuba 3's `eval_transmittance`, E[(1 − F) G1] of the refracted
/// direction over visible normals (1 − the reflectance, as older Mitsuba
/// sources had it, was 17% high at cos θ 0.05 and the means 0.2–1.3%).
#[test]
fn rough_plastics_match_mitsuba() {
    check(
        "roughplastic",
        "type = \"roughplastic\"\ndistribution = \"ggx\"\nalpha = 0.2\n\
         diffuse_reflectance = [0.1, 0.3, 0.7]",
        SPHERE,
    );
    check(
        "roughplastic_nonlinear",
        "type = \"roughplastic\"\ndistribution = \"beckmann\"\nalpha = 0.3\nnonlinear = true\n\
         diffuse_reflectance = [0.1, 0.3, 0.7]",
        SPHERE,
    );
}

#[test]
fn one_sided_and_two_sided_backs_match_mitsuba() {
    let gold = "type = \"roughconductor\"\nconductor = \"Au\"\ndistribution = \"ggx\"\nalpha = 0.3";
    check("onesided_back", gold, BEHIND);
    check("twosided_back", &format!("{gold}\ntwosided = true"), BEHIND);
}

/// Mitsuba's tent and Gaussian pixel filters, by filter importance sampling
/// here; the box filter's image against the tent's reference fails, so the
/// test sees the filter.
#[test]
fn pixel_filters_match_mitsuba() {
    let plastic = "type = \"plastic\"\ndiffuse_reflectance = [0.7, 0.1, 0.05]";
    for (name, camera) in [
        ("filter_tent", "filter = \"tent\""),
        ("filter_gaussian", "filter = \"gaussian\""),
    ] {
        let ratio = check_with_camera(name, name, plastic, SPHERE, camera);
        assert!(
            ratio <= 1.10,
            "{name}: RMSE {ratio:.3} times its expected value"
        );
    }
    let ratio = check_with_camera("box-against-tent", "filter_tent", plastic, SPHERE, "");
    // The same bound the right filter meets (1.04 here); the box gives 1.12.
    assert!(
        ratio > 1.10,
        "the box filter passed for the tent: RMSE ratio {ratio:.3}"
    );
}

/// Checkerboard textures as Mitsuba's: on the floor (a quad's (s, t)
/// coordinates) and on the sphere ((φ / 2π, θ / π)).
#[test]
fn textures_match_mitsuba() {
    let text = material_scene("type = \"diffuse\"\nalbedo_texture = \"ball\"", SPHERE).replace(
        "[materials.floor]\ntype = \"diffuse\"\nalbedo = [0.4, 0.4, 0.4]",
        "[materials.floor]\ntype = \"diffuse\"\nalbedo_texture = \"floor\"\n\n\
         [textures.floor]\ntype = \"checkerboard\"\ncolor0 = [0.6, 0.6, 0.6]\n\
         color1 = [0.1, 0.1, 0.1]\nuv_scale = [20.0, 20.0]\n\n\
         [textures.ball]\ntype = \"checkerboard\"\ncolor0 = [0.7, 0.6, 0.1]\n\
         color1 = [0.1, 0.2, 0.6]\nuv_scale = [8.0, 8.0]",
    );
    assert!(text.contains("[textures.floor]"));
    let ratio = check_scene("textured_diffuse", &text);
    assert!(
        ratio <= 1.10,
        "textured_diffuse: RMSE {ratio:.3} times its expected value"
    );
}

/// A constant environment and an environment map (tests/data/materials/
/// sky.exr, with a small sun) beside the area light, as Mitsuba's
/// `constant` and `envmap`: the map's orientation, its texel placement and
/// its importance sampling combined with BSDF sampling by MIS.
#[test]
fn environments_match_mitsuba() {
    let constant = material_scene("type = \"diffuse\"\nalbedo = [0.6, 0.6, 0.6]", SPHERE)
        + "\n[environment]\ntype = \"constant\"\nradiance = [0.3, 0.35, 0.4]\n";
    let ratio = check_scene("environment_constant", &constant);
    assert!(ratio <= 1.10, "environment_constant: RMSE ratio {ratio:.3}");
    let sky = crate::common::repo_path("tests/data/materials/sky.exr");
    let map = material_scene(
        "type = \"roughconductor\"\nconductor = \"Cu\"\ndistribution = \"ggx\"\nalpha = 0.2",
        SPHERE,
    ) + &format!(
        "\n[environment]\ntype = \"envmap\"\nfile = {:?}\nscale = 0.5\n",
        sky.display().to_string()
    );
    let ratio = check_scene("environment_map", &map);
    assert!(ratio <= 1.10, "environment_map: RMSE ratio {ratio:.3}");
}

/// A spot light (Mitsuba's falloff) and a directional light beside the
/// area light, as Mitsuba's `spot` and `directional`.
#[test]
fn spot_and_directional_lights_match_mitsuba() {
    let grey = "type = \"diffuse\"\nalbedo = [0.6, 0.6, 0.6]";
    let spot = material_scene(grey, SPHERE)
        + "\n[[spot_light]]\nposition = [-2.0, -2.0, 2.0]\ntarget = [0.0, 0.0, 0.3]\n\
           intensity = [20.0, 18.0, 15.0]\ncutoff_angle = 25.0\nbeam_width = 15.0\n";
    let ratio = check_scene("light_spot", &spot);
    assert!(ratio <= 1.10, "light_spot: RMSE ratio {ratio:.3}");
    let sun = material_scene(grey, SPHERE)
        + "\n[[directional_light]]\ndirection = [0.8, 0.3, -0.5]\nirradiance = [1.5, 1.2, 0.9]\n";
    let ratio = check_scene("light_directional", &sun);
    assert!(ratio <= 1.10, "light_directional: RMSE ratio {ratio:.3}");
}

/// A tangent-space normal map (tests/data/materials/bumps.exr, 4 x 4 bumps
/// in the sphere's (φ / 2π, θ / π) coordinates) on a rough copper sphere,
/// as Mitsuba's `normalmap`: the frame of dp/du and the map's convention.
#[test]
fn normal_map_matches_mitsuba() {
    let bumps = crate::common::repo_path("tests/data/materials/bumps.exr");
    let text = material_scene(
        "type = \"roughconductor\"\nconductor = \"Cu\"\ndistribution = \"ggx\"\nalpha = 0.2\nnormal_map_texture = \"bumps\"",
        SPHERE,
    ) + &format!(
        "\n[textures.bumps]\ntype = \"bitmap\"\nfile = {:?}\nraw = true\n",
        bumps.display().to_string()
    );
    let ratio = check_scene("normalmap", &text);
    assert!(ratio <= 1.10, "normalmap: RMSE ratio {ratio:.3}");
    // Without the map the sphere is smooth and far from Mitsuba's render
    // (measured: RMSE 0.033 against 0.0037).
    let plain = text.replace("normal_map_texture = \"bumps\"\n", "");
    assert_ne!(plain, text);
    let (mapped, smooth) = (
        rmse_against(&text, "normalmap"),
        rmse_against(&plain, "normalmap"),
    );
    eprintln!("normal map: RMSE {mapped:.4} mapped, {smooth:.4} smooth");
    assert!(
        smooth > 2.0 * mapped,
        "the map changes little: {smooth} vs {mapped}"
    );
}

/// A bump map (tests/data/materials/heights.exr, 4 x 4 bumps, scale 0.05)
/// on the rough copper sphere, as Mitsuba's `bumpmap`: the bilinear
/// gradient in uv and both of the sphere's uv derivatives.
#[test]
fn bump_map_matches_mitsuba() {
    let heights = crate::common::repo_path("tests/data/materials/heights.exr");
    let text = material_scene(
        "type = \"roughconductor\"\nconductor = \"Cu\"\ndistribution = \"ggx\"\nalpha = 0.2\nbump_map_texture = \"heights\"\nbump_scale = 0.05",
        SPHERE,
    ) + &format!(
        "\n[textures.heights]\ntype = \"bitmap\"\nfile = {:?}\nraw = true\n",
        heights.display().to_string()
    );
    let ratio = check_scene("bumpmap", &text);
    assert!(ratio <= 1.10, "bumpmap: RMSE ratio {ratio:.3}");
    let plain = text.replace("bump_map_texture = \"heights\"\nbump_scale = 0.05\n", "");
    assert_ne!(plain, text);
    let (bumped, smooth) = (
        rmse_against(&text, "bumpmap"),
        rmse_against(&plain, "bumpmap"),
    );
    eprintln!("bump map: RMSE {bumped:.4} bumped, {smooth:.4} smooth");
    assert!(
        smooth > 2.0 * bumped,
        "the bumps change little: {smooth} vs {bumped}"
    );
}

/// The RMSE of a 256-spp path-traced render of `text` against reference
/// `name`.
fn rmse_against(text: &str, name: &str) -> f64 {
    let (snapshot, _) = render(
        load_scene_text(name, text),
        Integrator::from(PathTracer::default()),
        SamplerKind::Independent,
        256,
        1,
    );
    snapshot
        .image
        .compare(&reference(&format!("materials/{name}.exr")))
        .unwrap()
        .rmse
}
