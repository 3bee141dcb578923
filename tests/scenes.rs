//! Every scene shipped in `scenes/` (TOML, and Mitsuba XML in its own
//! folder) loads without warnings and renders
//! without a single non-finite sample.

use crate::common::{render, repo_path};
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

/// tracelab's TOML scenes, and the imported ones (`scenes/NAME/scene.xml`).
fn shipped_scenes() -> Vec<std::path::PathBuf> {
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(repo_path("scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            paths.push(path);
        } else if path.join("scene.xml").is_file() {
            paths.push(path.join("scene.xml"));
        }
    }
    paths.sort();
    paths
}

#[test]
fn every_shipped_scene_renders_cleanly() {
    let mut count = 0;
    for path in shipped_scenes() {
        let mut scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            scene.warnings.is_empty(),
            "{}: {:?}",
            path.display(),
            scene.warnings
        );
        scene.set_resolution(40, 30);
        for nee in [true, false] {
            let tracer = PathTracer {
                nee,
                ..Default::default()
            };
            let (snapshot, stats) = render(
                scene.clone(),
                Integrator::from(tracer),
                SamplerKind::Stratified,
                16,
                1,
            );
            assert_eq!(stats.non_finite, 0, "{}", path.display());
            // BSDF sampling alone cannot find point lights.
            let findable = nee || scene.features.area_lights > 0;
            assert!(
                !findable || snapshot.image.mean().iter().all(|&m| m > 0.0),
                "{} renders black",
                path.display()
            );
        }
        count += 1;
    }
    assert!(count >= 8);
}

/// Every estimator on every scene for 64 spp: not one non-finite sample.
#[test]
fn every_estimator_renders_every_scene_without_non_finite_samples() {
    use tracelab::integrator::{IntegratorKind, IntegratorOptions};
    for path in shipped_scenes() {
        let mut scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        scene.set_resolution(24, 18);
        for kind in [
            IntegratorKind::Whitted,
            IntegratorKind::Mcrt,
            IntegratorKind::Path,
            IntegratorKind::Light,
        ] {
            let integrator = IntegratorOptions {
                kind,
                ..Default::default()
            }
            .build();
            let spp = if integrator.is_deterministic() { 1 } else { 64 };
            let (snapshot, stats) = render(scene.clone(), integrator, SamplerKind::Sobol, spp, 3);
            assert_eq!(stats.non_finite, 0, "{} {kind:?}", path.display());
            assert_eq!(snapshot.non_finite, 0, "{} {kind:?}", path.display());
            assert!(
                snapshot
                    .image
                    .pixels
                    .iter()
                    .flatten()
                    .all(|c| c.is_finite() && *c >= 0.0),
                "{} {kind:?}",
                path.display()
            );
        }
    }
}

/// The Cornell box's light (a quad in its OBJ, two triangles) is sampled as
/// one parallelogram of its full area, 130 x 105 mm.
#[test]
fn the_cornell_box_light_is_one_parallelogram() {
    use tracelab::scene::light::Light;
    let scene = crate::common::cornell_box();
    let lights = scene.lights.as_slice();
    assert_eq!(lights.len(), 1, "{lights:?}");
    let Light::Parallelogram(light) = lights[0] else {
        panic!("{:?}", lights[0]);
    };
    assert!((light.area - 130.0 * 105.0).abs() < 0.5, "{}", light.area);
    // One-sided, facing down into the box.
    assert!(light.normal.y < -0.999, "{}", light.normal);
}
