//! What every target does with a scene that loaded: build it and render one
//! sample per pixel of a tiny image, so that a scene that loads but breaks
//! the BVH, the lights or the tracer is found too.

use std::sync::Arc;
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::render::{RenderSettings, Session};
use tracelab::sampling::SamplerKind;
use tracelab::scene::{Limits, LoadOptions, Scene, SceneInput};

/// Small limits: a fuzzer must not spend its time on huge meshes or images.
pub fn limits() -> Limits {
    Limits {
        max_resolution: 64,
        max_triangles: 4096,
    }
}

pub fn build_and_render(input: SceneInput) {
    let Ok(mut scene) = Scene::build(input) else {
        return;
    };
    scene.set_resolution(4, 4);
    let settings = RenderSettings {
        integrator: Integrator::from(PathTracer {
            max_depth: 4,
            ..PathTracer::default()
        }),
        sampler: SamplerKind::Independent,
        seed: 0,
        planned_spp: 1,
        threads: 1,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    if let Ok(session) = Session::new(Arc::new(scene), settings) {
        session.render_pass(1);
    }
}

/// Loads any scene file the loader knows (by its extension) with the small
/// limits, and builds and renders what loads.
#[allow(dead_code)] // the targets that parse text themselves do not call it
pub fn load_and_render(path: &std::path::Path) {
    let options = LoadOptions {
        limits: limits(),
        ..Default::default()
    };
    if let Ok(input) = tracelab::scene::load::load_any(path, &options) {
        build_and_render(input);
    }
}
