//! Estimators of the rendering equation, one file each, behind one interface:
//! given a camera ray and a sampler, return a radiance sample. The enum is
//! dispatched once per camera sample, never inside the bounce loop.

pub mod mis;
pub mod path;

pub use mis::MisHeuristic;
pub use path::PathTracer;

use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::scene::Scene;

/// Rays cast, by kind; kept per thread and summed after each tile.
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

/// Names of the estimators, as the command line spells them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IntegratorKind {
    #[default]
    Path,
}

/// A configured estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    Path(PathTracer),
}

impl Integrator {
    /// One radiance sample along the camera ray `ray`. Counts the rays it
    /// casts after the camera ray into `counts`.
    #[inline]
    pub fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        match self {
            Integrator::Path(p) => p.radiance(scene, ray, sampler, counts),
        }
    }

    /// Short description for summaries and file names.
    pub fn describe(&self) -> String {
        match self {
            Integrator::Path(p) => p.describe(),
        }
    }
}
