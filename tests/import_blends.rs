//! Blends of two BSDFs (Mitsuba's `blendbsdf`, glTF's metallic between 0
//! and 1) against the weighted sum of their parts, and Mitsuba 3's
//! normal- and bump-map term named where a file meets it.

use crate::common::temp_dir;
use crate::import::{gltf_buffer, gltf_json, load};
use tracelab::integrator::{IntegratorKind, IntegratorOptions};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

/// The image mean of `scene` by `options` (64 spp) and its standard error.
type MeanAndError = ([f64; 3], [f64; 3]);

fn direct_mean(scene: Scene, options: &IntegratorOptions) -> MeanAndError {
    let (snapshot, stats) = crate::common::render_with(
        scene,
        options.build(),
        SamplerKind::Independent,
        64,
        1,
        0,
        8,
    );
    assert_eq!(stats.non_finite, 0);
    crate::common::mean_and_standard_error(&snapshot)
}

/// Asserts that `blend` is (1 − w) `first` + w `second`, within 4
/// standard errors of that difference (the three renders independent).
fn assert_mixes(
    w: f64,
    first: MeanAndError,
    second: MeanAndError,
    blend: MeanAndError,
    what: &str,
) {
    let ((a, a_error), (b, b_error), (m, m_error)) = (first, second, blend);
    for c in 0..3 {
        let expected = (1.0 - w) * a[c] + w * b[c];
        let error =
            (m_error[c].powi(2) + ((1.0 - w) * a_error[c]).powi(2) + (w * b_error[c]).powi(2))
                .sqrt();
        assert!(
            (m[c] - expected).abs() < 4.0 * error,
            "{what}, channel {c}: {} against {expected} ± {error} (first alone {}, second {})",
            m[c],
            a[c],
            b[c]
        );
    }
}

/// A `blendbsdf` is the weighted sum of its two BSDFs. Under direct light
/// alone every path meets the blended sphere once, so the blend's image is
/// (1 − w) times the first BSDF's image plus w times the second's, for
/// path tracing, light tracing and BDPT alike (before blends were read,
/// the first BSDF alone was rendered: 5% off on a probe against Mitsuba 3).
/// A weight texture that reads w everywhere gives the same image.
/// Tolerance: 4 standard errors of that difference, from the renders'
/// per-pixel standard errors, as independent.
#[test]
fn a_blend_is_the_weighted_sum_of_its_two_bsdfs_in_every_technique() {
    let scene = |bsdf: &str| {
        format!(
            r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -6, 3" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0" z="0.7"/><float name="radius" value="0.7"/>{bsdf}</shape>
  <shape type="sphere"><point name="center" x="1" y="-1" z="3"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="30"/></emitter></shape>
</scene>"#
        )
    };
    let diffuse = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.5, 0.3"/></bsdf>"#;
    let metal = r#"<bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="material" value="Cu"/></bsdf>"#;
    let w = 0.3;
    let blends = [
        format!(
            r#"<bsdf type="blendbsdf"><float name="weight" value="{w}"/>{diffuse}{metal}</bsdf>"#
        ),
        format!(
            r#"<bsdf type="blendbsdf"><texture type="checkerboard" name="weight"><float name="color0" value="{w}"/><float name="color1" value="{w}"/></texture>{diffuse}{metal}</bsdf>"#
        ),
    ];
    for kind in [
        IntegratorKind::Path,
        IntegratorKind::Light,
        IntegratorKind::Bdpt,
    ] {
        let mut options = IntegratorOptions::of(kind);
        *options.max_depth_mut().expect("a depth") = 1;
        let mean = |name: &str, bsdf: &str| {
            let scene = load(name, &scene(bsdf), &[], true).unwrap_or_else(|e| panic!("{e}"));
            direct_mean(scene, &options)
        };
        let (first, second) = (mean("blend-diffuse", diffuse), mean("blend-metal", metal));
        for (i, blend) in blends.iter().enumerate() {
            let what = format!("{kind:?}, blend {i}");
            assert_mixes(w, first, second, mean("blend", blend), &what);
        }
    }
}

