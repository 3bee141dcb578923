//! Microfacet normal distributions (Beckmann and GGX, anisotropic), Smith's
//! masking, and sampling of the normals visible from a direction: GGX by
//! Dupuy and Benyoub's spherical caps (2023), Beckmann by Jakob's slope
//! inversion (2014). Directions are in the local frame (normal = +z) and on
//! its upper side; callers flip them there first.

use crate::math::{erf_and_gaussian, erfinv};
use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

/// Which microfacet normal distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Distribution {
    Beckmann,
    Ggx,
}

/// A microfacet distribution with roughness α_u along the tangent (x) and
/// α_v along the bitangent (y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub distribution: Distribution,
    pub alpha_u: f32,
    pub alpha_v: f32,
}

/// Roughness below which a lobe is treated as its delta limit would be
/// numerically: Mitsuba clamps to the same value.
pub const MIN_ALPHA: f32 = 1e-4;

impl Microfacet {
    /// A distribution, α clamped to [1e-4, ∞) (NaN read as the minimum):
    /// at smaller α, D overflows f32 at the peak.
    pub fn new(distribution: Distribution, alpha_u: f32, alpha_v: f32) -> Microfacet {
        let clamp = |a: f32| {
            if a.is_finite() {
                a.max(MIN_ALPHA)
            } else {
                MIN_ALPHA
            }
        };
        Microfacet {
            distribution,
            alpha_u: clamp(alpha_u),
            alpha_v: clamp(alpha_v),
        }
    }

    /// An isotropic distribution.
    pub fn isotropic(distribution: Distribution, alpha: f32) -> Microfacet {
        Microfacet::new(distribution, alpha, alpha)
    }

    /// Normal density D(m), normalised so that ∫ D(m) cos θ_m dm = 1.
    #[inline]
    pub fn d(&self, m: Vec3A) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let cos2 = m.z * m.z;
        // tan² θ (cos² φ / α_u² + sin² φ / α_v²), from the slopes.
        let e = (m.x * m.x / (self.alpha_u * self.alpha_u)
            + m.y * m.y / (self.alpha_v * self.alpha_v))
            / cos2;
        let value = match self.distribution {
            Distribution::Beckmann => (-e).exp() / (PI * self.alpha_u * self.alpha_v * cos2 * cos2),
            Distribution::Ggx => {
                1.0 / (PI * self.alpha_u * self.alpha_v * cos2 * cos2 * (1.0 + e) * (1.0 + e))
            }
        };
        // Near the delta limit the peak may overflow; no infinity leaves here.
        if value.is_finite() { value } else { 0.0 }
    }

    /// Smith's Λ(w): G1 = 1 / (1 + Λ).
    #[inline]
    fn lambda(&self, w: Vec3A) -> f32 {
        let xy2 = self.alpha_u * self.alpha_u * w.x * w.x + self.alpha_v * self.alpha_v * w.y * w.y;
        if xy2 <= 0.0 {
            return 0.0;
        }
        // α(w)² tan² θ.
        let alpha2_tan2 = xy2 / (w.z * w.z);
        match self.distribution {
            Distribution::Ggx => 0.5 * ((1.0 + alpha2_tan2).sqrt() - 1.0),
            Distribution::Beckmann => {
                // Exact: (erf(a) - 1) / 2 + e^{-a²} / (2 a √π), a = 1 / (α tan θ).
                let a = 1.0 / alpha2_tan2.sqrt();
                if a > 6.0 {
                    return 0.0;
                }
                let (erf_a, gaussian) = erf_and_gaussian(a);
                (0.5 * (erf_a - 1.0) + gaussian / (2.0 * a * PI.sqrt())).max(0.0)
            }
        }
    }

    /// Smith's masking of direction `w` by microfacets of normal `m`: zero
    /// where `w` sees the back of `m` or lies below the surface.
    #[inline]
    pub fn g1(&self, w: Vec3A, m: Vec3A) -> f32 {
        if w.dot(m) * w.z <= 0.0 || w.z == 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(w))
    }

    /// Shadowing and masking, separable (uncorrelated) as Mitsuba's, so
    /// that images match its renders.
    #[inline]
    pub fn g(&self, wo: Vec3A, wi: Vec3A, m: Vec3A) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Density of [`Microfacet::sample_visible`]: D_w(m) = G1(w) max(0, w·m) D(m) / w_z.
    #[inline]
    pub fn pdf_visible(&self, w: Vec3A, m: Vec3A) -> f32 {
        if w.z <= 0.0 {
            return 0.0;
        }
        let dot = w.dot(m);
        if dot <= 0.0 {
            return 0.0;
        }
        self.g1(w, m) * dot * self.d(m) / w.z
    }

    /// Samples a normal visible from `w` (w.z > 0) in proportion to
    /// [`Microfacet::pdf_visible`].
    #[inline]
    pub fn sample_visible(&self, w: Vec3A, u: Vec2) -> Vec3A {
        // Stretch to the configuration of unit roughness.
        let ws = Vec3A::new(self.alpha_u * w.x, self.alpha_v * w.y, w.z).normalize();
        match self.distribution {
            Distribution::Ggx => {
                // Visible normals of the unit-roughness GGX are a spherical
                // cap of directions offset by ws (Dupuy and Benyoub 2023).
                let phi = 2.0 * PI * u.x;
                let z = (1.0 - u.y) * (1.0 + ws.z) - ws.z;
                let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
                let (sin_phi, cos_phi) = phi.sin_cos();
                let h = Vec3A::new(sin_theta * cos_phi, sin_theta * sin_phi, z) + ws;
                Vec3A::new(self.alpha_u * h.x, self.alpha_v * h.y, h.z.max(0.0)).normalize()
            }
            Distribution::Beckmann => {
                let sin_theta = (1.0 - ws.z * ws.z).max(0.0).sqrt();
                let (cos_phi, sin_phi) = if sin_theta > 1e-7 {
                    (ws.x / sin_theta, ws.y / sin_theta)
                } else {
                    (1.0, 0.0)
                };
                let s = beckmann_visible_slope(ws.z, u);
                // Rotate to ws's azimuth, then unstretch.
                let slope = Vec2::new(
                    (cos_phi * s.x - sin_phi * s.y) * self.alpha_u,
                    (sin_phi * s.x + cos_phi * s.y) * self.alpha_v,
                );
                let m = Vec3A::new(-slope.x, -slope.y, 1.0).normalize();
                if m.is_finite() { m } else { Vec3A::Z }
            }
        }
    }
}

