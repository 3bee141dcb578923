//! Lambertian reflection: f = albedo / π, sampled in proportion to cos θ.

use super::BsdfSample;
use crate::math::Rgb;
use crate::sampling::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use glam::{Vec2, Vec3A};
use std::f32::consts::FRAC_1_PI;

/// f(wo, wi) for directions on the same side.
#[inline]
pub fn eval(albedo: Rgb, wo: Vec3A, wi: Vec3A) -> Rgb {
    if wo.z * wi.z <= 0.0 {
        return Rgb::ZERO;
    }
    albedo * FRAC_1_PI
}

/// Density wrt. solid angle: |cos θ_i| / π on wo's side.
#[inline]
pub fn pdf(wo: Vec3A, wi: Vec3A) -> f32 {
    if wo.z * wi.z <= 0.0 {
        return 0.0;
    }
    cosine_hemisphere_pdf(wi.abs())
}

/// f(wo, wi) with the densities both ways, one side test for all three.
#[inline]
pub fn eval_with_pdfs(albedo: Rgb, wo: Vec3A, wi: Vec3A) -> (Rgb, f32, f32) {
    if wo.z * wi.z <= 0.0 {
        return (Rgb::ZERO, 0.0, 0.0);
    }
    (
        albedo * FRAC_1_PI,
        wi.z.abs() * FRAC_1_PI,
        wo.z.abs() * FRAC_1_PI,
    )
}

/// A cosine-distributed direction on wo's side; weight f cos / pdf = albedo.
#[inline]
pub fn sample(albedo: Rgb, wo: Vec3A, u: Vec2) -> Option<BsdfSample> {
    let mut wi = square_to_cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    if wi.z == 0.0 || wo.z == 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        weight: albedo,
        pdf: cosine_hemisphere_pdf(wi.abs()),
        specular: false,
    })
}
