//! BSDFs: a closed enum with `eval` / `sample` / `pdf`, dispatched once per
//! vertex (no trait objects); one file per scattering model, the
//! microfacet distributions and Fresnel terms beside them.
//!
//! All directions are in the local shading frame of the surface (normal =
//! +z, the geometric normal as stored, not flipped), both pointing away
//! from the surface; `wo` towards the camera (or the previous vertex).
//! The four original models (Lambert, Phong, mirror, smooth dielectric)
//! are two-sided. The models added for real scenes are one-sided as Mitsuba
//! defines them, black seen from behind, unless `two_sided` (Mitsuba's
//! `twosided`), which gives the back the front's response.
//! f is the radiance BSDF: transmission into a denser medium carries the
//! 1/η² compression, which light paths divide out with
//! [`Bsdf::refraction_scale`].

pub mod conductor;
pub mod dielectric;
pub mod fresnel;
pub mod lambert;
pub mod microfacet;
pub mod mirror;
pub mod phong;
pub mod plastic;
pub mod presets;
pub mod principled;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod rough_diffuse;
pub mod rough_plastic;
pub mod thin_dielectric;

pub use conductor::Conductor;
pub use fresnel::{Fresnel, fresnel_conductor, fresnel_dielectric};
pub use microfacet::{Distribution, Microfacet};
pub use phong::Phong;
pub use plastic::Plastic;
pub use principled::Principled;
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
pub use rough_diffuse::RoughDiffuse;
pub use rough_plastic::RoughPlastic;
pub use thin_dielectric::ThinDielectric;

use crate::math::Rgb;
use glam::{Vec2, Vec3A};

/// Scattering function of a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflection: f = albedo / π. Two-sided.
    Diffuse { albedo: Rgb },
    /// Diffuse plus a normalised modified Phong lobe ([`Phong`]). Two-sided.
    Glossy {
        diffuse: Rgb,
        specular: Rgb,
        exponent: f32,
        diffuse_probability: f32,
    },
    /// Perfect specular reflection. Two-sided.
    Mirror { reflectance: Rgb },
    /// Smooth dielectric boundary: Snell refraction, exact unpolarised Fresnel
    /// reflectance, total internal reflection. `eta` = interior / exterior IOR,
    /// the exterior being the side the geometric normal points to.
    Dielectric { eta: f32, tint: Rgb },
    /// Oren–Nayar rough diffuse.
    RoughDiffuse { lobe: RoughDiffuse, two_sided: bool },
    /// Smooth conductor: a Fresnel-weighted mirror.
    Conductor { lobe: Conductor, two_sided: bool },
    /// Microfacet conductor.
    RoughConductor {
        lobe: RoughConductor,
        two_sided: bool,
    },
    /// Smooth plastic: a dielectric coating over a diffuse base.
    Plastic { lobe: Plastic, two_sided: bool },
    /// Rough plastic: a microfacet coating over a diffuse base.
    RoughPlastic { lobe: RoughPlastic, two_sided: bool },
    /// A thin slab: reflection and straight-through transmission.
    ThinDielectric(ThinDielectric),
    /// Microfacet dielectric boundary.
    RoughDielectric(RoughDielectric),
    /// Mitsuba 3's `principled` (Burley's BSDF). With transmission it is
    /// a boundary, both sides scattering, and `two_sided` is not read.
    Principled { lobe: Principled, two_sided: bool },
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

const FLIP_Z: Vec3A = Vec3A::new(1.0, 1.0, -1.0);

/// Both directions moved to the side of the normal, for a one-sided model
/// seen from `wo`: mirrored when `two_sided` and `wo` is behind; None when
/// the surface is seen from behind and black there.
#[inline]
fn orient(two_sided: bool, wo: Vec3A, wi: Vec3A) -> Option<(Vec3A, Vec3A)> {
    if wo.z > 0.0 {
        Some((wo, wi))
    } else if two_sided && wo.z < 0.0 {
        Some((wo * FLIP_Z, wi * FLIP_Z))
    } else {
        None
    }
}

/// Samples a one-sided model from `wo`'s side (see [`orient`]), the
/// sampled direction mirrored back.
#[inline]
fn sample_oriented(
    two_sided: bool,
    wo: Vec3A,
    sample: impl FnOnce(Vec3A) -> Option<BsdfSample>,
) -> Option<BsdfSample> {
    let (wo_up, _) = orient(two_sided, wo, wo)?;
    let mut s = sample(wo_up)?;
    if wo.z < 0.0 {
        s.wi *= FLIP_Z;
    }
    Some(s)
}