/// Slopes of the unit Beckmann distribution visible from a direction of
/// cosine `cos_theta` in the xz-plane: the x slope by inverting its CDF with
/// Newton steps kept inside a bisection bracket (in the erf domain, as
/// Mitsuba does, which has no discontinuities), the y slope a Gaussian.
fn beckmann_visible_slope(cos_theta: f32, u: Vec2) -> Vec2 {
    const INV_SQRT_PI: f32 = 0.564_189_6;
    let cos_theta = cos_theta.clamp(1e-6, 1.0);
    let tan_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt() / cos_theta;
    let cot_theta = 1.0 / tan_theta;
    let ux = u.x.clamp(1e-6, 1.0 - 1e-6);
    // The CDF of b = erf(slope) is (1 + b + tan e^{-slope²} / √π) / norm on [-1, erf(cot)].
    let (erf_cot, gaussian_cot) = erf_and_gaussian(cot_theta);
    let (mut lo, mut hi) = (-1.0f32, erf_cot);
    let norm = 1.0 / (1.0 + hi + INV_SQRT_PI * tan_theta * gaussian_cot);
    // Initial guess: a fit of the inverse (Mitsuba's).
    let theta = cos_theta.acos();
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = hi - (1.0 + hi) * (1.0 - ux).powf(fit);
    // The slope of the converged b, so that it is not inverted twice.
    let mut converged = None;
    for _ in 0..10 {
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        let slope = erfinv(b);
        let value = norm * (1.0 + b + INV_SQRT_PI * tan_theta * (-slope * slope).exp()) - ux;
        let derivative = norm * (1.0 - slope * tan_theta);
        if value.abs() < 1e-6 {
            converged = Some(slope);
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        b -= value / derivative;
    }
    let clamped = b.clamp(-1.0 + 1e-7, 1.0 - 1e-7);
    let slope_x = match converged {
        Some(slope) if clamped == b => slope,
        _ => erfinv(clamped),
    };
    let uy = u.y.clamp(1e-6, 1.0 - 1e-6);
    Vec2::new(slope_x, erfinv(2.0 * uy - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::erf;

    /// ∫ f over the hemisphere by a midpoint rule in (cos θ, φ).
    fn hemisphere_integral(f: impl Fn(Vec3A) -> f64, n: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..n {
            let z = (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..2 * n {
                let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * std::f64::consts::PI;
                sum += f(Vec3A::new(
                    (r * phi.cos()) as f32,
                    (r * phi.sin()) as f32,
                    z as f32,
                ));
            }
        }
        sum * 2.0 * std::f64::consts::PI / (2 * n * n) as f64
    }

    #[test]
    fn distributions_are_normalised_and_visible_normals_integrate_to_one() {
        for distribution in [Distribution::Beckmann, Distribution::Ggx] {
            for (au, av) in [(0.3, 0.3), (0.6, 0.2), (1.0, 1.0)] {
                let mf = Microfacet::new(distribution, au, av);
                let projected = hemisphere_integral(|m| (mf.d(m) * m.z) as f64, 600);
                assert!(
                    (projected - 1.0).abs() < 2e-3,
                    "{distribution:?} {au} {av}: {projected}"
                );
                let w = Vec3A::new(0.6, 0.3, 0.5).normalize();
                let visible = hemisphere_integral(|m| mf.pdf_visible(w, m) as f64, 600);
                assert!(
                    (visible - 1.0).abs() < 3e-3,
                    "{distribution:?} {au} {av}: {visible}"
                );
            }
        }
    }

    #[test]
    fn erf_and_its_inverse_agree() {
        for i in -99..100 {
            let x = i as f32 / 100.0;
            assert!((erf(erfinv(x)) - x).abs() < 2e-6, "{x}");
        }
        assert!((erf(0.5) - 0.520_499_9).abs() < 2e-7);
    }
}
