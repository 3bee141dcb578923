//! Smooth plastic (Mitsuba's `plastic`): a smooth dielectric coating over a
//! Lambertian base. Light is either reflected specularly by the coating
//! (Fresnel F) or enters it, scatters diffusely, and leaves with
//! (1 − F_i)(1 − F_o)/η²; the light the coating reflects back inside is
//! summed in closed form through the diffuse Fresnel reflectance F_dr:
//! ρ / (1 − F_dr), or ρ / (1 − ρ F_dr) with `nonlinear`, which also darkens
//! and saturates the base as a wet surface looks. The specular event is
//! chosen with probability ∝ F · s, the diffuse one ∝ (1 − F)(1 − s), s
//! the specular sampling weight.

use super::BsdfSample;
use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
use crate::math::Rgb;
use crate::sampling::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use glam::{Vec2, Vec3A};
use std::f32::consts::FRAC_1_PI;

/// A smooth plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// Interior / exterior IOR of the coating.
    pub eta: f32,
    pub diffuse: Rgb,
    pub specular: Rgb,
    pub nonlinear: bool,
    /// Share of the specular lobe in lobe choice: mean specular over mean
    /// specular plus mean diffuse reflectance (Mitsuba's).
    pub specular_sampling_weight: f32,
    /// Diffuse reflectance of the coating seen from inside.
    pub fdr_internal: f32,
}

impl Plastic {
    pub fn new(eta: f32, diffuse: Rgb, specular: Rgb, nonlinear: bool) -> Plastic {
        let (d, s) = (mean(diffuse), mean(specular));
        Plastic {
            eta,
            diffuse,
            specular,
            nonlinear,
            specular_sampling_weight: if d + s > 0.0 { s / (d + s) } else { 0.5 },
            fdr_internal: fresnel_diffuse_reflectance(1.0 / eta),
        }
    }

    /// The base's albedo after the coating's internal reflections.
    #[inline]
    fn base(&self) -> Rgb {
        if self.nonlinear {
            self.diffuse / (Rgb::ONE - self.diffuse * self.fdr_internal)
        } else {
            self.diffuse / (1.0 - self.fdr_internal)
        }
    }

    /// Probability of choosing the specular event at wo of Fresnel `f`.
    #[inline]
    fn specular_probability(&self, f: f32) -> f32 {
        let ps = f * self.specular_sampling_weight;
        let pd = (1.0 - f) * (1.0 - self.specular_sampling_weight);
        if ps + pd > 0.0 { ps / (ps + pd) } else { 0.0 }
    }

    /// The diffuse part of f (the coating's reflection is a delta); both
    /// directions on the upper side.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let fo = fresnel_dielectric(wo.z, self.eta).reflectance;
        let fi = fresnel_dielectric(wi.z, self.eta).reflectance;
        self.base() * (FRAC_1_PI / (self.eta * self.eta) * (1.0 - fo) * (1.0 - fi))
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let f = fresnel_dielectric(wo.z, self.eta).reflectance;
        (1.0 - self.specular_probability(f)) * cosine_hemisphere_pdf(wi)
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let f = fresnel_dielectric(wo.z, self.eta).reflectance;
        let ps = self.specular_probability(f);
        if u_lobe < ps {
            return Some(BsdfSample {
                wi: Vec3A::new(-wo.x, -wo.y, wo.z),
                weight: self.specular * (f / ps),
                pdf: ps,
                specular: true,
            });
        }
        let wi = square_to_cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi);
        Some(BsdfSample {
            wi,
            weight: self.eval(wo, wi) * (wi.z / pdf),
            pdf,
            specular: false,
        })
    }

    /// The probability that [`Plastic::sample`] picks the coating's
    /// mirror reflection at `wo`.
    pub fn delta_probability(&self, wo: Vec3A) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.specular_probability(fresnel_dielectric(wo.z, self.eta).reflectance)
    }

    pub fn albedo_hint(&self) -> f32 {
        self.diffuse.max_element().max(self.specular.max_element())
    }
}

/// Mean of the three channels (Mitsuba's `mean` of a spectrum).
pub(super) fn mean(c: Rgb) -> f32 {
    (c.x + c.y + c.z) / 3.0
}
