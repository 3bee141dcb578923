//! Perfect specular reflection with a constant reflectance. Two-sided.

use super::BsdfSample;
use crate::math::Rgb;
use glam::Vec3A;

/// The mirror direction, a Dirac event weighted by the reflectance.
#[inline]
pub fn sample(reflectance: Rgb, wo: Vec3A) -> Option<BsdfSample> {
    Some(BsdfSample {
        wi: Vec3A::new(-wo.x, -wo.y, wo.z),
        weight: reflectance,
        pdf: 1.0,
        specular: true,
    })
}
