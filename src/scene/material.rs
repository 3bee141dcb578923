//! Materials: a BSDF (see [`crate::bsdf`]) plus optional emission.

pub use crate::accel::blend::{Blend, Weight as BlendWeight};
pub use crate::accel::mask::Opacity;
use crate::bsdf::Microfacet;
pub use crate::bsdf::{Bsdf, BsdfSample, Fresnel, fresnel_dielectric};
use crate::math::Rgb;
use crate::texture::Texture;
use glam::{Vec2, Vec3A};

/// A material: how a surface scatters and what it emits.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub bsdf: Bsdf,
    /// Emitted radiance (W sr^-1 m^-2 per channel); zero for non-emitters.
    pub emission: Rgb,
    /// Emit on both sides; by default only along the geometric normal.
    pub two_sided_emission: bool,
    /// A texture (index into the scene's) that multiplies `emission` at
    /// each point (Mitsuba's textured `radiance`, glTF's
    /// `emissiveTexture`); lights read it where they are sampled
    /// ([`crate::scene::light::EmissionTexture`]).
    pub emission_texture: Option<u32>,
    /// Parameters read from textures at each hit.
    pub textures: MaterialTextures,
    /// How much of the surface is there (Mitsuba's `mask`); queries pass
    /// through the rest ([`crate::accel::mask`]).
    pub opacity: Opacity,
    /// A tangent-space normal map that tilts the shading normal
    /// ([`crate::scene::Scene::shading_normal`]).
    pub normal_map: Option<NormalMap>,
    /// A blend with a second material (Mitsuba's `blendbsdf`): hits take
    /// it with the blend's weight ([`crate::accel::blend`]).
    pub blend: Option<Blend>,
}

/// A texture that tilts the shading normal; `texture` indexes the scene's
/// textures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalMap {
    /// Mitsuba's `normalmap`, glTF's `normalTexture`: texel c is the normal
    /// 2c − 1 in the frame (dp/du made orthogonal to the shading normal,
    /// their cross product, the shading normal), its x and y scaled by
    /// `scale` (glTF's; 1 in Mitsuba). Read raw (no sRGB decoding).
    Tangent { texture: u32, scale: f32 },
    /// Mitsuba's `bumpmap`: the surface displaced along its normal by
    /// `scale` times the texture (its luminance), whose gradient in uv
    /// tilts dp/du and dp/dv.
    Bump { texture: u32, scale: f32 },
}

/// Which of a material's parameters come from textures (indices into
/// [`crate::scene::Scene::textures`]), Mitsuba's names.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MaterialTextures {
    /// `reflectance` / `diffuse_reflectance`: the diffuse colour.
    pub diffuse: Option<u32>,
    /// `specular_reflectance`: conductors' and coatings' tint.
    pub specular: Option<u32>,
    /// `alpha` (or `alpha_u`): a rough conductor's, dielectric's or
    /// plastic's roughness (read by `Texture::eval_1`); along u where it is
    /// anisotropic.
    pub alpha: Option<u32>,
    /// `alpha_v`: the roughness along v. An isotropic textured roughness
    /// names the same texture in both.
    pub alpha_v: Option<u32>,
    /// `metallic` of a `principled` (its roughness takes `alpha`, its
    /// base colour `diffuse`).
    pub metallic: Option<u32>,
    /// A rough plastic's coating tables by roughness, where `alpha` is
    /// textured (glTF's roughness maps).
    pub coating: Option<&'static crate::bsdf::rough_plastic::CoatingLevels>,
}

impl MaterialTextures {
    /// True when no parameter is textured.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.diffuse.is_none()
            && self.specular.is_none()
            && self.alpha.is_none()
            && self.alpha_v.is_none()
            && self.metallic.is_none()
    }
}

impl Material {
    /// Sets the textured parameters, with what they need besides the
    /// texture: a rough plastic with a roughness texture gets its coating
    /// tables by roughness.
    pub fn set_textures(&mut self, textures: MaterialTextures) {
        self.textures = MaterialTextures {
            coating: match (&self.bsdf, textures.alpha) {
                (Bsdf::RoughPlastic { lobe, .. }, Some(_)) => {
                    Some(crate::bsdf::rough_plastic::CoatingLevels::of(
                        lobe.microfacet.distribution,
                        lobe.eta,
                    ))
                }
                _ => None,
            },
            ..textures
        };
    }

    /// Asks the cache for the texels that [`Material::bsdf_at`] reads at
    /// `uv`: a caller with work that needs no BSDF starts them early.
    #[inline(always)]
    pub fn prefetch_textures(&self, textures: &[Texture], uv: Vec2) {
        let t = &self.textures;
        for slot in [t.diffuse, t.specular, t.alpha, t.alpha_v, t.metallic] {
            if let Some(i) = slot {
                textures[i as usize].prefetch(uv);
            }
        }
    }

