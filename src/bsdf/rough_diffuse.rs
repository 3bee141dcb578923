//! Rough diffuse reflection: the Oren–Nayar model of a surface of
//! V-shaped Lambertian grooves, with its inter-reflection term, as
//! Mitsuba 0.6's `roughdiffuse` (the full model, not the fast fit). `alpha`
//! is the RMS slope; σ = α / √2 is Oren and Nayar's angle deviation, the
//! conversion Mitsuba uses. Sampled like Lambert (cosine-weighted).

use super::BsdfSample;
use crate::math::Rgb;
use crate::sampling::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use glam::{Vec2, Vec3A};
use std::f32::consts::{FRAC_1_PI, PI};

/// An Oren–Nayar surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDiffuse {
    pub albedo: Rgb,
    /// RMS slope of the grooves (Mitsuba's `alpha`).
    pub alpha: f32,
}

impl RoughDiffuse {
    /// f(wo, wi); both on the upper side.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let sigma = self.alpha * std::f32::consts::FRAC_1_SQRT_2;
        let sigma2 = sigma * sigma;
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        // cos(φ_i − φ_o) from the tangential components.
        let cos_phi_diff = if sin_i > 1e-4 && sin_o > 1e-4 {
            ((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o)).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let theta_i = wi.z.min(1.0).acos();
        let theta_o = wo.z.min(1.0).acos();
        let alpha = theta_i.max(theta_o);
        let beta = theta_i.min(theta_o);
        let (sin_alpha, sin_beta) = (alpha.sin(), beta.sin());
        let tan_beta = beta.tan();
        let tmp = sigma2 / (sigma2 + 0.09);
        let tmp2 = 4.0 / (PI * PI) * alpha * beta;
        let tmp3 = 2.0 * beta / PI;
        let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
        let c2 = 0.45
            * tmp
            * if cos_phi_diff >= 0.0 {
                sin_alpha
            } else {
                sin_alpha - tmp3 * tmp3 * tmp3
            };
        let c3 = 0.125 * tmp * tmp2 * tmp2;
        let tan_half = (sin_alpha + sin_beta)
            / ((1.0 - sin_alpha * sin_alpha).max(0.0).sqrt()
                + (1.0 - sin_beta * sin_beta).max(0.0).sqrt());
        let l1 = self.albedo
            * (c1 + cos_phi_diff * c2 * tan_beta + (1.0 - cos_phi_diff.abs()) * c3 * tan_half);
        // Light inter-reflected once within a groove.
        let l2 = self.albedo
            * self.albedo
            * (0.17 * sigma2 / (sigma2 + 0.13) * (1.0 - cos_phi_diff * tmp3 * tmp3));
        let f = (l1 + l2) * FRAC_1_PI;
        if f.is_finite() {
            f.max(Rgb::ZERO)
        } else {
            Rgb::ZERO
        }
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = square_to_cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        // f cos / (cos / π) = π f.
        Some(BsdfSample {
            wi,
            weight: self.eval(wo, wi) * PI,
            pdf: cosine_hemisphere_pdf(wi),
            specular: false,
        })
    }
}
