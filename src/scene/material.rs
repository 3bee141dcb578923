//! Materials: a BSDF plus optional emission. BSDFs are a closed enum with
//! `eval` / `sample` / `pdf`, dispatched once per vertex (no trait objects).
//!
//! All directions are in the local shading frame of the surface (normal = +z,
//! the geometric normal as stored, not flipped), both pointing away from the
//! surface. Opaque BSDFs are two-sided: they act on whichever side `wo` is.

use crate::math::Frame;
use crate::math::{Rgb, luminance, reflect};
use crate::sampling::warp::{
    cosine_hemisphere_pdf, phong_lobe_pdf, square_to_cosine_hemisphere, square_to_phong_lobe,
};
use glam::{Vec2, Vec3A};
use std::f32::consts::{FRAC_1_PI, PI};

/// Scattering function of a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflection: f = albedo / pi.
    Diffuse { albedo: Rgb },
    /// Diffuse plus a normalized modified Phong lobe (Lafortune & Willems 1994):
    /// f = kd / pi + ks (n + 2) / (2 pi) cos^n(alpha), alpha the angle between
    /// wi and the mirror direction of wo. Energy-conserving when kd + ks <= 1
    /// (the loader scales them down otherwise).
    Glossy {
        diffuse: Rgb,
        specular: Rgb,
        exponent: f32,
        diffuse_probability: f32,
    },
    /// Perfect specular reflection.
    Mirror { reflectance: Rgb },
    /// Smooth dielectric boundary: Snell refraction, exact unpolarised Fresnel
    /// reflectance, total internal reflection. `eta` = interior / exterior IOR,
    /// the exterior being the side the geometric normal points to.
    Dielectric { eta: f32, tint: Rgb },
}

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

/// A sampled direction with its Monte Carlo weight.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Incident direction in the local frame.
    pub wi: Vec3A,
    /// f(wo, wi) |cos theta_i| / pdf, the throughput factor of the bounce.
    pub weight: Rgb,
    /// Density wrt. solid angle; for specular events, the discrete probability
    /// of the chosen event (never used for MIS).
    pub pdf: f32,
    /// True for Dirac (mirror/refraction) events.
    pub specular: bool,
}

/// Flips both directions to the +z side when `wo` is below: opaque BSDFs are two-sided.
#[inline]
fn to_upper_side(wo: Vec3A, wi: Vec3A) -> (Vec3A, Vec3A) {
    if wo.z < 0.0 {
        (
            wo * Vec3A::new(1.0, 1.0, -1.0),
            wi * Vec3A::new(1.0, 1.0, -1.0),
        )
    } else {
        (wo, wi)
    }
}

impl Bsdf {
    /// True when every scattering event is a Dirac delta (no light sampling helps).
    #[inline]
    pub fn is_specular(&self) -> bool {
        matches!(self, Bsdf::Mirror { .. } | Bsdf::Dielectric { .. })
    }

    /// True when the surface scatters nothing (paths end here).
    #[inline]
    pub fn is_black(&self) -> bool {
        match *self {
            Bsdf::Diffuse { albedo } => albedo.max_element() <= 0.0,
            Bsdf::Glossy {
                diffuse, specular, ..
            } => diffuse.max_element() <= 0.0 && specular.max_element() <= 0.0,
            Bsdf::Mirror { reflectance } => reflectance.max_element() <= 0.0,
            Bsdf::Dielectric { .. } => false,
        }
    }

