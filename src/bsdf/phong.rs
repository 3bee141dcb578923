//! Diffuse plus a normalised modified Phong lobe (Lafortune and Willems 1994):
//! f = kd / π + ks (n + 2) / (2π) cos^n α, α the angle between wi and the
//! mirror direction of wo. Energy-conserving when kd + ks ≤ 1 (the
//! constructor scales them down otherwise). Two-sided.

use super::{Bsdf, BsdfSample};
use crate::math::{Frame, Rgb, luminance, reflect};
use crate::sampling::warp::{
    cosine_hemisphere_pdf, phong_lobe_pdf, square_to_cosine_hemisphere, square_to_phong_lobe,
};
use glam::{Vec2, Vec3A};
use std::f32::consts::{FRAC_1_PI, PI};

/// The Phong lobe's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    pub diffuse: Rgb,
    pub specular: Rgb,
    pub exponent: f32,
    /// Probability of sampling the diffuse lobe (its share of the albedo).
    pub diffuse_probability: f32,
}

impl Phong {
    /// Scales kd + ks down to at most one per channel so that the lobe
    /// conserves energy, and picks lobes in proportion to their albedo.
    pub fn new(diffuse: Rgb, specular: Rgb, exponent: f32) -> Phong {
        let sum = (diffuse + specular).max_element();
        let scale = if sum > 1.0 { 1.0 / sum } else { 1.0 };
        let (diffuse, specular) = (diffuse * scale, specular * scale);
        let (ld, ls) = (luminance(diffuse), luminance(specular));
        let diffuse_probability = if ld + ls > 0.0 { ld / (ld + ls) } else { 1.0 };
        Phong {
            diffuse,
            specular,
            exponent: exponent.max(0.0),
            diffuse_probability,
        }
    }

    /// f, and the densities of sampling wi from wo and wo from wi; wo and wi
    /// on the upper side. The lobe's cos^n is symmetric and computed once.
    #[inline]
    pub fn eval_with_pdfs(&self, wo: Vec3A, wi: Vec3A) -> (Rgb, f32, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0, 0.0);
        }
        let cos_alpha = reflect(wo, Vec3A::Z).dot(wi).max(0.0);
        let lobe = if cos_alpha > 0.0 {
            cos_alpha.powf(self.exponent)
        } else {
            0.0
        };
        let f =
            self.diffuse * FRAC_1_PI + self.specular * ((self.exponent + 2.0) / (2.0 * PI) * lobe);
        let phong = (1.0 - self.diffuse_probability) * (self.exponent + 1.0) / (2.0 * PI) * lobe;
        let pdf = |w: Vec3A| self.diffuse_probability * cosine_hemisphere_pdf(w) + phong;
        (f, pdf(wi), pdf(wo))
    }

    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let cos_alpha = reflect(wo, Vec3A::Z).dot(wi).max(0.0);
        self.diffuse * FRAC_1_PI
            + self.specular * ((self.exponent + 2.0) / (2.0 * PI) * cos_alpha.powf(self.exponent))
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let cos_alpha = reflect(wo, Vec3A::Z).dot(wi);
        self.diffuse_probability * cosine_hemisphere_pdf(wi)
            + (1.0 - self.diffuse_probability) * phong_lobe_pdf(cos_alpha, self.exponent)
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.diffuse_probability {
            square_to_cosine_hemisphere(u)
        } else {
            Frame::from_normal(reflect(wo, Vec3A::Z))
                .to_world(square_to_phong_lobe(u, self.exponent))
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval(wo, wi) * (wi.z / pdf),
            pdf,
            specular: false,
        })
    }
}

impl From<Phong> for Bsdf {
    fn from(p: Phong) -> Bsdf {
        Bsdf::Glossy {
            diffuse: p.diffuse,
            specular: p.specular,
            exponent: p.exponent,
            diffuse_probability: p.diffuse_probability,
        }
    }
}
