//! Thin dielectric (Mitsuba's `thindielectric`): a slab too thin to offset a
//! ray. Light is reflected or passes straight through; the slab's internal
//! reflections are summed in closed form: with R the reflectance of one
//! interface, R' = R + T²R/(1 − R²) = 2R/(1 + R) and T' = 1 − R'. Both
//! events are Dirac; the slab is symmetric, so either side behaves alike.

use super::BsdfSample;
use super::fresnel::fresnel_dielectric;
use crate::math::Rgb;
use glam::Vec3A;

/// A thin dielectric slab.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// Interior / exterior IOR of the slab's material.
    pub eta: f32,
    pub reflectance: Rgb,
    pub transmittance: Rgb,
}

impl ThinDielectric {
    /// Reflectance of the slab, inter-reflections included, at |cos θ|.
    #[inline]
    pub fn slab_reflectance(&self, cos: f32) -> f32 {
        let r = fresnel_dielectric(cos.abs(), self.eta).reflectance;
        if r >= 1.0 { 1.0 } else { 2.0 * r / (1.0 + r) }
    }

    /// Chooses reflection with probability R', else straight transmission.
    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = self.slab_reflectance(wo.z);
        if u_lobe < r {
            Some(BsdfSample {
                wi: Vec3A::new(-wo.x, -wo.y, wo.z),
                weight: self.reflectance,
                pdf: r,
                specular: true,
            })
        } else {
            Some(BsdfSample {
                wi: -wo,
                weight: self.transmittance,
                pdf: 1.0 - r,
                specular: true,
            })
        }
    }

    pub fn albedo_hint(&self) -> f32 {
        self.reflectance
            .max_element()
            .max(self.transmittance.max_element())
    }
}