    /// The BSDF at a hit with texture coordinates `uv`: the textured
    /// parameters read from `textures`, the rest as stored.
    #[inline]
    pub fn bsdf_at(&self, textures: &[Texture], uv: Vec2) -> Bsdf {
        let t = self.textures;
        if t.is_empty() {
            return self.bsdf;
        }
        let read = |slot: Option<u32>| slot.map(|i| textures[i as usize].eval(uv));
        let (diffuse, specular) = (read(t.diffuse), read(t.specular));
        let read_1 = |slot: Option<u32>| slot.map(|i| textures[i as usize].eval_1(uv));
        let alpha_u = read_1(t.alpha);
        let alpha_v = match t.alpha_v == t.alpha {
            true => alpha_u,
            false => read_1(t.alpha_v),
        };
        let rough = |m: &mut Microfacet| {
            if alpha_u.is_some() || alpha_v.is_some() {
                let (u, v) = (alpha_u.unwrap_or(m.alpha_u), alpha_v.unwrap_or(m.alpha_v));
                *m = Microfacet::new(m.distribution, u, v);
            }
        };
        let mut bsdf = self.bsdf;
        match &mut bsdf {
            Bsdf::Diffuse { albedo } => *albedo = diffuse.unwrap_or(*albedo),
            Bsdf::RoughDiffuse { lobe, .. } => lobe.albedo = diffuse.unwrap_or(lobe.albedo),
            Bsdf::Plastic { lobe, .. } => {
                lobe.diffuse = diffuse.unwrap_or(lobe.diffuse);
                lobe.specular = specular.unwrap_or(lobe.specular);
            }
            Bsdf::RoughPlastic { lobe, .. } => {
                lobe.diffuse = diffuse.unwrap_or(lobe.diffuse);
                lobe.specular = specular.unwrap_or(lobe.specular);
                if let (Some(a), Some(levels)) = (alpha_u, t.coating) {
                    lobe.microfacet = Microfacet::new(lobe.microfacet.distribution, a, a);
                    lobe.tables = levels.nearest(a);
                }
            }
            Bsdf::Conductor { lobe, .. } => lobe.tint = specular.unwrap_or(lobe.tint),
            Bsdf::RoughConductor { lobe, .. } => {
                lobe.tint = specular.unwrap_or(lobe.tint);
                rough(&mut lobe.microfacet);
            }
            Bsdf::RoughDielectric(lobe) => {
                lobe.reflectance = specular.unwrap_or(lobe.reflectance);
                rough(&mut lobe.microfacet);
            }
            Bsdf::ThinDielectric(lobe) => lobe.reflectance = specular.unwrap_or(lobe.reflectance),
            Bsdf::Principled { lobe, .. } => {
                if let Some(base) = diffuse {
                    lobe.base = base.to_array();
                }
                if let Some(r) = alpha_u {
                    lobe.set_roughness(r.clamp(0.0, 1.0));
                }
                if let Some(m) = read_1(t.metallic) {
                    lobe.metallic = m.clamp(0.0, 1.0);
                }
            }
            Bsdf::Glossy { .. } | Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => {}
        }
        bsdf
    }

    /// True when the roughness differs along u and v (a lobe that turns
    /// with the surface's tangent).
    pub fn is_anisotropic(&self) -> bool {
        let microfacet = match &self.bsdf {
            Bsdf::RoughConductor { lobe, .. } => lobe.microfacet,
            Bsdf::RoughDielectric(lobe) => lobe.microfacet,
            Bsdf::Principled { lobe, .. } => lobe.microfacet(),
            _ => return false,
        };
        microfacet.alpha_u != microfacet.alpha_v || self.textures.alpha != self.textures.alpha_v
    }

    /// True when the surface is a light source.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// The emission averaged over the texture (where one multiplies it),
    /// for what reads one value per surface: radiosity's elements.
    pub fn mean_emission(&self, textures: &[Texture]) -> Rgb {
        match self.emission_texture {
            Some(t) => self.emission * textures[t as usize].mean(),
            None => self.emission,
        }
    }

    /// Radiance emitted from a surface with geometric normal `n` towards
    /// `w`, before its texture ([`crate::scene::Scene::emitted`] reads it).
    #[inline]
    pub fn emitted(&self, n: Vec3A, w: Vec3A) -> Rgb {
        if self.two_sided_emission || n.dot(w) > 0.0 {
            self.emission
        } else {
            Rgb::ZERO
        }
    }
}