/// The sample of direction `wi` of density `pdf`, weighed by f (given by
/// `f`) · |cos| / pdf; None where the density is zero or a value is not
/// finite (the sample carries no energy).
#[inline]
fn weighed(wi: Vec3A, pdf: f32, f: impl FnOnce() -> Rgb) -> Option<BsdfSample> {
    if !(pdf > 0.0) || !pdf.is_finite() {
        return None;
    }
    let weight = f() * (wi.z.abs() / pdf);
    weight.is_finite().then_some(BsdfSample {
        wi,
        weight,
        pdf,
        specular: false,
    })
}

impl Bsdf {
    /// True when every scattering event is a Dirac delta (no light sampling helps).
    #[inline]
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Bsdf::Mirror { .. }
                | Bsdf::Dielectric { .. }
                | Bsdf::Conductor { .. }
                | Bsdf::ThinDielectric(_)
        )
    }

    /// True when some scattering event is a Dirac delta (a path through it
    /// may be specular even if [`Bsdf::is_specular`] is false).
    #[inline]
    pub fn has_delta(&self) -> bool {
        self.is_specular() || matches!(self, Bsdf::Plastic { .. })
    }

    /// True when light can pass through the surface.
    #[inline]
    pub fn is_transmissive(&self) -> bool {
        matches!(
            self,
            Bsdf::Dielectric { .. } | Bsdf::ThinDielectric(_) | Bsdf::RoughDielectric(_)
        ) || matches!(self, Bsdf::Principled { lobe, .. } if lobe.transmits())
    }

    /// True where a photon mapper estimates light from its photons: the
    /// surface has a diffuse part. Through the others (mirrors and glass,
    /// but also rough metals and rough glass, whose narrow lobes read a
    /// photon map with much noise and blur) its camera paths go on by
    /// sampling them, as pbrt's SPPM does.
    #[inline]
    pub fn gathers_photons(&self) -> bool {
        match *self {
            Bsdf::Diffuse { .. }
            | Bsdf::RoughDiffuse { .. }
            | Bsdf::Plastic { .. }
            | Bsdf::RoughPlastic { .. } => true,
            Bsdf::Glossy { diffuse, .. } => diffuse.max_element() > 0.0,
            Bsdf::Principled { lobe, .. } => lobe.has_diffuse(),
            Bsdf::Mirror { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::Conductor { .. }
            | Bsdf::RoughConductor { .. }
            | Bsdf::ThinDielectric(_)
            | Bsdf::RoughDielectric(_) => false,
        }
    }

    /// The probability that [`Bsdf::sample`] picks a Dirac lobe at `wo`,
    /// for a model with a Dirac lobe over a diffuse one (a smooth plastic's
    /// coating); 0 for the others.
    #[inline]
    pub fn delta_probability(&self, wo: Vec3A) -> f32 {
        match *self {
            Bsdf::Plastic { lobe, two_sided } => {
                orient(two_sided, wo, wo).map_or(0.0, |(wo, _)| lobe.delta_probability(wo))
            }
            _ => 0.0,
        }
    }

    /// True when the surface scatters nothing (paths end here).
    #[inline]
    pub fn is_black(&self) -> bool {
        match *self {
            Bsdf::Dielectric { .. } | Bsdf::RoughDielectric(_) => false,
            Bsdf::Principled { lobe, .. } if lobe.transmits() => false,
            _ => self.max_reflectance() <= 0.0,
        }
    }

    /// BSDF value f(wo, wi) without the cosine; zero for Dirac events.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Rgb {
        match *self {
            Bsdf::Diffuse { albedo } => lambert::eval(albedo, wo, wi),
            Bsdf::Glossy { .. } => {
                let (wo, wi) = orient(true, wo, wi).unwrap_or((wo, wi));
                self.phong().eval(wo, wi)
            }
            Bsdf::Mirror { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::Conductor { .. }
            | Bsdf::ThinDielectric(_) => Rgb::ZERO,
            Bsdf::RoughDiffuse { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(Rgb::ZERO, |(wo, wi)| lobe.eval(wo, wi))
            }
            Bsdf::RoughConductor { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(Rgb::ZERO, |(wo, wi)| lobe.eval(wo, wi))
            }
            Bsdf::Plastic { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(Rgb::ZERO, |(wo, wi)| lobe.eval(wo, wi))
            }
            Bsdf::RoughPlastic { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(Rgb::ZERO, |(wo, wi)| lobe.eval(wo, wi))
            }
            Bsdf::RoughDielectric(lobe) => lobe.eval(wo, wi),
            Bsdf::Principled { lobe, two_sided } => match lobe.transmits() {
                true => lobe.eval(wo, wi),
                false => orient(two_sided, wo, wi).map_or(Rgb::ZERO, |(wo, wi)| lobe.eval(wo, wi)),
            },
        }
    }

    /// f(wo, wi) with the densities of sampling `wi` from `wo` and `wo`
    /// from `wi`, in one evaluation: what a bidirectional connection needs
    /// at each end. Equals `(eval(wo, wi), pdf(wo, wi), pdf(wi, wo))`.
    #[inline]
    pub fn eval_with_pdfs(&self, wo: Vec3A, wi: Vec3A) -> (Rgb, f32, f32) {
        match *self {
            Bsdf::Diffuse { albedo } => lambert::eval_with_pdfs(albedo, wo, wi),
            Bsdf::Glossy { .. } => {
                let (wo, wi) = orient(true, wo, wi).unwrap_or((wo, wi));
                self.phong().eval_with_pdfs(wo, wi)
            }
            _ => (self.eval(wo, wi), self.pdf(wo, wi), self.pdf(wi, wo)),
        }
    }

    /// As [`Bsdf::eval_with_pdfs`] at a vertex of a light subpath, where
    /// importance flows from `wo` (towards the light) to `wi`: the adjoint
    /// f*(wo, wi) = f(wi, wo), which differs from f by the 1/η² of
    /// transmission, with the same densities.
    #[inline]
    pub fn eval_adjoint_with_pdfs(&self, wo: Vec3A, wi: Vec3A) -> (Rgb, f32, f32) {
        let (f, pdf, pdf_reverse) = self.eval_with_pdfs(wo, wi);
        (f / self.refraction_scale(wo, wi), pdf, pdf_reverse)
    }

    /// Density wrt. solid angle with which [`Bsdf::sample`] picks `wi`;
    /// zero for Dirac events.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match *self {
            Bsdf::Diffuse { .. } => lambert::pdf(wo, wi),
            Bsdf::Glossy { .. } => {
                let (wo, wi) = orient(true, wo, wi).unwrap_or((wo, wi));
                self.phong().pdf(wo, wi)
            }
            Bsdf::Mirror { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::Conductor { .. }
            | Bsdf::ThinDielectric(_) => 0.0,
            Bsdf::RoughDiffuse { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(0.0, |(wo, wi)| lobe.pdf(wo, wi))
            }
            Bsdf::RoughConductor { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(0.0, |(wo, wi)| lobe.pdf(wo, wi))
            }
            Bsdf::Plastic { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(0.0, |(wo, wi)| lobe.pdf(wo, wi))
            }
            Bsdf::RoughPlastic { lobe, two_sided } => {
                orient(two_sided, wo, wi).map_or(0.0, |(wo, wi)| lobe.pdf(wo, wi))
            }
            Bsdf::RoughDielectric(lobe) => lobe.pdf(wo, wi),
            Bsdf::Principled { lobe, two_sided } => match lobe.transmits() {
                true => lobe.pdf(wo, wi),
                false => orient(two_sided, wo, wi).map_or(0.0, |(wo, wi)| lobe.pdf(wo, wi)),
            },
        }
    }

    /// Samples an incident direction for outgoing `wo`. `u_lobe` chooses among
    /// lobes or events, `u` places the direction. `None` when the sample carries
    /// no energy (below the horizon, or the back of a one-sided surface).
    #[inline]
    pub fn sample(&self, wo: Vec3A, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        match *self {
            Bsdf::Diffuse { albedo } => lambert::sample(albedo, wo, u),
            Bsdf::Glossy { .. } => {
                sample_oriented(true, wo, |wo| self.phong().sample(wo, u_lobe, u))
            }
            Bsdf::Mirror { reflectance } => mirror::sample(reflectance, wo),
            Bsdf::Dielectric { eta, tint } => dielectric::sample(eta, tint, wo, u_lobe),
            Bsdf::RoughDiffuse { lobe, two_sided } => {
                sample_oriented(two_sided, wo, |wo| lobe.sample(wo, u))
            }
            Bsdf::Conductor { lobe, two_sided } => {
                sample_oriented(two_sided, wo, |wo| lobe.sample(wo))
            }
            Bsdf::RoughConductor { lobe, two_sided } => {
                sample_oriented(two_sided, wo, |wo| lobe.sample(wo, u))
            }
            Bsdf::Plastic { lobe, two_sided } => {
                sample_oriented(two_sided, wo, |wo| lobe.sample(wo, u_lobe, u))
            }
            Bsdf::RoughPlastic { lobe, two_sided } => {
                sample_oriented(two_sided, wo, |wo| lobe.sample(wo, u_lobe, u))
            }
            Bsdf::ThinDielectric(lobe) => lobe.sample(wo, u_lobe),
            Bsdf::RoughDielectric(lobe) => lobe.sample(wo, u_lobe, u),
            Bsdf::Principled { lobe, two_sided } => match lobe.transmits() {
                true => lobe.sample(wo, u_lobe, u),
                false => sample_oriented(two_sided, wo, |wo| lobe.sample(wo, u_lobe, u)),
            },
        }
    }

    /// The factor (eta_i / eta_t)^2 that [`Bsdf::sample`]'s weight and
    /// [`Bsdf::eval`] apply to radiance carried from `wi` to `wo`
    /// (directions on opposite sides of a refracting boundary), else 1.
    /// Roulette divides it out: radiance inside glass is smaller by 1/eta^2
    /// without the path being worth less; light paths divide it out too,
    /// as importance is not compressed.
    #[inline]
    pub fn refraction_scale(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match *self {
            Bsdf::Dielectric { eta, .. } => dielectric::refraction_scale(eta, wo, wi),
            Bsdf::RoughDielectric(lobe) => lobe.refraction_scale(wo, wi),
            Bsdf::Principled { lobe, .. } if lobe.transmits() => lobe.refraction_scale(wo, wi),
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
            Bsdf::RoughDiffuse { lobe, .. } => lobe.albedo.max_element(),
            Bsdf::Conductor { lobe, .. } => lobe.albedo_hint(),
            Bsdf::RoughConductor { lobe, .. } => lobe.albedo_hint(),
            Bsdf::Plastic { lobe, .. } => lobe.albedo_hint(),
            Bsdf::RoughPlastic { lobe, .. } => lobe.albedo_hint(),
            Bsdf::ThinDielectric(lobe) => lobe.albedo_hint(),
            Bsdf::RoughDielectric(lobe) => lobe.albedo_hint(),
            Bsdf::Principled { lobe, .. } => lobe.albedo_hint(),
        }
    }

    /// What a diffuse-only method (radiosity) makes of this surface: a
    /// patch of this diffuse reflectance, with whether that drops part of
    /// the model (a note then says so), or None for a surface it can only
    /// trace through (mirrors, glass, conductors).
    pub fn diffuse_albedo(&self) -> Option<(Rgb, bool)> {
        match *self {
            Bsdf::Diffuse { albedo } => Some((albedo, false)),
            Bsdf::Glossy { diffuse, .. } => Some((diffuse, true)),
            Bsdf::RoughDiffuse { lobe, .. } => Some((lobe.albedo, true)),
            Bsdf::Plastic { lobe, .. } => Some((lobe.diffuse, true)),
            Bsdf::RoughPlastic { lobe, .. } => Some((lobe.diffuse, true)),
            Bsdf::Principled { lobe, .. } => Some((lobe.diffuse_colour(), true)),
            _ => None,
        }
    }

    /// The ideal (Dirac) events nearest to this model, for Whitted ray
    /// tracing: a reflection and a transmission, each with its direction
    /// and weight (zero when absent). A rough lobe is read as its smooth
    /// limit, a plastic's coating as a smooth one; diffuse lobes have none.
    pub fn ideal_events(&self, wo: Vec3A) -> [(Vec3A, Rgb); 2] {
        let mirror = Vec3A::new(-wo.x, -wo.y, wo.z);
        let none = (Vec3A::Z, Rgb::ZERO);
        let refract = |eta: f32, tint: Rgb| -> [(Vec3A, Rgb); 2] {
            let f = fresnel_dielectric(wo.z, eta);
            let wt = Vec3A::new(-wo.x * f.eta_ti, -wo.y * f.eta_ti, f.cos_t);
            // (eta_i / eta_t)^2: radiance crossing into a denser medium.
            let t = tint * ((1.0 - f.reflectance) * f.eta_ti * f.eta_ti);
            [(mirror, Rgb::splat(f.reflectance)), (wt, t)]
        };
        let conductor = |eta: Rgb, k: Rgb, tint: Rgb, two_sided: bool| {
            if wo.z > 0.0 || two_sided {
                [(mirror, tint * fresnel_conductor(wo.z.abs(), eta, k)), none]
            } else {
                [none, none]
            }
        };
        let coating = |eta: f32, specular: Rgb, two_sided: bool| {
            if wo.z > 0.0 || two_sided {
                let f = fresnel_dielectric(wo.z.abs(), eta).reflectance;
                [(mirror, specular * f), none]
            } else {
                [none, none]
            }
        };
        match *self {
            Bsdf::Mirror { reflectance } => [(mirror, reflectance), none],
            Bsdf::Dielectric { eta, tint } => refract(eta, tint),
            Bsdf::RoughDielectric(lobe) => {
                let [r, t] = refract(lobe.eta, lobe.transmittance);
                [(r.0, r.1 * lobe.reflectance), t]
            }
            Bsdf::ThinDielectric(lobe) => {
                let r = lobe.slab_reflectance(wo.z);
                [
                    (mirror, lobe.reflectance * r),
                    (-wo, lobe.transmittance * (1.0 - r)),
                ]
            }
            Bsdf::Conductor { lobe, two_sided } => {
                conductor(lobe.eta, lobe.k, lobe.tint, two_sided)
            }
            Bsdf::RoughConductor { lobe, two_sided } => {
                conductor(lobe.eta, lobe.k, lobe.tint, two_sided)
            }
            Bsdf::Plastic { lobe, two_sided } => coating(lobe.eta, lobe.specular, two_sided),
            Bsdf::RoughPlastic { lobe, two_sided } => coating(lobe.eta, lobe.specular, two_sided),
            Bsdf::Principled { lobe, two_sided } => {
                if lobe.transmits() {
                    let [(r, _), t] = refract(lobe.eta, lobe.transmission_tint());
                    [(r, lobe.ideal_reflectance(wo.z)), t]
                } else if wo.z > 0.0 || two_sided {
                    [(mirror, lobe.ideal_reflectance(wo.z.abs())), none]
                } else {
                    [none, none]
                }
            }
            Bsdf::Diffuse { .. } | Bsdf::Glossy { .. } | Bsdf::RoughDiffuse { .. } => [none, none],
        }
    }

    /// True when Whitted ray tracing reads this model as an ideal one.
    pub fn is_rough(&self) -> bool {
        matches!(
            self,
            Bsdf::RoughConductor { .. }
                | Bsdf::RoughPlastic { .. }
                | Bsdf::RoughDielectric(_)
                | Bsdf::Principled { .. }
        )
    }

    /// Builds a glossy BSDF (see [`Phong::new`]).
    pub fn glossy(diffuse: Rgb, specular: Rgb, exponent: f32) -> Bsdf {
        Phong::new(diffuse, specular, exponent).into()
    }

    #[inline]
    fn phong(&self) -> Phong {
        match *self {
            Bsdf::Glossy {
                diffuse,
                specular,
                exponent,
                diffuse_probability,
            } => Phong {
                diffuse,
                specular,
                exponent,
                diffuse_probability,
            },
            _ => unreachable!("phong() of a non-Phong BSDF"),
        }
    }

    /// The model's name as a scene file would write it.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Bsdf::Diffuse { .. } => "diffuse",
            Bsdf::Glossy { .. } => "glossy",
            Bsdf::Mirror { .. } => "mirror",
            Bsdf::Dielectric { .. } => "dielectric",
            Bsdf::RoughDiffuse { .. } => "roughdiffuse",
            Bsdf::Conductor { .. } => "conductor",
            Bsdf::RoughConductor { .. } => "roughconductor",
            Bsdf::Plastic { .. } => "plastic",
            Bsdf::RoughPlastic { .. } => "roughplastic",
            Bsdf::ThinDielectric(_) => "thindielectric",
            Bsdf::RoughDielectric(_) => "roughdielectric",
            Bsdf::Principled { .. } => "principled",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn one_sided_models_are_black_from_behind_unless_two_sided() {
        let lobe = RoughConductor {
            microfacet: Microfacet::isotropic(Distribution::Ggx, 0.3),
            eta: Rgb::splat(0.2),
            k: Rgb::splat(3.0),
            tint: Rgb::ONE,
        };
        let (wo, wi) = (
            Vec3A::new(0.3, 0.1, -0.9).normalize(),
            Vec3A::new(-0.2, 0.1, -0.95).normalize(),
        );
        let one = Bsdf::RoughConductor {
            lobe,
            two_sided: false,
        };
        let two = Bsdf::RoughConductor {
            lobe,
            two_sided: true,
        };
        assert_eq!(one.eval(wo, wi), Rgb::ZERO);
        assert!(one.sample(wo, 0.5, Vec2::splat(0.3)).is_none());
        assert_eq!(two.eval(wo, wi), one.eval(wo * FLIP_Z, wi * FLIP_Z));
        let s = two.sample(wo, 0.5, Vec2::splat(0.3)).unwrap();
        assert!(s.wi.z < 0.0);
    }
}