    /// BSDF value f(wo, wi) without the cosine; zero for specular BSDFs.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        match *self {
            Bsdf::Diffuse { albedo } => {
                if wo.z * wi.z <= 0.0 {
                    return Rgb::ZERO;
                }
                albedo * FRAC_1_PI
            }
            Bsdf::Glossy {
                diffuse,
                specular,
                exponent,
                ..
            } => {
                let (wo, wi) = to_upper_side(wo, wi);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return Rgb::ZERO;
                }
                let cos_alpha = reflect(wo, Vec3A::Z).dot(wi).max(0.0);
                diffuse * FRAC_1_PI
                    + specular * ((exponent + 2.0) / (2.0 * PI) * cos_alpha.powf(exponent))
            }
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => Rgb::ZERO,
        }
    }

    /// f(wo, wi) with the densities of sampling `wi` from `wo` and `wo`
    /// from `wi`, in one evaluation: what a bidirectional connection needs
    /// at each end. Equals `(eval(wo, wi), pdf(wo, wi), pdf(wi, wo))`; the
    /// Phong lobe's cos^n is symmetric in the two directions and computed
    /// once.
    #[inline]
    pub fn eval_with_pdfs(&self, wo: Vec3A, wi: Vec3A) -> (Rgb, f32, f32) {
        match *self {
            Bsdf::Glossy {
                diffuse,
                specular,
                exponent,
                diffuse_probability,
            } => {
                let (wo, wi) = to_upper_side(wo, wi);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return (Rgb::ZERO, 0.0, 0.0);
                }
                let cos_alpha = reflect(wo, Vec3A::Z).dot(wi).max(0.0);
                let lobe = if cos_alpha > 0.0 {
                    cos_alpha.powf(exponent)
                } else {
                    0.0
                };
                let f = diffuse * FRAC_1_PI + specular * ((exponent + 2.0) / (2.0 * PI) * lobe);
                let phong = (1.0 - diffuse_probability) * (exponent + 1.0) / (2.0 * PI) * lobe;
                let pdf = |w: Vec3A| diffuse_probability * cosine_hemisphere_pdf(w) + phong;
                (f, pdf(wi), pdf(wo))
            }
            _ => (self.eval(wo, wi), self.pdf(wo, wi), self.pdf(wi, wo)),
        }
    }

    /// Density wrt. solid angle with which [`Bsdf::sample`] picks `wi`; zero for specular BSDFs.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match *self {
            Bsdf::Diffuse { .. } => {
                let (_, wi) = to_upper_side(wo, wi);
                cosine_hemisphere_pdf(wi)
            }
            Bsdf::Glossy {
                exponent,
                diffuse_probability,
                ..
            } => {
                let (wo, wi) = to_upper_side(wo, wi);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return 0.0;
                }
                let cos_alpha = reflect(wo, Vec3A::Z).dot(wi);
                diffuse_probability * cosine_hemisphere_pdf(wi)
                    + (1.0 - diffuse_probability) * phong_lobe_pdf(cos_alpha, exponent)
            }
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => 0.0,
        }
    }

    /// Samples an incident direction for outgoing `wo`. `u_lobe` chooses among
    /// lobes or events, `u` places the direction. `None` when the sample carries
    /// no energy (below the horizon).
    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        match *self {
            Bsdf::Diffuse { albedo } => {
                let mut wi = square_to_cosine_hemisphere(u);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                if wi.z == 0.0 || wo.z == 0.0 {
                    return None;
                }
                // f cos / pdf = (albedo / pi) cos / (cos / pi) = albedo.
                Some(BsdfSample {
                    wi,
                    weight: albedo,
                    pdf: cosine_hemisphere_pdf(wi.abs()),
                    specular: false,
                })
            }
            Bsdf::Glossy {
                exponent,
                diffuse_probability,
                ..
            } => {
                let flip = if wo.z < 0.0 {
                    Vec3A::new(1.0, 1.0, -1.0)
                } else {
                    Vec3A::ONE
                };
                let wo_up = wo * flip;
                if wo_up.z <= 0.0 {
                    return None;
                }
                let wi_up = if u_lobe < diffuse_probability {
                    square_to_cosine_hemisphere(u)
                } else {
                    let lobe = Frame::from_normal(reflect(wo_up, Vec3A::Z));
                    lobe.to_world(square_to_phong_lobe(u, exponent))
                };
                if wi_up.z <= 0.0 {
                    return None;
                }
                let wi = wi_up * flip;
                let pdf = self.pdf(wo, wi);
                if pdf <= 0.0 {
                    return None;
                }
                let weight = self.eval(wo, wi) * (wi_up.z / pdf);
                Some(BsdfSample {
                    wi,
                    weight,
                    pdf,
                    specular: false,
                })
            }
            Bsdf::Mirror { reflectance } => Some(BsdfSample {
                wi: Vec3A::new(-wo.x, -wo.y, wo.z),
                weight: reflectance,
                pdf: 1.0,
                specular: true,
            }),
            Bsdf::Dielectric { eta, tint } => {
                let cos_o = wo.z;
                let f = fresnel_dielectric(cos_o, eta);
                if u_lobe < f.reflectance {
                    Some(BsdfSample {
                        wi: Vec3A::new(-wo.x, -wo.y, wo.z),
                        weight: Rgb::ONE,
                        pdf: f.reflectance,
                        specular: true,
                    })
                } else {
                    // Snell: tangential components scale by 1 / eta_rel, the
                    // normal component is cos_t on the other side.
                    let wi = Vec3A::new(-wo.x * f.eta_ti, -wo.y * f.eta_ti, f.cos_t);
                    // Radiance is compressed into a smaller solid angle when
                    // entering a denser medium: scale by (eta_i / eta_t)^2.
                    Some(BsdfSample {
                        wi,
                        weight: tint * (f.eta_ti * f.eta_ti),
                        pdf: 1.0 - f.reflectance,
                        specular: true,
                    })
                }
            }
        }
    }

    /// The factor (eta_i / eta_t)^2 that [`Bsdf::sample`]'s weight applies
    /// to radiance carried from `wi` to `wo` (directions on opposite sides
    /// of a dielectric), else 1. Roulette divides it out: radiance inside
    /// glass is smaller by 1/eta^2 without the path being worth less.
    #[inline]
    pub fn refraction_scale(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match *self {
            Bsdf::Dielectric { eta, .. } if wo.z * wi.z < 0.0 => {
                if wo.z > 0.0 {
                    1.0 / (eta * eta)
                } else {
                    eta * eta
                }
            }
            _ => 1.0,
        }
    }

    /// Directional albedo hint used to pick lobes and to weigh Russian roulette.
    pub fn max_reflectance(&self) -> f32 {
        match *self {
            Bsdf::Diffuse { albedo } => albedo.max_element(),
            Bsdf::Glossy {
                diffuse, specular, ..
            } => (diffuse + specular).max_element(),
            Bsdf::Mirror { reflectance } => reflectance.max_element(),
            Bsdf::Dielectric { tint, .. } => tint.max_element(),
        }
    }

    /// Builds a glossy BSDF, scaling kd + ks down to at most one per channel so
    /// that it conserves energy, and choosing lobes in proportion to their albedo.
    pub fn glossy(diffuse: Rgb, specular: Rgb, exponent: f32) -> Bsdf {
        let sum = (diffuse + specular).max_element();
        let scale = if sum > 1.0 { 1.0 / sum } else { 1.0 };
        let (diffuse, specular) = (diffuse * scale, specular * scale);
        let (ld, ls) = (luminance(diffuse), luminance(specular));
        let diffuse_probability = if ld + ls > 0.0 { ld / (ld + ls) } else { 1.0 };
        Bsdf::Glossy {
            diffuse,
            specular,
            exponent: exponent.max(0.0),
            diffuse_probability,
        }
    }
}

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
    fn refraction_obeys_snell() {
        let bsdf = Bsdf::Dielectric {
            eta: 1.5,
            tint: Rgb::ONE,
        };
        let theta_i = 30f32.to_radians();
        let wo = Vec3A::new(theta_i.sin(), 0.0, theta_i.cos());
        // u_lobe = 0.999 > F picks refraction.
        let s = bsdf.sample(wo, 0.999, Vec2::ZERO).unwrap();
        assert!(s.wi.z < 0.0);
        let sin_t = (s.wi.x * s.wi.x + s.wi.y * s.wi.y).sqrt();
        assert!((sin_t * 1.5 - theta_i.sin()).abs() < 1e-5);
        assert!((s.wi.length() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn glossy_is_scaled_to_conserve_energy() {
        match Bsdf::glossy(Rgb::splat(0.8), Rgb::splat(0.6), 10.0) {
            Bsdf::Glossy {
                diffuse, specular, ..
            } => {
                assert!(((diffuse + specular).max_element() - 1.0).abs() < 1e-6)
            }
            _ => unreachable!(),
        }
    }
}
