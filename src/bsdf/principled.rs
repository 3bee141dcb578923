//! Mitsuba 3's `principled` BSDF (Burley 2012 and 2015, as Mitsuba
//! defines it, so that its files render as they do there): a diffuse lobe
//! with retro-reflection, fake subsurface (`flatness`) and sheen; a GGX
//! specular lobe whose Fresnel term mixes the dielectric's, a tinted
//! Schlick and the metal's Schlick of the base colour; a microfacet
//! transmission lobe (`spec_trans`); and a GTR1 clearcoat. Only the
//! specular lobes act from behind, and only with transmission.
//!
//! `wo` looks towards the camera (Mitsuba's `wi`), `wi` towards the light.
//! Sampling is ours: a lobe by weights that depend on `wo` alone, then, in
//! the specular lobe, reflection or refraction by the Fresnel term at the
//! sampled normal; the densities of every lobe add up in [`Principled::pdf`].

use super::BsdfSample;
use super::fresnel::fresnel_dielectric;
use super::microfacet::{Distribution, Microfacet};
use crate::math::{Rgb, luminance};
use glam::{Vec2, Vec3A};
use std::f32::consts::{FRAC_1_PI, PI};

/// The parameters of Mitsuba's `principled`, each in [0, 1] but `eta`.
/// Plain floats (64 bytes), so that a [`super::Bsdf`] stays as small as
/// the rough plastic makes it: vertices of bidirectional methods hold one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    pub base: [f32; 3],
    /// GGX's α along u and v: max(0.001, roughness²), stretched by
    /// `anisotropic` ([`Principled::alphas`]).
    pub alpha: [f32; 2],
    pub roughness: f32,
    pub anisotropic: f32,
    pub metallic: f32,
    pub spec_trans: f32,
    /// Interior over exterior IOR (Mitsuba's `eta`, or from `specular`).
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    /// GTR1's α, lerp(0.1, 0.001, clearcoat_gloss).
    pub clearcoat_alpha: f32,
}

/// Mitsuba's `schlick_weight`: (1 − cos)⁵, cos clamped to [0, 1].
#[inline]
fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's Fresnel from `r0` at a microfacet cosine `cos` (negative
/// inside); past the critical angle's side it reads the transmitted cosine.
#[inline]
fn schlick(r0: Rgb, cos: f32, eta: f32) -> Rgb {
    let eta_it = if cos >= 0.0 { eta } else { 1.0 / eta };
    let weight = if eta_it > 1.0 {
        schlick_weight(cos.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos * cos) / (eta_it * eta_it);
        schlick_weight(cos_t2.max(0.0).sqrt())
    };
    r0 + (Rgb::ONE - r0) * weight
}

/// The reflectance of a dielectric at normal incidence.
#[inline]
fn schlick_r0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Smith's G1 of GGX at roughness `alpha` for direction `v` and normal `m`
/// (the clearcoat's masking, separable as Mitsuba's).
#[inline]
fn smith_ggx1(v: Vec3A, m: Vec3A, alpha: f32) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    let cos2 = v.z * v.z;
    let tan2 = (1.0 - cos2) / cos2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// GTR1's normal density (Burley's clearcoat), normalised over the
/// projected hemisphere.
#[inline]
fn gtr1(m: Vec3A, alpha: f32) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z))
}

/// Samples GTR1's normals in proportion to D(m) cos θ_m.
#[inline]
fn sample_gtr1(u: Vec2, alpha: f32) -> Vec3A {
    let a2 = alpha * alpha;
    let cos2 = ((1.0 - a2.powf(1.0 - u.y)) / (1.0 - a2)).clamp(0.0, 1.0);
    let (sin, cos) = ((1.0 - cos2).sqrt(), cos2.sqrt());
    let (sin_phi, cos_phi) = (2.0 * PI * u.x).sin_cos();
    Vec3A::new(cos_phi * sin, sin_phi * sin, cos)
}

