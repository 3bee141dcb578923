//! What Mitsuba 3's documentation scenes use (mitsuba-data, `docs/scenes`):
//! roughness read from textures, objects declared at the top level and
//! used where a `<ref>` names them, and integrators' default depth.

use crate::common::{mean_and_standard_error, render};
use crate::import::load;
use glam::Vec2;
use tracelab::bsdf::{Bsdf, Microfacet};
use tracelab::integrator::{IntegratorKind, IntegratorOptions, Strategy};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

const SENSOR: &str = r#"<sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0"/></transform>
  </sensor>"#;

/// A checkerboard of two values, 4 × 4 squares over the unit square.
fn checks(name: &str, a: f32, b: f32) -> String {
    format!(
        r#"<texture name="{name}" type="checkerboard">
      <transform name="to_uv"><scale x="2" y="2"/></transform>
      <float name="color0" value="{a}"/><float name="color1" value="{b}"/>
    </texture>"#
    )
}

/// The microfacet distribution of material `name` at `uv`.
fn microfacet(scene: &Scene, name: &str, uv: Vec2) -> Microfacet {
    let m = scene.materials.iter().find(|m| m.name == name).unwrap();
    match m.bsdf_at(&scene.textures, uv) {
        Bsdf::RoughConductor { lobe, .. } => lobe.microfacet,
        Bsdf::RoughDielectric(lobe) => lobe.microfacet,
        Bsdf::RoughPlastic { lobe, .. } => lobe.microfacet,
        other => panic!("{name}: {other:?}"),
    }
}

/// `alpha`, `alpha_u` and `alpha_v` as textures, as Mitsuba's
/// `bsdf_roughconductor_textured_carbon.xml` and
/// `bsdf_roughdielectric_textured.xml` give them: read at each hit, each
/// axis from its own texture.
#[test]
fn roughness_textures_are_read_at_each_hit() {
    let xml = format!(
        r#"<scene version="3.0.0">
  {SENSOR}
  <bsdf type="roughconductor" id="carbon">
    <string name="distribution" value="beckmann"/>
    {}
    {}
    <string name="material" value="Al"/>
  </bsdf>
  <bsdf type="roughdielectric" id="frosted">{}</bsdf>
  <bsdf type="roughplastic" id="plastic">{}</bsdf>
  <shape type="rectangle"><ref id="carbon"/></shape>
  <shape type="rectangle"><ref id="frosted"/></shape>
  <shape type="rectangle"><ref id="plastic"/></shape>
  <emitter type="constant"/>
</scene>"#,
        checks("alpha_u", 0.05, 0.3),
        checks("alpha_v", 0.3, 0.05),
        checks("alpha", 0.0, 0.4),
        checks("alpha", 0.1, 0.2),
    );
    let scene = load("rough_textures", &xml, &[], true).unwrap_or_else(|e| panic!("{e}"));
    // Read as one value, Mitsuba's checkerboard swaps its squares (its
    // `eval_1` gives color1 where `eval` gives color0): the first square
    // (u, v < 1/4) is color1 here, the next along u color0.
    let (first, second) = (Vec2::new(0.1, 0.1), Vec2::new(0.35, 0.1));
    let alphas = |name: &str, uv: Vec2| {
        let m = microfacet(&scene, name, uv);
        (m.alpha_u, m.alpha_v)
    };
    let close = |a: (f32, f32), b: (f32, f32)| (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6;
    assert!(
        close(alphas("carbon", first), (0.3, 0.05)),
        "{:?}",
        alphas("carbon", first)
    );
    assert!(
        close(alphas("carbon", second), (0.05, 0.3)),
        "{:?}",
        alphas("carbon", second)
    );
    // α 0 is kept off the delta limit (the model's minimum), as untextured.
    let smooth = alphas("frosted", second);
    assert!(
        smooth.0 == smooth.1 && smooth.0 > 0.0 && smooth.0 < 1e-3,
        "{smooth:?}"
    );
    assert!(close(alphas("frosted", first), (0.4, 0.4)));
    assert!(close(alphas("plastic", first), (0.2, 0.2)));
    assert!(close(alphas("plastic", second), (0.1, 0.1)));
    // One texture per roughness element, each loaded once.
    assert_eq!(scene.textures.len(), 4);
}

/// Mitsuba's cbox and sampler scenes declare the area emitter and the
/// sampler at the top level and name them by `<ref>` inside a shape and a
/// sensor: used there, with no warning that they were skipped.
#[test]
fn declarations_used_by_reference_are_not_warned_about() {
    let xml = r#"<scene version="3.0.0">
  <sampler type="independent" id="my_sampler"><integer name="sample_count" value="16"/></sampler>
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0"/></transform>
    <ref id="my_sampler"/>
  </sensor>
  <shape type="rectangle"><ref id="light"/></shape>
  <emitter type="area" id="light"><rgb name="radiance" value="3"/></emitter>
</scene>"#;
    let scene = load("declared", xml, &[], true).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.hints.spp, Some(16));
    assert_eq!(scene.lights.as_slice().len(), 1);
    // Declared and named by nothing, it still says what was left out.
    let unused = xml.replace(r#"<ref id="light"/>"#, "");
    let scene = load("declared_unused", &unused, &[], false).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        scene.warnings.iter().any(|w| w.contains(":8:3:")),
        "{:?}",
        scene.warnings
    );
}

