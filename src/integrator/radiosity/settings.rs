//! Radiosity's defaults, the checks of its settings (the technique's
//! struct is its settings) and how its solution is shown.

use super::Radiosity;
use crate::integrator::Settings;
use crate::radiosity::{FormFactorMethod, RadiositySolver};

impl Default for Radiosity {
    fn default() -> Self {
        Radiosity {
            solver: RadiositySolver::GaussSeidel,
            patch_size: 0.1,
            form_factors: FormFactorMethod::Analytic,
            form_factor_samples: FormFactorMethod::Analytic.default_samples(),
            ambient: true,
            iterations: 0,
            display: RadiosityDisplay::Gather,
            epsilon: 1e-4,
            adaptive_rounds: 0,
            adaptive_tolerance: 0.5,
            adaptive_min_angle: 0.0,
            wireframe: false,
            discontinuity: false,
            lines_on_regular_mesh: false,
            min_piece_area: 0.0,
            max_penumbra: None,
        }
    }
}

impl Radiosity {
    /// The adaptive rounds and discontinuity meshing, for the summary.
    pub(super) fn meshing_summary(&self) -> String {
        let adaptive = if self.adaptive_rounds > 0 && self.solver.matrix().is_some() {
            let angle = match self.adaptive_min_angle {
                0.0 => String::new(),
                a => format!(" (angles under {a}° left whole)"),
            };
            format!(
                ", {} adaptive rounds at tolerance {}{angle}",
                self.adaptive_rounds, self.adaptive_tolerance
            )
        } else {
            String::new()
        };
        if !self.discontinuity {
            return adaptive;
        }
        let base = match (self.lines_on_regular_mesh, self.min_piece_area) {
            (false, _) => String::new(),
            (true, 0.0) => " on the regular mesh".to_string(),
            (true, a) => format!(" on the regular mesh (no piece under {a} of its element)"),
        };
        let lines = match self.max_penumbra.filter(|_| self.solver.matrix().is_some()) {
            Some(0.0) => " (contact lines only)".to_string(),
            Some(m) => format!(" (lines of penumbrae narrower than {m} patch sizes)"),
            None => String::new(),
        };
        format!("{adaptive}, discontinuity meshing{base}{lines}")
    }
}

impl Settings for Radiosity {
    fn validate(&self) -> Result<(), String> {
        if !(self.epsilon > 0.0 && self.epsilon.is_finite()) {
            return Err(format!("epsilon must be positive, got {}", self.epsilon));
        }
        if !(self.adaptive_tolerance > 0.0 && self.adaptive_tolerance.is_finite()) {
            return Err(format!(
                "adaptive tolerance must be positive, got {}",
                self.adaptive_tolerance
            ));
        }
        if !(0.0..60.0).contains(&self.adaptive_min_angle) {
            return Err(format!(
                "adaptive min angle must be in [0, 60) degrees, got {}",
                self.adaptive_min_angle
            ));
        }
        if !(0.0..0.5).contains(&self.min_piece_area) {
            return Err(format!(
                "min piece area must be in [0, 0.5) of an element, got {}",
                self.min_piece_area
            ));
        }
        if let Some(m) = self.max_penumbra
            && !(m >= 0.0 && m.is_finite())
        {
            return Err(format!(
                "max penumbra must be a number of patch sizes, 0 or more, got {m}"
            ));
        }
        if !(self.patch_size > 0.0 && self.patch_size <= 1.0) || self.form_factor_samples == 0 {
            return Err(format!(
                "patch size must be in (0, 1] (got {}) and form factor samples at least 1 (got {})",
                self.patch_size, self.form_factor_samples
            ));
        }
        Ok(())
    }
}

/// How the solution is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadiosityDisplay {
    /// Each element's constant radiance.
    Flat,
    /// Radiance interpolated from the elements' vertices.
    Smooth,
    /// Direct light sampled, indirect gathered from the solution.
    #[default]
    Gather,
}

impl RadiosityDisplay {
    pub const ALL: [RadiosityDisplay; 3] = [
        RadiosityDisplay::Flat,
        RadiosityDisplay::Smooth,
        RadiosityDisplay::Gather,
    ];

    pub fn name(self) -> &'static str {
        match self {
            RadiosityDisplay::Flat => "flat",
            RadiosityDisplay::Smooth => "smooth",
            RadiosityDisplay::Gather => "gather",
        }
    }
}