/// The half vector of a pair, facing +z, with η' (1 for reflection);
/// None where a microfacet would be seen from behind by either direction
/// (Mitsuba's macro-micro compatibility).
#[inline]
fn half_vector(eta: f32, wo: Vec3A, wi: Vec3A) -> Option<(Vec3A, f32)> {
    if wo.z == 0.0 || wi.z == 0.0 {
        return None;
    }
    let reflect = wo.z * wi.z > 0.0;
    let etap = match (reflect, wo.z > 0.0) {
        (true, _) => 1.0,
        (false, true) => eta,
        (false, false) => 1.0 / eta,
    };
    let m = (wo + wi * etap).normalize();
    let m = if m.z < 0.0 { -m } else { m };
    // wo on m's outer side; wi on it too for reflection, past it for refraction.
    let outer = wo.z.signum();
    let wi_side = if reflect { outer } else { -outer };
    if !m.is_finite() || wo.dot(m) * outer <= 0.0 || wi.dot(m) * wi_side <= 0.0 {
        return None;
    }
    Some((m, etap))
}

impl Principled {
    #[inline]
    fn base_color(&self) -> Rgb {
        Rgb::from(self.base)
    }

    /// The base colour over its luminance (white where it is black): the
    /// hue that `spec_tint` and `sheen_tint` lend.
    #[inline]
    fn tint(&self) -> Rgb {
        let lum = luminance(self.base_color());
        if lum > 0.0 {
            self.base_color() / lum
        } else {
            Rgb::ONE
        }
    }

    /// The specular lobes' GGX.
    #[inline]
    pub fn microfacet(&self) -> Microfacet {
        Microfacet::new(Distribution::Ggx, self.alpha[0], self.alpha[1])
    }

    /// The weight of the diffuse lobes (Mitsuba's `brdf`) and of
    /// transmission (its `bsdf`).
    #[inline]
    fn weights(&self) -> (f32, f32) {
        let dielectric = 1.0 - self.metallic;
        (
            dielectric * (1.0 - self.spec_trans),
            dielectric * self.spec_trans,
        )
    }

    /// True when the diffuse lobe (with sheen) has a weight.
    #[inline]
    pub fn has_diffuse(&self) -> bool {
        self.weights().0 > 0.0
    }

    /// True when light passes through (the back side then scatters too).
    #[inline]
    pub fn transmits(&self) -> bool {
        self.weights().1 > 0.0
    }

    /// Mitsuba's `principled_fresnel` of the specular reflection at
    /// microfacet cosine `cos` with the dielectric's `f`.
    #[inline]
    fn fresnel(&self, f: f32, cos: f32, front: bool) -> Rgb {
        let (_, transmission) = self.weights();
        if !front {
            return Rgb::splat(transmission * f);
        }
        let metal = self.metallic * schlick(self.base_color(), cos, self.eta);
        let eta_it = if cos >= 0.0 { self.eta } else { 1.0 / self.eta };
        let tinted = schlick(self.tint() * schlick_r0(eta_it), cos, self.eta);
        let dielectric = 1.0 - self.metallic;
        Rgb::splat(dielectric * (1.0 - self.spec_tint) * f)
            + metal
            + dielectric * self.spec_tint * tinted
    }

    /// f(wo, wi), the cosine not included.
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        let Some((m, etap)) = half_vector(self.eta, wo, wi) else {
            return Rgb::ZERO;
        };
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let (diffuse_weight, transmission) = self.weights();
        let front = wo.z > 0.0;
        let f = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        let microfacet = self.microfacet();
        let (d, g) = (microfacet.d(m), microfacet.g(wo, wi, m));
        if wo.z * wi.z < 0.0 {
            if transmission <= 0.0 || f >= 1.0 {
                return Rgb::ZERO;
            }
            // Radiance compressed by 1/η'², as the rough dielectric's.
            let denom = wo.dot(m) + etap * wi.dot(m);
            let t =
                (1.0 - f) * d * g * (wo.dot(m) * wi.dot(m)).abs() / (cos_o * cos_i * denom * denom);
            return sqrt_rgb(self.base_color()) * (transmission * t);
        }
        let mut value = Rgb::ZERO;
        if f > 0.0 {
            value += self.fresnel(f, wo.dot(m), front) * (d * g / (4.0 * cos_o * cos_i));
        }
        if !front {
            return value;
        }
        if self.clearcoat > 0.0 {
            let fcc = schlick(Rgb::splat(0.04), wo.dot(m), self.eta).x;
            let gcc = smith_ggx1(wo, m, 0.25) * smith_ggx1(wi, m, 0.25);
            value += Rgb::splat(0.25 * self.clearcoat * fcc * gtr1(m, self.clearcoat_alpha) * gcc);
        }
        if diffuse_weight > 0.0 {
            let (fo, fi) = (schlick_weight(cos_i), schlick_weight(cos_o));
            let cos_d = m.dot(wi);
            let rr = 2.0 * self.roughness * cos_d * cos_d;
            let lambert = (1.0 - 0.5 * fo) * (1.0 - 0.5 * fi);
            let retro = rr * (fo + fi + fo * fi * (rr - 1.0));
            let mut diffuse = lambert + retro;
            if self.flatness > 0.0 {
                // Hanrahan–Krueger's flattened lobe, Burley's fake subsurface.
                let fss90 = 0.5 * rr;
                let fss = (1.0 + (fss90 - 1.0) * fo) * (1.0 + (fss90 - 1.0) * fi);
                let ss = 1.25 * (fss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
                diffuse += (ss - diffuse) * self.flatness;
            }
            value += self.base_color() * (diffuse_weight * diffuse * FRAC_1_PI);
            if self.sheen > 0.0 && self.metallic < 1.0 {
                let colour = Rgb::ONE + (self.tint() - Rgb::ONE) * self.sheen_tint;
                let weight = self.sheen * (1.0 - self.metallic) * schlick_weight(cos_d.abs());
                value += colour * weight;
            }
        }
        value
    }