/// Mitsuba 3's `normalmap` and `bumpmap` shade by a terminator term that
/// tracelab does not apply: a 3.0 file is told so at each map; a 0.6 file,
/// whose plugins had no such term, renders as its renderer did, silently.
#[test]
fn normal_and_bump_maps_warn_of_mitsuba_3s_terminator_term_only_in_version_3() {
    let xml = |version: &str| {
        format!(
            r#"<scene version="{version}">
  <shape type="cube">
    <bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/><bsdf type="diffuse"/></bsdf>
  </shape>
  <shape type="sphere">
    <bsdf type="bumpmap"><texture type="checkerboard"/><bsdf type="diffuse"/></bsdf>
  </shape>
</scene>"#
        )
    };
    let mapped = |scene: &Scene| {
        scene
            .materials
            .iter()
            .filter(|m| m.normal_map.is_some())
            .count()
    };
    let scene = load("maps-3", &xml("3.0.0"), &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mapped(&scene), 2);
    let w = scene.warnings.join("\n");
    for expected in [
        "scene.xml:3:5: normalmap: Mitsuba 3's terminator term",
        "scene.xml:6:5: bumpmap: Mitsuba 3's terminator term",
    ] {
        assert!(w.contains(expected), "missing {expected:?} in\n{w}");
    }
    let scene = load("maps-0.6", &xml("0.6.0"), &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mapped(&scene), 2);
    assert!(
        !scene.warnings.iter().any(|w| w.contains("terminator term")),
        "{:?}",
        scene.warnings
    );
}

/// glTF's BRDF mixes the dielectric and the metal by `metallic`: a floor
/// of metallic 0.4 renders as 0.6 times the dielectric floor plus 0.4
/// times the metal one under direct light (before blends, it rendered as
/// the dielectric, with a warning). Tolerance as in the blendbsdf test.
#[test]
fn gltf_metallic_between_zero_and_one_blends_the_dielectric_and_the_metal() {
    let dir = temp_dir("gltf-metallic");
    std::fs::write(dir.join("quad.bin"), gltf_buffer()).unwrap();
    let mut options = IntegratorOptions::of(IntegratorKind::Path);
    *options.max_depth_mut().expect("a depth") = 1;
    let mean = |metallic: &str| {
        let file = dir.join(format!("metal-{metallic}.gltf"));
        let json = gltf_json(Some("quad.bin")).replace(
            r#""metallicFactor": 0, "roughnessFactor": 0.5"#,
            &format!(r#""metallicFactor": {metallic}, "roughnessFactor": 0.5"#),
        );
        std::fs::write(&file, json).unwrap();
        let mut scene = Scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        scene.set_resolution(48, 32);
        direct_mean(scene, &options)
    };
    assert_mixes(0.4, mean("0"), mean("1"), mean("0.4"), "metallic 0.4");
}

/// A normal or bump map around a `blendbsdf` tilts both of its BSDFs (the
/// second one once rendered flat: half a floor's points unmapped).
#[test]
fn a_map_around_a_blend_tilts_both_of_its_bsdfs() {
    for map in [
        r#"<bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/>"#,
        r#"<bsdf type="bumpmap"><texture type="checkerboard"/>"#,
    ] {
        let xml = format!(
            r#"<scene version="3.0.0">
  <shape type="rectangle">
    {map}<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf></bsdf>
  </shape>
</scene>"#
        );
        let scene = load("map-blend", &xml, &[], false).unwrap_or_else(|e| panic!("{e}"));
        let blended = scene
            .materials
            .iter()
            .find_map(|m| m.blend)
            .expect("a blend");
        let first = scene.materials.iter().find(|m| m.blend.is_some()).unwrap();
        assert!(first.normal_map.is_some(), "{map}");
        assert_eq!(
            scene.materials[blended.second as usize].normal_map, first.normal_map,
            "{map}"
        );
    }
}
