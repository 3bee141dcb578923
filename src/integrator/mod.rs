//! Estimators of the rendering equation, one file each, behind one interface:
//! given a camera ray and a sampler, return a radiance sample. The enum is
//! dispatched once per camera sample, never inside the bounce loop.
//!
//! Light tracing runs the other way (particles from the lights splat onto
//! the film), so it has its own entry point, [`LightTracer::trace_particle`],
//! which the render session calls instead of [`Integrator::radiance`].

pub mod light;
pub mod mcrt;
pub mod mis;
pub mod options;
pub mod path;
pub mod whitted;

pub use light::LightTracer;
pub use mcrt::McRayTracer;
pub use mis::MisHeuristic;
pub use options::{IntegratorKind, IntegratorOptions, Strategy};
pub use path::PathTracer;
pub use whitted::{GlassShadows, WhittedTracer};

use crate::accel::PrimaryPixel;
use crate::math::{Ray, Rgb};
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;

/// Rays cast, by kind; kept per thread and summed after each tile. For light
/// tracing, `camera` counts the rays leaving the lights (the primary rays)
/// and `shadow` the connections to the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub camera: u64,
    pub shadow: u64,
    pub bounce: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.bounce
    }
}

/// Russian roulette (after the first `rr_depth` bounces): the path survives
/// with probability q = min(max(beta), 0.95) (Mitsuba's choice) and is
/// reweighted by 1/q, which keeps the estimate unbiased while paths that
/// carry little energy end early. Returns false when the path ends.
#[inline]
pub(crate) fn survives_roulette(beta: &mut Rgb, u: f32) -> bool {
    let q = beta.max_element().min(0.95);
    if u >= q {
        return false;
    }
    *beta /= q;
    true
}

/// The time of a path: uniform over the shutter interval when something
/// moves while the shutter is open, else the shutter's opening without
/// consuming a dimension (a static scene has no time dimension). `always`
/// draws the time anyway, as a renderer without feature detection would.
#[inline]
pub fn sample_time(scene: &Scene, sampler: &mut Sampler, always: bool) -> f32 {
    if scene.features.motion || always {
        scene.camera.time(sampler.next_1d_for(Domain::Time))
    } else {
        scene.camera.shutter_open
    }
}

/// A configured estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    Whitted(WhittedTracer),
    Mcrt(McRayTracer),
    Path(PathTracer),
    Light(LightTracer),
}

impl Integrator {
    /// One radiance sample along the camera ray `ray`. Counts the rays it
    /// casts after the camera ray into `counts`. `pixel`: what is known in
    /// advance about the ray's pixel (path and MC ray tracing use it).
    #[inline]
    pub fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        match self {
            Integrator::Whitted(w) => w.radiance(scene, ray, counts),
            Integrator::Mcrt(m) => m.radiance(scene, ray, pixel.seen_emission, sampler, counts),
            Integrator::Path(p) => p.radiance(scene, ray, pixel, sampler, counts),
            // Light tracing splats instead; the session never calls this for it.
            Integrator::Light(_) => Rgb::ZERO,
        }
    }

    /// Short description for summaries and file names.
    pub fn describe(&self) -> String {
        match self {
            Integrator::Whitted(w) => w.describe(),
            Integrator::Mcrt(m) => m.describe(),
            Integrator::Path(p) => p.describe(),
            Integrator::Light(l) => l.describe(),
        }
    }

    /// Short name, as the command line spells it.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Whitted(_) => "whitted",
            Integrator::Mcrt(_) => "mcrt",
            Integrator::Path(_) => "path",
            Integrator::Light(_) => "light",
        }
    }

    /// True when the estimator adds [`PrimaryPixel::seen_emission`] where it
    /// is known instead of sampling the emission camera rays hit.
    pub fn integrates_seen_emitters(&self) -> bool {
        match self {
            Integrator::Mcrt(m) => m.exact_seen_emitters,
            Integrator::Path(p) => p.exact_seen_emitters,
            Integrator::Whitted(_) | Integrator::Light(_) => false,
        }
    }

    /// True when every sample of a pixel gives the same value (Whitted: one
    /// ray through the pixel centre), so one sample per pixel is the image.
    pub fn is_deterministic(&self) -> bool {
        matches!(self, Integrator::Whitted(_))
    }

    /// True when the estimator runs its general loop even where the scene
    /// allows a specialised one (for measuring what specialisation saves).
    pub fn is_general(&self) -> bool {
        match self {
            Integrator::Path(p) => p.general,
            Integrator::Whitted(w) => w.general,
            _ => false,
        }
    }
}
