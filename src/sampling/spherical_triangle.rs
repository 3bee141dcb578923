//! Uniform sampling of the solid angle a triangle subtends (Arvo 1995,
//! "Stratified sampling of spherical triangles", in the form of pbrt-v4's
//! `SampleSphericalTriangle`): the density is 1 / (solid angle), constant,
//! where area sampling's density d^2 / (cos A) varies wildly for large or
//! close lights.

use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

/// Below this solid angle the spherical construction loses precision in f32
/// and above it the triangle nearly surrounds the point; callers fall back
/// to area sampling outside the range (pbrt-v4 uses the same bounds).
pub const MIN_SOLID_ANGLE: f32 = 3e-4;
pub const MAX_SOLID_ANGLE: f32 = 6.22;

/// Solid angle of the triangle seen from `p` (Van Oosterom & Strackee 1983).
#[inline]
pub fn solid_angle(p: Vec3A, v: [Vec3A; 3]) -> f32 {
    let [a, b, c] = v.map(|x| (x - p).normalize_or_zero());
    let numerator = a.dot(b.cross(c)).abs();
    let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    (2.0 * numerator.atan2(denominator)).abs()
}

/// Whether [`sample`] is accurate for this solid angle.
#[inline]
pub fn usable(solid_angle: f32) -> bool {
    (MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE).contains(&solid_angle)
}

#[inline]
fn angle_between(a: Vec3A, b: Vec3A) -> f32 {
    // Numerically stable for nearly parallel and antiparallel vectors.
    if a.dot(b) < 0.0 {
        PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

#[inline]
fn gram_schmidt(v: Vec3A, w: Vec3A) -> Vec3A {
    v - v.dot(w) * w
}

/// A unit direction from `p` towards the triangle, uniform in solid angle,
/// and its density 1 / solid angle. `None` for degenerate configurations.
pub fn sample(p: Vec3A, v: [Vec3A; 3], u: Vec2) -> Option<(Vec3A, f32)> {
    let [a, b, c] = v.map(|x| (x - p).normalize_or_zero());
    let n_ab = a.cross(b);
    let n_bc = b.cross(c);
    let n_ca = c.cross(a);
    if n_ab.length_squared() == 0.0 || n_bc.length_squared() == 0.0 || n_ca.length_squared() == 0.0
    {
        return None;
    }
    let (n_ab, n_bc, n_ca) = (n_ab.normalize(), n_bc.normalize(), n_ca.normalize());
    // Interior angles of the spherical triangle; their excess is its area.
    let alpha = angle_between(n_ab, -n_ca);
    let beta = angle_between(n_bc, -n_ab);
    let gamma = angle_between(n_ca, -n_bc);
    let area_pi = alpha + beta + gamma;
    let area = area_pi - PI;
    if !(area > 0.0) {
        return None;
    }
    // Choose the sub-triangle area A' = u0 A, which fixes the point c' on
    // the arc from a to c; then a point on the arc from b to c' with u1.
    let ap_pi = PI + u.x * area;
    let (sin_alpha, cos_alpha) = alpha.sin_cos();
    let (sin_ap, cos_ap) = ap_pi.sin_cos();
    let sin_phi = sin_ap * cos_alpha - cos_ap * sin_alpha;
    let cos_phi = cos_ap * cos_alpha + sin_ap * sin_alpha;
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let denominator = (k2 * sin_phi + k1 * cos_phi) * sin_alpha;
    let cos_bp = if denominator != 0.0 {
        ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / denominator).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let sin_bp = (1.0 - cos_bp * cos_bp).max(0.0).sqrt();
    let cp = cos_bp * a + sin_bp * gram_schmidt(c, a).normalize_or_zero();
    let cos_theta = 1.0 - u.y * (1.0 - cp.dot(b));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let w = cos_theta * b + sin_theta * gram_schmidt(cp, b).normalize_or_zero();
    let w = w.normalize_or_zero();
    (w != Vec3A::ZERO).then_some((w, 1.0 / area))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octant_triangle_has_an_eighth_of_the_sphere() {
        let v = [Vec3A::X, Vec3A::Y, Vec3A::Z];
        let expected = 4.0 * PI / 8.0;
        assert!((solid_angle(Vec3A::ZERO, v) - expected).abs() < 1e-5);
        let (w, pdf) = sample(Vec3A::ZERO, v, Vec2::new(0.3, 0.6)).unwrap();
        assert!((pdf - 1.0 / expected).abs() < 1e-4);
        assert!(w.x > 0.0 && w.y > 0.0 && w.z > 0.0);
        assert!((w.length() - 1.0).abs() < 1e-5);
    }
}
