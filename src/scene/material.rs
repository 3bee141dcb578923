//! Materials: a BSDF (see [`crate::bsdf`]) plus optional emission.

pub use crate::bsdf::{Bsdf, BsdfSample, Fresnel, fresnel_dielectric};
use crate::math::Rgb;
use glam::Vec3A;

/// A material: how a surface scatters and what it emits.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub bsdf: Bsdf,
    /// Emitted radiance (W sr^-1 m^-2 per channel); zero for non-emitters.
    pub emission: Rgb,
    /// Emit on both sides; by default only along the geometric normal.
    pub two_sided_emission: bool,
}

impl Material {
    /// True when the surface is a light source.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Radiance emitted from a surface with geometric normal `n` towards `w`.
    #[inline]
    pub fn emitted(&self, n: Vec3A, w: Vec3A) -> Rgb {
        if self.two_sided_emission || n.dot(w) > 0.0 {
            self.emission
        } else {
            Rgb::ZERO
        }
    }
}