/// Mitsuba's integrators default to `max_depth` -1, unbounded: the
/// material previews (`include/matpreview.xml`) give only
/// `<integrator type="path"/>`, and their glass lost a tenth of its light
/// when that was read as tracelab's own default depth.
#[test]
fn an_integrator_without_max_depth_is_unbounded_as_in_mitsuba() {
    let scene = |integrator: &str| {
        let xml = format!(
            r#"<scene version="3.0.0">{integrator}{SENSOR}<shape type="cube"/><emitter type="constant"/></scene>"#
        );
        load("default_depth", &xml, &[], true).unwrap_or_else(|e| panic!("{e}"))
    };
    for plugin in ["path", "volpath", "bdpt", "ptracer"] {
        let hints = scene(&format!(r#"<integrator type="{plugin}"/>"#)).hints;
        assert_eq!(
            hints.max_depth,
            Some(tracelab::scene::UNBOUNDED_DEPTH),
            "{plugin}"
        );
    }
    let given = r#"<integrator type="path"><integer name="max_depth" value="4"/></integrator>"#;
    assert_eq!(scene(given).hints.max_depth, Some(3));
    // No integrator at all: Mitsuba 3 refuses to render; tracelab's defaults.
    assert_eq!(scene("").hints.max_depth, None);
}

/// Mitsuba's -1 has no limit where roulette ends the paths: inside a
/// closed cube of albedo a = 0.98 that emits 1 everywhere (a white
/// furnace), L = 1 / (1 - a) = 50, while paths cut at 100 bounces, the
/// limit that stood for -1 before, find 50 (1 - a^101) = 43.5. Mitsuba's
/// diamond preview, whose light circles by total internal reflection, was
/// 1.4% dark at that limit. Roulette starts at 1 000 bounces, as in that
/// file: earlier, Mitsuba's survival probability (at most 0.95) against an
/// albedo above its square root would make the variance infinite.
///
/// Tolerance: 3 standard errors of the image mean (per-pixel standard
/// errors combined as `mean_and_standard_error`); the test also checks that
/// 43.5 lies beyond 6 of them, so that it can fail.
#[test]
fn an_unbounded_depth_has_no_limit_where_roulette_ends_paths() {
    let xml = r#"<scene version="3.0.0">
  <integrator type="path"><integer name="rr_depth" value="1000"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="90"/>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
  </sensor>
  <shape type="cube">
    <boolean name="flip_normals" value="true"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.98"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter>
  </shape>
</scene>"#;
    let scene = load("unbounded_furnace", xml, &[], true).unwrap_or_else(|e| panic!("{e}"));
    let mut options = IntegratorOptions::default();
    let said = options.take_hints(&scene.hints, false).unwrap();
    assert!(said.iter().any(|s| s == "max depth no limit"), "{said:?}");
    assert_eq!(options.max_depth(), Some(tracelab::scene::UNBOUNDED_DEPTH));
    options.validate().unwrap();
    let (snapshot, stats) = render(scene, options.build(), SamplerKind::Independent, 16, 1);
    assert_eq!(stats.non_finite, 0);
    let (mean, se) = mean_and_standard_error(&snapshot);
    let (expected, truncated) = (50.0, 50.0 * (1.0 - 0.98f64.powi(101)));
    for c in 0..3 {
        let z = (mean[c] - expected) / se[c];
        assert!(
            z.abs() < 3.0,
            "channel {c}: {} against {expected} (z {z:.2})",
            mean[c]
        );
        assert!(
            (expected - truncated) / se[c] > 6.0,
            "too few samples to tell: {}",
            se[c]
        );
    }
    // Without roulette, no limit would never end a trapped path: refused.
    options.length_mut().unwrap().russian_roulette = false;
    assert!(options.validate().unwrap_err().contains("Russian roulette"));
}

/// Two spot lights beside a dim constant environment over a wide floor, as
/// Mitsuba's `emitter_spot_no_texture.xml`: by power, the environment's
/// flux through a disc around the whole floor took 95% of the shadow rays
/// and the lit spots were speckled (at equal time the MSE against Mitsuba
/// was 13 times today's). The scene's pilot gives the spots what they
/// deliver where the camera looks, and the image stays the same: it must
/// equal the sum of the environment alone and the spots alone, each of
/// which has nothing to choose between.
///
/// Tolerance: 4 standard errors of the difference of the image means
/// (per-pixel standard errors combined as `mean_and_standard_error`).
#[test]
fn shadow_rays_go_where_the_light_arrives_and_the_image_stays_the_same() {
    let scene = |emitters: &str| {
        let xml = format!(
            r#"<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="3.7, -3.5, 3.3" target="0, 0, 0.5" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/></film>
  </sensor>
  <shape type="rectangle">
    <transform name="to_world"><scale value="40"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.3"/></bsdf>
  </shape>
  <shape type="sphere"><point name="center" x="0" y="0" z="1"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>
  </shape>
  {emitters}
</scene>"#
        );
        load("spots", &xml, &[], true).unwrap_or_else(|e| panic!("{e}"))
    };
    let environment = r#"<emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>"#;
    let spots = r#"<emitter type="spot"><rgb name="intensity" value="200, 0, 0"/><float name="cutoff_angle" value="20"/>
      <transform name="to_world"><lookat origin="4, 0, 3.5" target="0, 0, 1"/></transform></emitter>
    <emitter type="spot"><rgb name="intensity" value="0, 0, 200"/><float name="cutoff_angle" value="20"/>
      <transform name="to_world"><lookat origin="0.3, -4, 3.5" target="0, 0, 1"/></transform></emitter>"#;
    let both = scene(&format!("{environment}{spots}"));
    let summary = both.lights.direct_summary().expect("two groups to weigh");
    let spot_share: f32 = (0..2).map(|i| both.lights.direct_pmf(i)).sum();
    assert!(spot_share > 0.3, "{summary}");
    // Each alone: nothing to weigh, power decides as before.
    let (alone_env, alone_spots) = (scene(environment), scene(spots));
    assert!(alone_env.lights.direct_summary().is_none());
    assert!(alone_spots.lights.direct_summary().is_none());

    let mean = |scene: Scene, seed: u64| {
        let mut options = IntegratorOptions::default();
        options.take_hints(&scene.hints, false).unwrap();
        let (snapshot, stats) = render(scene, options.build(), SamplerKind::Independent, 64, seed);
        assert_eq!(stats.non_finite, 0);
        mean_and_standard_error(&snapshot)
    };
    let ((m, s), (me, se), (ms, ss)) = (mean(both, 1), mean(alone_env, 2), mean(alone_spots, 3));
    for c in 0..3 {
        let sum = me[c] + ms[c];
        let sigma = (s[c].powi(2) + se[c].powi(2) + ss[c].powi(2)).sqrt();
        let z = (m[c] - sum) / sigma;
        assert!(
            z.abs() < 4.0,
            "channel {c}: {} against {sum} (z {z:.2}); {summary}",
            m[c]
        );
    }
}

/// Mitsuba's `direct` integrator with one of its sample counts 0, as
/// `integrator_direct_lum.xml` and `_bsdf.xml` give Veach's MIS figure:
/// path tracing's one bounce with that strategy alone, not MIS.
#[test]
fn the_direct_integrators_sample_counts_choose_the_strategy() {
    let scene = |integrator: &str, strict: bool| {
        let xml = format!(
            r#"<scene version="3.0.0"><integrator type="direct">{integrator}</integrator>{SENSOR}<shape type="cube"/><emitter type="constant"/></scene>"#
        );
        load("direct", &xml, &[], strict)
    };
    let counts = |e: i32, b: i32| {
        format!(
            r#"<integer name="emitter_samples" value="{e}"/><integer name="bsdf_samples" value="{b}"/>"#
        )
    };
    for ((e, b), strategy, said) in [
        ((1, 0), Strategy::Light, "strategy light"),
        ((0, 1), Strategy::Bsdf, "strategy bsdf"),
        ((1, 1), Strategy::Mis, "strategy mis"),
    ] {
        let loaded = scene(&counts(e, b), true).unwrap_or_else(|err| panic!("{err}"));
        assert_eq!(loaded.hints.max_depth, Some(1));
        let mut options = IntegratorOptions::default();
        let taken = options.take_hints(&loaded.hints, false).unwrap();
        assert!(taken.iter().any(|t| t == said), "{taken:?}");
        assert_eq!(options.path.strategy, strategy);
        // Another technique chosen on the command line keeps its own.
        let mut bdpt = IntegratorOptions::of(IntegratorKind::Bdpt);
        assert!(
            !bdpt
                .take_hints(&loaded.hints, true)
                .unwrap()
                .iter()
                .any(|t| t == said)
        );
    }
    // The default (shading_samples 1) is both; none leaves the emitters seen.
    assert_eq!(
        scene("", true).unwrap().hints.strategy.as_deref(),
        Some("mis")
    );
    assert_eq!(scene(&counts(0, 0), true).unwrap().hints.max_depth, Some(0));
    // More than one sample of a kind is said, and an error under --strict.
    let many = scene(&counts(4, 2), false).unwrap();
    assert!(
        many.warnings
            .iter()
            .any(|w| w.contains("4 emitter and 2 BSDF samples")),
        "{:?}",
        many.warnings
    );
    assert!(scene(&counts(4, 2), true).is_err());
    let negative = scene(&counts(-1, 1), false).unwrap_err().to_string();
    assert!(
        negative.contains("emitter_samples must be >= 0"),
        "{negative}"
    );
}
