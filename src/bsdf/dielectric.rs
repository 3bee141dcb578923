//! Smooth dielectric boundary: Snell refraction, exact unpolarised Fresnel
//! reflectance, total internal reflection. `eta` = interior / exterior IOR,
//! the exterior being the side the geometric normal points to.

use super::BsdfSample;
use super::fresnel::fresnel_dielectric;
use crate::math::Rgb;
use glam::Vec3A;

/// Reflects with probability F, else refracts; both are Dirac events.
#[inline]
pub fn sample(eta: f32, tint: Rgb, wo: Vec3A, u_lobe: f32) -> Option<BsdfSample> {
    let f = fresnel_dielectric(wo.z, eta);
    if u_lobe < f.reflectance {
        Some(BsdfSample {
            wi: Vec3A::new(-wo.x, -wo.y, wo.z),
            weight: Rgb::ONE,
            pdf: f.reflectance,
            specular: true,
        })
    } else {
        // Snell: tangential components scale by 1 / eta_rel, the normal
        // component is cos_t on the other side.
        let wi = Vec3A::new(-wo.x * f.eta_ti, -wo.y * f.eta_ti, f.cos_t);
        // Radiance is compressed into a smaller solid angle when entering a
        // denser medium: scale by (eta_i / eta_t)^2.
        Some(BsdfSample {
            wi,
            weight: tint * (f.eta_ti * f.eta_ti),
            pdf: 1.0 - f.reflectance,
            specular: true,
        })
    }
}

/// The factor (eta_i / eta_t)² that radiance picks up crossing from `wi`'s
/// side to `wo`'s (1 on the same side).
#[inline]
pub fn refraction_scale(eta: f32, wo: Vec3A, wi: Vec3A) -> f32 {
    if wo.z * wi.z >= 0.0 {
        1.0
    } else if wo.z > 0.0 {
        1.0 / (eta * eta)
    } else {
        eta * eta
    }
}
