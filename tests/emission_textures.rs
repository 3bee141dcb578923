//! Textured emission (Mitsuba's textured `radiance`, glTF's
//! `emissiveTexture`): a light half black and half white by its texture
//! lights the room as a white light of half its size does, in every
//! technique.

use crate::common::{load_scene_text, render_with, temp_dir};
use crate::import::{gltf_buffer, gltf_json};
use tracelab::film::FilmSnapshot;
use tracelab::integrator::{IntegratorKind, IntegratorOptions};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

/// A floor under a 2 × 2 light at height 1 facing down, seen from below
/// the light's plane; `light` is the light's shape element. Both the
/// light's and the floor's BSDFs are plain, and the light's black, so that
/// under direct light alone only what the light emits differs.
fn room(light: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, -4.5, 0.6" target="0, 0, 0.3" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></shape>
  {light}
</scene>"#
    )
}

/// Means of the image's regions in a grid of `columns` × `rows` (row-major
/// from the top left), with their standard errors (each region's pixels
/// as independent, times the film's correlation).
fn region_means(snapshot: &FilmSnapshot, columns: usize, rows: usize) -> Vec<(f64, f64)> {
    let (width, height) = (
        snapshot.image.width as usize,
        snapshot.image.height as usize,
    );
    let mut sums = vec![(0.0f64, 0.0f64, 0usize); columns * rows];
    for (i, (p, se)) in snapshot
        .image
        .pixels
        .iter()
        .zip(&snapshot.standard_error.pixels)
        .enumerate()
    {
        let region = (i / width) * rows / height * columns + (i % width) * columns / width;
        let luminance = |c: &[f32; 3]| (c[0] + c[1] + c[2]) as f64 / 3.0;
        sums[region].0 += luminance(p);
        sums[region].1 += luminance(se).powi(2);
        sums[region].2 += 1;
    }
    sums.into_iter()
        .map(|(sum, var, n)| {
            let n = n as f64;
            (sum / n, (var * snapshot.correlation).sqrt() / n)
        })
        .collect()
}

/// Asserts that two renders' regions agree within 4 standard errors of
/// their difference (the renders independent).
fn assert_regions_agree(got: &[(f64, f64)], want: &[(f64, f64)], what: &str) {
    for (region, (&(g, g_error), &(w, w_error))) in got.iter().zip(want).enumerate() {
        let error = g_error.hypot(w_error);
        assert!(
            (g - w).abs() < 4.0 * error,
            "{what}, region {region}: {g} against {w} ± {error}"
        );
    }
}

/// The regions' means of `scene` rendered by `kind` under direct light
/// (one bounce), 64 spp.
fn direct_regions(
    scene: Scene,
    kind: IntegratorKind,
    columns: usize,
    rows: usize,
) -> Vec<(f64, f64)> {
    let mut options = IntegratorOptions::of(kind);
    if let Some(depth) = options.max_depth_mut() {
        *depth = 1;
    }
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let (snapshot, stats) = render_with(
        scene,
        options.build(),
        SamplerKind::Independent,
        64,
        1,
        0,
        8,
    );
    assert_eq!(stats.non_finite, 0);
    region_means(&snapshot, columns, rows)
}

/// The light's texture is 2 × 1 texels, black then white, read nearest:
/// its u < 1/2 half emits nothing, the other half 1. That half is x > 0
/// (Mitsuba's rectangle has u = (x + 1) / 2), so the image's right half
/// is lit and its left half dim. The same render with a white light on
/// x in [0, 1] alone must agree in both halves, within 4 standard errors
/// of the difference (two independent renders). Reading the texture's
/// mean instead (as before textured lights were sampled) lit both halves
/// alike: the right half 40% too dark.
#[test]
fn a_half_black_light_lights_the_room_as_a_light_of_half_its_size_in_every_technique() {
    let dir = temp_dir("emission-texture");
    image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255])
        .unwrap()
        .save(dir.join("half.png"))
        .unwrap();
    let black = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>"#;
    let textured = format!(
        r#"<shape type="rectangle"><transform name="to_world"><rotate x="1" angle="180"/><translate z="1"/></transform>
    {black}<emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="half.png"/>
      <string name="filter_type" value="nearest"/></texture></emitter></shape>"#
    );
    let half = format!(
        r#"<shape type="rectangle"><transform name="to_world"><scale x="0.5"/><translate x="0.5"/><rotate x="1" angle="180"/><translate z="1"/></transform>
    {black}<emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
    );
    let halves = |name: &str, light: &str, kind| {
        let file = dir.join(format!("{name}.xml"));
        std::fs::write(&file, room(light)).unwrap();
        direct_regions(
            Scene::load(&file).unwrap_or_else(|e| panic!("{e}")),
            kind,
            2,
            1,
        )
    };
    for kind in [
        IntegratorKind::Path,
        IntegratorKind::Light,
        IntegratorKind::Bdpt,
        IntegratorKind::Vcm,
        IntegratorKind::Mcrt,
    ] {
        let (got, want) = (
            halves("textured", &textured, kind),
            halves("half", &half, kind),
        );
        assert!(
            want[1].0 > 2.0 * want[0].0,
            "{kind:?}: the lit half should stand out: {want:?}"
        );
        assert_regions_agree(&got, &want, &format!("{kind:?}"));
    }
}