    /// The probabilities of the diffuse, clearcoat and specular lobes
    /// seen from `wo`.
    #[inline]
    fn lobe_probabilities(&self, wo: Vec3A) -> [f32; 3] {
        if wo.z <= 0.0 {
            return [0.0, 0.0, 1.0];
        }
        let (diffuse, _) = self.weights();
        let clearcoat = 0.25 * self.clearcoat;
        let total = diffuse + clearcoat + 1.0;
        [diffuse / total, clearcoat / total, 1.0 / total]
    }

    /// The probability of refracting at a sampled normal of dielectric
    /// Fresnel `f`: Mitsuba's share of the transmission lobe.
    #[inline]
    fn refraction_probability(&self, f: f32, front: bool) -> f32 {
        let (_, transmission) = self.weights();
        if transmission <= 0.0 {
            return 0.0;
        }
        match front {
            true => transmission * (1.0 - f),
            false => 1.0 - f,
        }
    }

    /// Density with which [`Principled::sample`] picks `wi`.
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let Some((m, etap)) = half_vector(self.eta, wo, wi) else {
            return 0.0;
        };
        if wo.z < 0.0 && !self.transmits() {
            return 0.0;
        }
        let [diffuse, clearcoat, specular] = self.lobe_probabilities(wo);
        let wo_up = if wo.z < 0.0 { -wo } else { wo };
        let visible = self.microfacet().pdf_visible(wo_up, m);
        let f = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        let refract = self.refraction_probability(f, wo.z > 0.0);
        if wo.z * wi.z < 0.0 {
            let denom = wo.dot(m) + etap * wi.dot(m);
            return specular * refract * visible * etap * etap * wi.dot(m).abs() / (denom * denom);
        }
        let jacobian = 1.0 / (4.0 * wo.dot(m).abs());
        let mut pdf = specular * (1.0 - refract) * visible * jacobian;
        if clearcoat > 0.0 {
            pdf += clearcoat * gtr1(m, self.clearcoat_alpha) * m.z * jacobian;
        }
        if diffuse > 0.0 {
            pdf += diffuse * wi.z.abs() * FRAC_1_PI;
        }
        pdf
    }

    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || (wo.z < 0.0 && !self.transmits()) {
            return None;
        }
        let [diffuse, clearcoat, _] = self.lobe_probabilities(wo);
        // A reflection that leaves below the surface (or a refraction that
        // does not cross it) is no sample: another lobe would claim it.
        let (wi, reflected) = if u_lobe < diffuse {
            (crate::sampling::warp::square_to_cosine_hemisphere(u), true)
        } else if u_lobe < diffuse + clearcoat {
            let m = sample_gtr1(u, self.clearcoat_alpha);
            (2.0 * wo.dot(m) * m - wo, true)
        } else {
            // Reused for the choice of event, rescaled to [0, 1).
            let u_event = (u_lobe - diffuse - clearcoat) / (1.0 - diffuse - clearcoat);
            let wo_up = if wo.z < 0.0 { -wo } else { wo };
            let m = self.microfacet().sample_visible(wo_up, u);
            let cos = wo.dot(m);
            let fr = fresnel_dielectric(cos, self.eta);
            if u_event < self.refraction_probability(fr.reflectance, wo.z > 0.0) {
                if fr.reflectance >= 1.0 {
                    return None;
                }
                let wi = -wo * fr.eta_ti + (cos * fr.eta_ti + fr.cos_t) * m;
                (wi.normalize(), false)
            } else {
                (2.0 * cos * m - wo, true)
            }
        };
        if (wi.z * wo.z > 0.0) != reflected {
            return None;
        }
        super::weighed(wi, self.pdf(wo, wi), || self.eval(wo, wi))
    }

    /// (η_i / η_t)² that radiance picks up crossing from wi's side to wo's.
    #[inline]
    pub fn refraction_scale(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        super::dielectric::refraction_scale(self.eta, wo, wi)
    }

    /// Reflectance at normal incidence, for lobe choices and roulette.
    pub fn albedo_hint(&self) -> f32 {
        let (diffuse, transmission) = self.weights();
        let r0 = schlick_r0(self.eta);
        let specular = self.metallic * self.base_color() + Rgb::splat((1.0 - self.metallic) * r0);
        let through = sqrt_rgb(self.base_color()) * transmission;
        (self.base_color() * diffuse + specular + through)
            .max_element()
            .min(1.0)
    }

    /// The transmission lobe's colour, √base times its weight.
    pub fn transmission_tint(&self) -> Rgb {
        sqrt_rgb(self.base_color()) * self.weights().1
    }

    /// Sets the roughness (a texture's value at a hit) and the GGX it gives.
    #[inline]
    pub fn set_roughness(&mut self, roughness: f32) {
        self.roughness = roughness;
        self.alpha = Principled::alphas(roughness, self.anisotropic);
    }

    /// The diffuse lobe's colour (what radiosity keeps).
    pub fn diffuse_colour(&self) -> Rgb {
        self.base_color() * self.weights().0
    }

    /// The reflectance of the smooth limit at `wo` (Whitted's mirror).
    pub fn ideal_reflectance(&self, cos: f32) -> Rgb {
        let f = fresnel_dielectric(cos, self.eta).reflectance;
        self.fresnel(f, cos.abs(), cos > 0.0)
    }

    /// GGX's α along u and v from Mitsuba's roughness and anisotropy.
    pub fn alphas(roughness: f32, anisotropic: f32) -> [f32; 2] {
        let r2 = roughness * roughness;
        let aspect = (1.0 - 0.9 * anisotropic).sqrt();
        [(r2 / aspect).max(0.001), (r2 * aspect).max(0.001)]
    }
}

