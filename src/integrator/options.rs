//! Estimator settings as plain data, the one form that the CLI and the viewer
//! both fill in; [`IntegratorOptions::build`] turns them into an
//! [`super::Integrator`], each technique reading the fields it has.

use super::radiosity::RadiosityDisplay;
use super::{GlassShadows, IntegratorKind, MisHeuristic};
use crate::radiosity::{FormFactorMethod, RadiositySolver};

/// Which sampling strategies the path tracer uses for direct light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// BSDF sampling only: light is found when a bounce hits an emitter.
    Bsdf,
    /// Light sampling only (next-event estimation); hits on emitters after a
    /// diffuse or glossy bounce are ignored.
    Light,
    /// Both, combined by multiple importance sampling.
    #[default]
    Mis,
}

/// Every estimator setting; each estimator reads the ones it has.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct IntegratorOptions {
    pub kind: IntegratorKind,
    /// Bounces (1 = direct lighting); Mitsuba's max_depth is one more.
    pub max_depth: u32,
    pub russian_roulette: bool,
    pub rr_depth: u32,
    pub strategy: Strategy,
    /// Heuristic for [`Strategy::Mis`] and MC ray tracing (never `None`).
    pub mis: MisHeuristic,
    /// MC ray tracing branching factors.
    pub shadow_rays: u32,
    pub glossy_rays: u32,
    /// Whitted's constant ambient radiance (grey).
    pub ambient: f32,
    pub glass_shadows: GlassShadows,
    /// Path tracing and Whitted: the general code even where a specialised
    /// one applies.
    pub general: bool,
    /// Path and MC ray tracing: emitters seen directly are integrated
    /// exactly over each pixel where that is possible (`crate::accel::seen_emitters`); off,
    /// camera rays sample them like everything else.
    pub exact_seen_emitters: bool,
    /// Ambient occlusion: occluders count within this fraction of the
    /// scene's bounding-box diagonal (0: no limit).
    pub ao_distance: f32,
    /// Radiosity: the solver, the longest element edge (fraction of the
    /// scene's diagonal), how form factors are estimated and with how many
    /// samples per pair, the ambient term (progressive), and the steps to
    /// run (0: until converged).
    pub radiosity_solver: RadiositySolver,
    pub patch_size: f32,
    pub form_factor_method: FormFactorMethod,
    pub form_factor_samples: u32,
    pub radiosity_ambient: bool,
    pub radiosity_iterations: u32,
    pub radiosity_display: RadiosityDisplay,
    pub radiosity_epsilon: f32,
    /// Radiosity (Jacobi, Gauss-Seidel, progressive): rounds of adaptive
    /// subdivision after the first solve, splitting elements whose reflected
    /// radiance differs from a neighbour's by more than the tolerance times
    /// the mean; and the wireframe overlay of the elements.
    pub adaptive_rounds: u32,
    pub adaptive_tolerance: f32,
    pub radiosity_wireframe: bool,
    /// Radiosity: split receivers along the shadows' discontinuity lines.
    pub radiosity_discontinuity: bool,
    /// Photon mapping: photons per iteration (0: one per pixel), the first
    /// iteration's radius (fraction of the scene's diagonal) and alpha.
    pub photons: u32,
    pub photon_radius: f32,
    pub photon_alpha: f32,
    /// Jensen's photon map: photons per density estimate, and the largest
    /// gather radius (fraction of the scene's diagonal).
    pub photon_k: u32,
    pub gather_radius: f32,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            kind: IntegratorKind::Path,
            max_depth: 8,
            russian_roulette: true,
            rr_depth: 5,
            strategy: Strategy::Mis,
            mis: MisHeuristic::Power,
            shadow_rays: 1,
            glossy_rays: 1,
            ambient: 0.0,
            glass_shadows: GlassShadows::Opaque,
            general: false,
            exact_seen_emitters: true,
            ao_distance: 0.1,
            radiosity_solver: RadiositySolver::GaussSeidel,
            patch_size: 0.1,
            form_factor_method: FormFactorMethod::Analytic,
            form_factor_samples: FormFactorMethod::Analytic.default_samples(),
            radiosity_ambient: true,
            radiosity_iterations: 0,
            radiosity_display: RadiosityDisplay::Gather,
            radiosity_epsilon: 1e-4,
            adaptive_rounds: 0,
            adaptive_tolerance: 0.5,
            radiosity_wireframe: false,
            radiosity_discontinuity: false,
            photons: 0,
            photon_radius: 0.002,
            photon_alpha: 2.0 / 3.0,
            photon_k: 50,
            gather_radius: 0.05,
        }
    }
}

impl IntegratorOptions {
    /// Takes radiosity's settings from `other`, leaving the rest.
    pub fn set_radiosity_from(&mut self, other: &IntegratorOptions) {
        self.radiosity_solver = other.radiosity_solver;
        self.patch_size = other.patch_size;
        self.radiosity_epsilon = other.radiosity_epsilon;
        self.form_factor_method = other.form_factor_method;
        self.form_factor_samples = other.form_factor_samples;
        self.radiosity_ambient = other.radiosity_ambient;
        self.radiosity_iterations = other.radiosity_iterations;
        self.radiosity_display = other.radiosity_display;
        self.adaptive_rounds = other.adaptive_rounds;
        self.adaptive_tolerance = other.adaptive_tolerance;
        self.radiosity_wireframe = other.radiosity_wireframe;
        self.radiosity_discontinuity = other.radiosity_discontinuity;
    }

    /// The MIS heuristic of estimators that always combine strategies
    /// (`None` is not one of them).
    pub fn combining_heuristic(&self) -> MisHeuristic {
        if self.mis == MisHeuristic::None {
            MisHeuristic::Power
        } else {
            self.mis
        }
    }
}