/// A sphere light whose texture lights one quadrant of its (u, v) square
/// above a floor, seen from above: light tracing (which reads the texture
/// where particles start) and BDPT give path tracing's image in each
/// quarter of the frame, which they would not if a light sample's
/// texture coordinates differed from a hit's.
#[test]
fn a_textured_sphere_light_gives_every_technique_the_same_image() {
    let text = r#"
[camera]
eye = [0.3, -1.0, 4.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_y = 60.0
width = 40
height = 32

[textures.quadrant]
type = "checkerboard"
color0 = [0.0, 0.0, 0.0]
color1 = [6.0, 6.0, 6.0]

[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission_texture = "quadrant"

[[quad]]
corner = [-3.0, -3.0, 0.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 6.0, 0.0]
material = "floor"

[[sphere]]
center = [0.2, 0.1, 0.9]
radius = 0.5
material = "lamp"
"#;
    let regions = |kind| direct_regions(load_scene_text("sphere-lamp", text), kind, 2, 2);
    let path = regions(IntegratorKind::Path);
    for kind in [IntegratorKind::Light, IntegratorKind::Bdpt] {
        assert_regions_agree(&regions(kind), &path, &format!("{kind:?}"));
    }
    // A name that no texture has is an error naming it.
    let dir = temp_dir("sphere-lamp-typo");
    let file = dir.join("scene.toml");
    std::fs::write(&file, text.replace("= \"quadrant\"", "= \"quadrnat\"")).unwrap();
    let error = Scene::load(&file)
        .expect_err("an unknown texture")
        .to_string();
    assert!(
        error.contains("unknown texture `quadrnat` for `emission_texture`"),
        "{error}"
    );
}

/// glTF's `emissiveTexture` multiplies the emissive factor at each point,
/// without a warning (its mean was once used, with one).
#[test]
fn gltf_emissive_textures_are_read_where_the_light_is_hit_or_sampled() {
    let dir = temp_dir("gltf-emissive");
    std::fs::write(dir.join("quad.bin"), gltf_buffer()).unwrap();
    image::RgbImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255])
        .unwrap()
        .save(dir.join("half.png"))
        .unwrap();
    let json = gltf_json(Some("quad.bin"))
        .replace(
            r#"{"primitives": [{"attributes": {"POSITION": 0}, "indices": 3, "material": 1}]}"#,
            r#"{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 3, "material": 1}]}"#,
        )
        .replace(
            r#""emissiveFactor": [1, 1, 1],"#,
            r#""emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0},"#,
        )
        .replace(
            r#""buffers":"#,
            r#""images": [{"uri": "half.png"}], "textures": [{"source": 0}], "buffers":"#,
        );
    assert!(
        json.contains("emissiveTexture")
            && json.contains(r#""TEXCOORD_0": 2}, "indices": 3, "material": 1"#)
    );
    let file = dir.join("lamp.gltf");
    std::fs::write(&file, json).unwrap();
    let scene = Scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let lamp = scene
        .materials
        .iter()
        .find(|m| m.is_emissive())
        .expect("the lamp");
    assert!(lamp.emission_texture.is_some());
    assert_eq!(lamp.emission, glam::Vec3A::splat(5.0));
}