#[inline]
fn sqrt_rgb(c: Rgb) -> Rgb {
    Rgb::new(
        c.x.max(0.0).sqrt(),
        c.y.max(0.0).sqrt(),
        c.z.max(0.0).sqrt(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::RoughConductor;

    /// Metallic 1 with a white base is Schlick's Fresnel of 1: the rough
    /// conductor of Fresnel 1 (η 0, k 1) at α = roughness², in value and
    /// in density, at every pair of directions tried.
    #[test]
    fn a_white_metal_is_the_rough_conductor_of_fresnel_one() {
        let principled = Principled {
            base: [1.0; 3],
            alpha: Principled::alphas(0.3, 0.0),
            roughness: 0.3,
            anisotropic: 0.0,
            metallic: 1.0,
            spec_trans: 0.0,
            eta: 1.5,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_alpha: 0.1,
        };
        let conductor = RoughConductor {
            microfacet: Microfacet::isotropic(Distribution::Ggx, 0.09),
            eta: Rgb::ZERO,
            k: Rgb::ONE,
            tint: Rgb::ONE,
        };
        for i in 0..200 {
            let angle = |k: u32| ((i * 7919 + k * 104_729) % 1000) as f32 / 1000.0;
            let direction = |a: f32, b: f32| {
                let z = 0.05 + 0.95 * a;
                let s = (1.0 - z * z).sqrt();
                let phi = 2.0 * PI * b;
                Vec3A::new(s * phi.cos(), s * phi.sin(), z)
            };
            let wo = direction(angle(1), angle(2));
            let wi = direction(angle(3), angle(4));
            let (f, g) = (principled.eval(wo, wi), conductor.eval(wo, wi));
            assert!(
                (f - g).abs().max_element() <= 1e-5 * g.max_element().max(1.0),
                "{f} {g}"
            );
            let (p, q) = (principled.pdf(wo, wi), conductor.pdf(wo, wi));
            assert!((p - q).abs() <= 1e-5 * q.max(1.0), "{p} {q}");
        }
    }
}
