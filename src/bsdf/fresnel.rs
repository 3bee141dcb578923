//! Fresnel equations: dielectric interfaces, conductors with a complex IOR,
//! and the diffuse (hemispherically averaged) reflectance of an interface.

use crate::math::Rgb;

/// Result of the Fresnel equations at a smooth dielectric boundary.
#[derive(Clone, Copy, Debug)]
pub struct Fresnel {
    /// Unpolarised reflectance F in [0, 1]; 1 under total internal reflection.
    pub reflectance: f32,
    /// Cosine of the transmitted direction, signed: on the opposite side of wo.
    pub cos_t: f32,
    /// eta_i / eta_t for the side wo is on (scales tangential components).
    pub eta_ti: f32,
}

/// Exact Fresnel reflectance for a ray arriving with cosine `cos_i` (positive
/// on the exterior side) at a boundary with relative IOR `eta` = interior / exterior.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> Fresnel {
    let (eta_rel, cos_i_abs) = if cos_i >= 0.0 {
        (eta, cos_i)
    } else {
        (1.0 / eta, -cos_i)
    };
    let eta_ti = 1.0 / eta_rel;
    // Snell: sin_t = sin_i / eta_rel.
    let sin2_t = (1.0 - cos_i_abs * cos_i_abs).max(0.0) * eta_ti * eta_ti;
    if sin2_t >= 1.0 {
        return Fresnel {
            reflectance: 1.0,
            cos_t: 0.0,
            eta_ti,
        };
    }
    let cos_t_abs = (1.0 - sin2_t).sqrt();
    let rs = (cos_i_abs - eta_rel * cos_t_abs) / (cos_i_abs + eta_rel * cos_t_abs);
    let rp = (eta_rel * cos_i_abs - cos_t_abs) / (eta_rel * cos_i_abs + cos_t_abs);
    let reflectance = 0.5 * (rs * rs + rp * rp);
    Fresnel {
        reflectance,
        cos_t: if cos_i >= 0.0 { -cos_t_abs } else { cos_t_abs },
        eta_ti,
    }
}

/// Exact unpolarised reflectance of a conductor with complex IOR eta + i k
/// (relative to the exterior), per channel, at incident cosine `cos_i` ≥ 0
/// (the closed form of Mitsuba's `fresnel_conductor`, after Born and Wolf).
#[inline]
pub fn fresnel_conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c2 = (cos_i * cos_i).clamp(0.0, 1.0);
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let temp1 = eta * eta - k * k - Rgb::splat(s2);
    // a² + b² = |(eta + ik)² - sin²|.
    let a2pb2 = (temp1 * temp1 + 4.0 * k * k * eta * eta).max(Rgb::ZERO);
    let a2pb2 = Rgb::new(a2pb2.x.sqrt(), a2pb2.y.sqrt(), a2pb2.z.sqrt());
    let a = (0.5 * (a2pb2 + temp1)).max(Rgb::ZERO);
    let a = Rgb::new(a.x.sqrt(), a.y.sqrt(), a.z.sqrt());
    let term1 = a2pb2 + Rgb::splat(c2);
    let term2 = 2.0 * cos_i.max(0.0) * a;
    let rs = (term1 - term2) / (term1 + term2).max(Rgb::splat(1e-30));
    let term3 = a2pb2 * c2 + Rgb::splat(s4);
    let term4 = term2 * s2;
    let rp = rs * (term3 - term4) / (term3 + term4).max(Rgb::splat(1e-30));
    (0.5 * (rs + rp)).clamp(Rgb::ZERO, Rgb::ONE)
}

/// [`fresnel_conductor`] at normal incidence, ((η − 1)² + k²) / ((η + 1)² + k²):
/// the same value without the square roots, for tests made at every hit.
#[inline]
pub fn fresnel_conductor_normal(eta: Rgb, k: Rgb) -> Rgb {
    let k2 = k * k;
    let below = (eta - Rgb::ONE) * (eta - Rgb::ONE) + k2;
    let above = (eta + Rgb::ONE) * (eta + Rgb::ONE) + k2;
    below / above.max(Rgb::splat(1e-30))
}

/// Fraction of uniformly diffuse light that a smooth interface of relative
/// IOR `eta` reflects: 2 ∫ F(cos) cos d(cos). The polynomial fits of d'Eon
/// and Irving that Mitsuba uses, so that plastics match it.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let i1 = 1.0 / eta;
        let i2 = i1 * i1;
        let i3 = i2 * i1;
        let i4 = i3 * i1;
        let i5 = i4 * i1;
        0.919317 - 3.4793 * i1 + 6.75335 * i2 - 7.80989 * i3 + 4.98554 * i4 - 1.36881 * i5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_matches_known_values() {
        // Normal incidence, glass: ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
        let f = fresnel_dielectric(1.0, 1.5);
        assert!((f.reflectance - 0.04).abs() < 1e-6);
        assert!((f.cos_t + 1.0).abs() < 1e-6);
        // Inside glass beyond the critical angle asin(1/1.5) ~ 41.8 deg: TIR.
        let cos_50 = 50f32.to_radians().cos();
        assert_eq!(fresnel_dielectric(-cos_50, 1.5).reflectance, 1.0);
        // Grazing incidence reflects everything.
        assert!(fresnel_dielectric(1e-6, 1.5).reflectance > 0.999);
    }

    #[test]
    fn conductor_fresnel_reduces_to_the_dielectric_one_and_to_normal_incidence() {
        // k = 0: a dielectric seen from outside.
        for cos in [1.0, 0.7, 0.3, 0.05] {
            let c = fresnel_conductor(cos, Rgb::splat(1.5), Rgb::ZERO);
            let d = fresnel_dielectric(cos, 1.5).reflectance;
            assert!((c.x - d).abs() < 1e-5, "cos {cos}: {} vs {d}", c.x);
        }
        // Normal incidence: ((eta - 1)² + k²) / ((eta + 1)² + k²).
        let (eta, k) = (0.2f32, 3.9f32);
        let expected = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        let c = fresnel_conductor(1.0, Rgb::splat(eta), Rgb::splat(k));
        assert!((c.x - expected).abs() < 1e-5);
        let n = fresnel_conductor_normal(Rgb::new(eta, 1.0, 1.5), Rgb::new(k, 0.0, 0.0));
        assert!((n.x - expected).abs() < 1e-6);
        assert_eq!(n.y, 0.0, "eta 1, k 0 reflects nothing");
        assert!((n.z - 0.04).abs() < 1e-6);
        assert!(fresnel_conductor(0.0, Rgb::splat(eta), Rgb::splat(k)).x > 0.999);
    }

    #[test]
    fn diffuse_reflectance_fit_matches_quadrature() {
        for eta in [1.33f32, 1.5, 2.0, 1.0 / 1.5] {
            let n = 20_000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let c = (i as f64 + 0.5) / n as f64;
                    2.0 * fresnel_dielectric(c as f32, eta).reflectance as f64 * c / n as f64
                })
                .sum();
            let fit = fresnel_diffuse_reflectance(eta) as f64;
            assert!((fit - sum).abs() < 6e-3, "eta {eta}: fit {fit} vs {sum}");
        }
    }
}
