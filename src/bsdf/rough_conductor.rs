//! Rough conductor (Mitsuba's `roughconductor`): the Torrance–Sparrow
//! microfacet model f = F(wo·m) D(m) G(wo, wi) / (4 cos θ_o cos θ_i), with
//! the conductor's exact Fresnel term, sampled by visible normals.
//! One-sided unless the material says otherwise (the dispatch flips).

use super::BsdfSample;
use super::fresnel::{fresnel_conductor, fresnel_conductor_normal};
use super::microfacet::Microfacet;
use crate::math::Rgb;
use glam::{Vec2, Vec3A};

/// A rough conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    pub microfacet: Microfacet,
    pub eta: Rgb,
    pub k: Rgb,
    /// Mitsuba's `specular_reflectance`: a factor on the Fresnel term.
    pub tint: Rgb,
}

impl RoughConductor {
    /// f(wo, wi); both on the upper side.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let m = (wo + wi).normalize();
        let d = self.microfacet.d(m);
        if d == 0.0 || !m.is_finite() {
            return Rgb::ZERO;
        }
        let g = self.microfacet.g(wo, wi, m);
        let f = fresnel_conductor(wo.dot(m), self.eta, self.k);
        self.tint * f * (d * g / (4.0 * wo.z * wi.z))
    }

    /// Density of reflecting a visible normal: D_wo(m) / (4 wo·m).
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let m = (wo + wi).normalize();
        let dot = wo.dot(m);
        if dot <= 0.0 || !m.is_finite() {
            return 0.0;
        }
        self.microfacet.pdf_visible(wo, m) / (4.0 * dot)
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.microfacet.sample_visible(wo, u);
        let dot = wo.dot(m);
        let wi = 2.0 * dot * m - wo;
        if wi.z <= 0.0 || dot <= 0.0 {
            return None;
        }
        let pdf = self.microfacet.pdf_visible(wo, m) / (4.0 * dot);
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        // f cos / pdf = F G1(wi) with visible normals: no D to overflow.
        let f = fresnel_conductor(dot, self.eta, self.k);
        Some(BsdfSample {
            wi,
            weight: self.tint * f * self.microfacet.g1(wi, m),
            pdf,
            specular: false,
        })
    }

    pub fn albedo_hint(&self) -> f32 {
        (self.tint * fresnel_conductor_normal(self.eta, self.k)).max_element()
    }
}
