//! Smooth conductor: a mirror whose reflectance is the exact Fresnel
//! reflectance of a complex IOR η + ik, times a tint (Mitsuba's `conductor`).
//! One-sided unless the material says otherwise (the dispatch flips).

use super::BsdfSample;
use super::fresnel::{fresnel_conductor, fresnel_conductor_normal};
use crate::math::Rgb;
use glam::Vec3A;

/// A smooth conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the IOR relative to the exterior, per channel.
    pub eta: Rgb,
    /// Imaginary part (absorption), per channel.
    pub k: Rgb,
    /// Mitsuba's `specular_reflectance`: a factor on the Fresnel term.
    pub tint: Rgb,
}

impl Conductor {
    /// The mirror direction, weighted by F(cos θ) · tint; wo on the upper side.
    #[inline]
    pub fn sample(&self, wo: Vec3A) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi: Vec3A::new(-wo.x, -wo.y, wo.z),
            weight: self.tint * fresnel_conductor(wo.z, self.eta, self.k),
            pdf: 1.0,
            specular: true,
        })
    }

    /// Reflectance at normal incidence, the hint for roulette and lobe choice.
    pub fn albedo_hint(&self) -> f32 {
        (self.tint * fresnel_conductor_normal(self.eta, self.k)).max_element()
    }
}
