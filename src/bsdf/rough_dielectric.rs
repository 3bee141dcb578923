//! Rough dielectric boundary (Walter, Marschner, Li and Torrance 2007;
//! Mitsuba's `roughdielectric`): microfacet reflection and refraction with
//! the exact dielectric Fresnel term, sampled by visible normals, the
//! event chosen with probability F. `eta` = interior / exterior IOR, the
//! exterior on the side the normal points to. f carries radiance: its
//! transmission is divided by η'² (η' = η_t / η_i seen from wo).

use super::BsdfSample;
use super::fresnel::fresnel_dielectric;
use super::microfacet::Microfacet;
use crate::math::Rgb;
use glam::{Vec2, Vec3A};

/// A rough dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    pub microfacet: Microfacet,
    pub eta: f32,
    pub reflectance: Rgb,
    pub transmittance: Rgb,
}

/// The generalised half vector of a pair of directions, facing +z, and η'
/// (1 for reflection); None where it is undefined or a microfacet would
/// be seen from behind by either direction.
#[inline]
fn half_vector(eta: f32, wo: Vec3A, wi: Vec3A) -> Option<(Vec3A, f32)> {
    if wo.z == 0.0 || wi.z == 0.0 {
        return None;
    }
    let reflect = wo.z * wi.z > 0.0;
    let etap = if reflect {
        1.0
    } else if wo.z > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let m = wi * etap + wo;
    if m.length_squared() == 0.0 {
        return None;
    }
    let m = m.normalize();
    let m = if m.z < 0.0 { -m } else { m };
    if m.dot(wi) * wi.z <= 0.0 || m.dot(wo) * wo.z <= 0.0 || !m.is_finite() {
        return None;
    }
    Some((m, etap))
}

impl RoughDielectric {
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        let Some((m, etap)) = half_vector(self.eta, wo, wi) else {
            return Rgb::ZERO;
        };
        let d = self.microfacet.d(m);
        let g = self.microfacet.g(wo, wi, m);
        let f = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        if wo.z * wi.z > 0.0 {
            self.reflectance * (f * d * g / (4.0 * (wo.z * wi.z).abs()))
        } else {
            let denom = wi.dot(m) + wo.dot(m) / etap;
            let t =
                (1.0 - f) * d * g * (wi.dot(m) * wo.dot(m) / (denom * denom * wi.z * wo.z)).abs();
            // Radiance is compressed by 1/η'² on entering the denser side.
            self.transmittance * (t / (etap * etap))
        }
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let Some((m, etap)) = half_vector(self.eta, wo, wi) else {
            return 0.0;
        };
        let wo_up = if wo.z < 0.0 { -wo } else { wo };
        let visible = self.microfacet.pdf_visible(wo_up, m);
        let r = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        let (pr, pt) = self.lobe_probabilities(r);
        if wo.z * wi.z > 0.0 {
            pr * visible / (4.0 * wo.dot(m).abs())
        } else {
            let denom = wi.dot(m) + wo.dot(m) / etap;
            pt * visible * wi.dot(m).abs() / (denom * denom)
        }
    }

    /// Probabilities of reflecting and refracting for Fresnel reflectance
    /// `r`: F and 1 − F, weighted by the tints so that a black lobe is
    /// never chosen.
    #[inline]
    fn lobe_probabilities(&self, r: f32) -> (f32, f32) {
        let pr = r * self.reflectance.max_element();
        let pt = (1.0 - r) * self.transmittance.max_element();
        if pr + pt <= 0.0 {
            return (0.0, 0.0);
        }
        (pr / (pr + pt), pt / (pr + pt))
    }

    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wo_up = if wo.z < 0.0 { -wo } else { wo };
        let m = self.microfacet.sample_visible(wo_up, u);
        let cos = wo.dot(m);
        let fr = fresnel_dielectric(cos, self.eta);
        let (pr, _) = self.lobe_probabilities(fr.reflectance);
        let wi = if u_lobe < pr {
            let wi = 2.0 * cos * m - wo;
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            wi
        } else {
            // Refraction through m (see dielectric.rs), η'-scaled.
            let wi = -wo * fr.eta_ti + (cos * fr.eta_ti + fr.cos_t) * m;
            if wi.z * wo.z >= 0.0 || fr.reflectance >= 1.0 {
                return None;
            }
            wi.normalize()
        };
        super::weighed(wi, self.pdf(wo, wi), || self.eval(wo, wi))
    }

    /// (η_i / η_t)² that radiance picks up crossing from wi's side to wo's.
    #[inline]
    pub fn refraction_scale(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        super::dielectric::refraction_scale(self.eta, wo, wi)
    }

    pub fn albedo_hint(&self) -> f32 {
        self.reflectance
            .max_element()
            .max(self.transmittance.max_element())
    }
}
