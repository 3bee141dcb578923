//! Mitsuba's BSDF and texture plugins onto tracelab's materials. The models
//! of [`crate::bsdf`] take Mitsuba's parameter names, so a plugin becomes a
//! [`MaterialDesc`] and goes through the same checks as a TOML material.

use super::props::{Colour, Props};
use super::xml::Element;
use super::{Emission, Importer};
use crate::bsdf::Distribution;
use crate::error::Result;
use crate::math::Rgb;
use crate::scene::appearance::build_material;
use crate::scene::description::{IorDesc, MaterialDesc, MaterialKind};
use crate::scene::material::{Blend, BlendWeight, Material, MaterialTextures, NormalMap, Opacity};
use crate::texture::{Bitmap, Filter, Texture, UvTransform, Wrap};
use glam::Vec2;
use std::collections::HashMap;
use std::sync::Arc;

impl<'a> Importer<'a> {
    /// The material of a shape: its BSDF plus an area emitter's radiance.
    pub(super) fn material(
        &mut self,
        bsdf: Option<&'a Element>,
        emission: Option<Emission>,
    ) -> Result<u32> {
        let key = bsdf.map_or(std::ptr::null(), |b| b as *const Element);
        if emission.is_none()
            && let Some(&id) = self.material_ids.get(&key)
        {
            return Ok(id);
        }
        let mut material = match bsdf {
            Some(b) => {
                let mut m = self.bsdf(b, false)?;
                // Named after the outermost element (a `twosided`'s id).
                if let Some(id) = b.attr("id") {
                    m.name = id.to_string();
                }
                m
            }
            // Mitsuba's default: a one-sided diffuse of reflectance 0.5, or
            // of 0 on an emitter (Mitsuba 3 and 0.6 alike: a lamp given no
            // BSDF reflects nothing).
            None => self.built(
                "default",
                MaterialDesc {
                    kind: MaterialKind::RoughDiffuse,
                    albedo: Some(if emission.is_some() {
                        [0.0; 3]
                    } else {
                        [0.5; 3]
                    }),
                    alpha: Some(0.0),
                    ..Default::default()
                },
                MaterialTextures::default(),
                None,
            )?,
        };
        if let Some(e) = emission {
            (material.emission, material.emission_texture) = (e.radiance, e.texture);
            material.name = format!("{} (emitter)", material.name);
            // A blend's second material emits too, from a copy of its own.
            if let Some(blend) = material.blend.as_mut() {
                let mut second = self.materials[blend.second as usize].clone();
                (second.emission, second.emission_texture) = (e.radiance, e.texture);
                second.name = format!("{} (emitter)", second.name);
                blend.second = self.materials.len() as u32;
                self.materials.push(second);
            }
        }
        let id = self.materials.len() as u32;
        self.materials.push(material);
        if emission.is_none() {
            self.material_ids.insert(key, id);
        }
        Ok(id)
    }

    pub(super) fn built(
        &mut self,
        name: &str,
        desc: MaterialDesc,
        textures: MaterialTextures,
        at: Option<&Element>,
    ) -> Result<Material> {
        let mut m = build_material(name, &desc).map_err(|m| match at {
            Some(e) => e.loc.error(m),
            None => crate::error::Error::new(m),
        })?;
        m.set_textures(textures);
        Ok(m)
    }

    /// One BSDF element; `two_sided` when a `twosided` wraps it.
    fn bsdf(&mut self, e: &'a Element, two_sided: bool) -> Result<Material> {
        let p = Props::new(e, self.ids);
        let name = e.attr("id").unwrap_or(e.plugin()).to_string();
        let kind = e.plugin();
        if kind == "twosided" {
            let nested = p.objects("bsdf")?;
            let Some(&front) = nested.first() else {
                return Err(e.loc.error("twosided needs a nested <bsdf>"));
            };
            if nested.len() > 1 {
                self.warn(
                    &e.loc,
                    "twosided with a different back BSDF: the front one is used on both sides",
                );
            }
            p.unused(&mut self.warnings);
            return self.bsdf(front, true);
        }
        if kind == "mask" {
            let nested = p.objects("bsdf")?;
            let Some(&inner) = nested.first() else {
                return Err(e.loc.error("mask needs a nested <bsdf>"));
            };
            let opacity = match p.colour("opacity", false)? {
                // Mitsuba's default.
                None => Opacity::Constant(0.5),
                Some(Colour::Value(c)) => match crate::math::luminance(c) {
                    a if a >= 1.0 => Opacity::Opaque,
                    a => Opacity::Constant(a.max(0.0)),
                },
                Some(Colour::Texture(t)) => Opacity::Texture(self.texture(t)?),
            };
            p.unused(&mut self.warnings);
            let mut m = self.bsdf(inner, two_sided)?;
            m.opacity = opacity;
            return Ok(m);
        }
        if kind == "normalmap" {
            let nested = p.objects("bsdf")?;
            let Some(&inner) = nested.first() else {
                return Err(e.loc.error("normalmap needs a nested <bsdf>"));
            };
            let texture = match p.colour("normalmap", false)? {
                Some(Colour::Texture(t)) => self.texture(t)?,
                _ => return Err(e.loc.error("normalmap needs a `normalmap` texture")),
            };
            p.unused(&mut self.warnings);
            self.warn_terminator(e, "normalmap");
            let mut m = self.bsdf(inner, two_sided)?;
            m.normal_map = Some(NormalMap::Tangent {
                texture,
                scale: 1.0,
            });
            self.map_blend_too(&m);
            return Ok(m);
        }
        if kind == "bumpmap" {
            let nested = p.objects("bsdf")?;
            let Some(&inner) = nested.first() else {
                return Err(e.loc.error("bumpmap needs a nested <bsdf>"));
            };
            let Some(&height) = p.any_objects("texture")?.first() else {
                return Err(e.loc.error("bumpmap needs a nested <texture>"));
            };
            let texture = self.texture(height)?;
            let scale = p.float_or("scale", 1.0)?;
            p.unused(&mut self.warnings);
            self.warn_terminator(e, "bumpmap");
            let mut m = self.bsdf(inner, two_sided)?;
            m.normal_map = Some(NormalMap::Bump { texture, scale });
            self.map_blend_too(&m);
            return Ok(m);
        }
        if kind == "blendbsdf" {
            return self.blend(e, &p, two_sided);
        }
        if kind == "principled" {
            return self.principled(e, &p, &name, two_sided);
        }
        let mut d = MaterialDesc {
            twosided: Some(two_sided),
            ..Default::default()
        };
        let mut textures = MaterialTextures::default();
        match kind {
            "diffuse" | "roughdiffuse" => {
                d.kind = match (kind, two_sided) {
                    // The Lambertian model is two-sided; one-sided diffuse is
                    // Oren–Nayar at zero roughness, which is Lambert exactly.
                    ("diffuse", true) => MaterialKind::Diffuse,
                    _ => MaterialKind::RoughDiffuse,
                };
                if d.kind == MaterialKind::Diffuse {
                    d.twosided = None;
                }
                let albedo = self.colour(&p, "reflectance", 0.5, &mut textures.diffuse)?;
                d.albedo = Some(albedo);
                if d.kind == MaterialKind::RoughDiffuse {
                    d.alpha = Some(p.float_or("alpha", 0.0)?);
                    if p.bool("use_fast_approx")? == Some(true) {
                        self.warn(
                            &e.loc,
                            "useFastApprox ignored: the full Oren–Nayar model is used",
                        );
                    }
                }
            }
            "conductor" | "roughconductor" => {
                d.kind = match kind {
                    "conductor" => MaterialKind::Conductor,
                    _ => MaterialKind::RoughConductor,
                };
                let material = p.string("material")?;
                d.conductor = material.filter(|m| *m != "none").map(String::from);
                d.eta = p.rgb("eta", false)?.map(|c| c.to_array());
                d.k = p.rgb("k", false)?.map(|c| c.to_array());
                // An explicit "none" is the mirror in every version.
                if material.is_none()
                    && d.eta.is_none()
                    && d.k.is_none()
                    && self.doc.major_version == 0
                {
                    d.conductor = Some("Cu".into()); // Mitsuba 0.6's default; 3's is a mirror
                }
                d.specular_reflectance =
                    Some(self.colour(&p, "specular_reflectance", 1.0, &mut textures.specular)?);
                if kind == "roughconductor" {
                    self.roughness(&p, &mut d, &mut textures)?;
                }
            }
            "dielectric" => {
                d.kind = MaterialKind::Dielectric;
                d.twosided = None;
                let int = ior(&p, "int_ior")?;
                let ext = ior(&p, "ext_ior")?;
                d.ior = Some(relative_ior(&e.loc, int, ext, 1.5046)?);
                if let Some(r) = p.rgb("specular_reflectance", false)?
                    && r != Rgb::ONE
                {
                    self.warn(
                        &e.loc,
                        "specular_reflectance of a smooth dielectric ignored (1)",
                    );
                }
                d.tint = p
                    .rgb("specular_transmittance", false)?
                    .map(|c| c.to_array());
            }
            "thindielectric" | "roughdielectric" => {
                d.kind = match kind {
                    "thindielectric" => MaterialKind::ThinDielectric,
                    _ => MaterialKind::RoughDielectric,
                };
                d.twosided = None;
                d.int_ior = ior(&p, "int_ior")?;
                d.ext_ior = ior(&p, "ext_ior")?;
                d.specular_reflectance =
                    Some(self.colour(&p, "specular_reflectance", 1.0, &mut textures.specular)?);
                d.specular_transmittance = p
                    .rgb("specular_transmittance", false)?
                    .map(|c| c.to_array());
                if kind == "roughdielectric" {
                    self.roughness(&p, &mut d, &mut textures)?;
                }
            }
            "plastic" | "roughplastic" => {
                d.kind = match kind {
                    "plastic" => MaterialKind::Plastic,
                    _ => MaterialKind::RoughPlastic,
                };
                d.int_ior = ior(&p, "int_ior")?;
                d.ext_ior = ior(&p, "ext_ior")?;
                d.diffuse_reflectance =
                    Some(self.colour(&p, "diffuse_reflectance", 0.5, &mut textures.diffuse)?);
                d.specular_reflectance =
                    Some(self.colour(&p, "specular_reflectance", 1.0, &mut textures.specular)?);
                d.nonlinear = p.bool("nonlinear")?;
                if kind == "roughplastic" {
                    self.roughness(&p, &mut d, &mut textures)?;
                    if d.alpha.is_none() {
                        return Err(e.loc.error("roughplastic is isotropic: give `alpha`"));
                    }
                }
            }
            "null" => {
                // Nothing there: every ray passes (an opacity of 0).
                d.kind = MaterialKind::Diffuse;
                d.twosided = None;
                d.albedo = Some([0.0; 3]);
                p.unused(&mut self.warnings);
                let mut m = self.built(&name, d, textures, Some(e))?;
                m.opacity = Opacity::Constant(0.0);
                return Ok(m);
            }
            other => {
                self.warn(
                    &e.loc,
                    &format!("BSDF \"{other}\" is not supported: rendered as diffuse 0.5"),
                );
                p.mark_all_used();
                d.kind = MaterialKind::Diffuse;
                d.twosided = None;
                d.albedo = Some([0.5; 3]);
            }
        }
        p.unused(&mut self.warnings);
        self.built(&name, d, textures, Some(e))
    }

    /// A colour parameter: its value, or its texture's id in `slot` (the
    /// value then is the texture's mean, for whatever reads one value).
    /// Mitsuba's `blendbsdf`: the first BSDF's material, blended with the
    /// second's (added to the scene's materials) by `weight`, a float or
    /// a texture's luminance in [0, 1].
    fn blend(&mut self, e: &'a Element, p: &Props<'a>, two_sided: bool) -> Result<Material> {
        let nested = p.objects("bsdf")?;
        let [first, second] = nested[..] else {
            return Err(e.loc.error(format!(
                "blendbsdf needs two nested <bsdf>, not {}",
                nested.len()
            )));
        };
        let weight = match p.colour("weight", false)? {
            None => BlendWeight::Constant(0.5),
            Some(Colour::Value(c)) => BlendWeight::Constant(crate::math::luminance(c)),
            Some(Colour::Texture(t)) => BlendWeight::Texture(self.texture(t)?),
        };
        if let BlendWeight::Constant(w) = weight
            && !(0.0..=1.0).contains(&w)
        {
            return Err(e
                .loc
                .error(format!("blendbsdf weight {w} is not in [0, 1]")));
        }
        p.unused(&mut self.warnings);
        let mut parts = [self.bsdf(first, two_sided)?, self.bsdf(second, two_sided)?];
        for (part, element) in parts.iter_mut().zip([first, second]) {
            // One level of blending is resolved at a hit.
            if part.blend.take().is_some() {
                self.warn(
                    &element.loc,
                    "a blendbsdf inside a blendbsdf: its first BSDF is used",
                );
            }
        }
        let [mut m, second] = parts;
        m.blend = Some(Blend {
            second: self.materials.len() as u32,
            weight,
        });
        self.materials.push(second);
        Ok(m)
    }

    /// A map around a `blendbsdf` tilts both of its BSDFs.
    fn map_blend_too(&mut self, m: &Material) {
        if let Some(blend) = m.blend {
            self.materials[blend.second as usize].normal_map = m.normal_map;
        }
    }

    /// Mitsuba 3's `normalmap` and `bumpmap` (not 0.6's) scale what
    /// arrives at a tilted normal by Estevez et al.'s (2019) terminator
    /// term, G1 of the light's direction against the untilted normal with
    /// α² = tan²(tilt) / 8 (measured on Mitsuba 3.9's `eval` to 5 digits).
    /// tracelab keeps the tilted normal alone, as pbrt-v4 does.
    fn warn_terminator(&mut self, e: &Element, kind: &str) {
        if self.doc.major_version == 0 {
            return;
        }
        let what = format!(
            "{kind}: Mitsuba 3's terminator term (Estevez et al. 2019) not applied: light \
             from grazing directions is brighter than in Mitsuba 3 where the map tilts \
             strongly (3.5% at 70° from a normal tilted 22°)"
        );
        self.warn(&e.loc, &what);
    }

    fn colour(
        &mut self,
        p: &Props<'a>,
        name: &str,
        default: f32,
        slot: &mut Option<u32>,
    ) -> Result<[f32; 3]> {
        match p.colour(name, false)? {
            None => Ok([default; 3]),
            Some(Colour::Value(c)) => Ok(c.to_array()),
            Some(Colour::Texture(t)) => {
                let id = self.texture(t)?;
                *slot = Some(id);
                Ok(self.textures[id as usize].mean().min(Rgb::ONE).to_array())
            }
        }
    }

    /// A microfacet model's distribution and roughness: `alpha`, or
    /// `alpha_u` and `alpha_v`, each a number or a texture (read at each
    /// hit; its mean stands for it where one value is read).
    fn roughness(
        &mut self,
        p: &Props<'a>,
        d: &mut MaterialDesc,
        textures: &mut MaterialTextures,
    ) -> Result<()> {
        d.distribution = Some(distribution(p)?);
        // Visible-normal sampling is always on: it changes noise, not the image.
        let _ = p.bool("sample_visible")?;
        let mut read = |name: &str, slot: &mut Option<u32>| -> Result<Option<f32>> {
            let texture = match p.tag_of(name) {
                Some("texture" | "ref") => p.colour(name, false)?,
                _ => None,
            };
            let Some(Colour::Texture(t)) = texture else {
                return p.float(name);
            };
            let id = self.texture(t)?;
            *slot = Some(id);
            Ok(Some(self.textures[id as usize].mean().x))
        };
        d.alpha_u = read("alpha_u", &mut textures.alpha)?;
        d.alpha_v = read("alpha_v", &mut textures.alpha_v)?;
        if d.alpha_u.is_none() && d.alpha_v.is_none() {
            d.alpha = Some(read("alpha", &mut textures.alpha)?.unwrap_or(0.1));
            textures.alpha_v = textures.alpha;
        }
        Ok(())
    }

    /// A texture plugin, loaded once however many materials read it.
    pub(super) fn texture(&mut self, e: &'a Element) -> Result<u32> {
        let key = e as *const Element;
        if let Some(&id) = self.texture_ids.get(&key) {
            return Ok(id);
        }
        let p = Props::new(e, self.ids);
        let to_uv = self.uv_transform(&p)?;
        let texture = match e.plugin() {
            "bitmap" => {
                let file = p
                    .string("filename")?
                    .ok_or_else(|| e.loc.error("a bitmap needs `filename`"))?;
                let path = self.doc.resolve(file, &e.loc)?;
                let wrap = match p.string("wrap_mode")? {
                    None | Some("repeat") => Wrap::Repeat,
                    Some("mirror") => Wrap::Mirror,
                    Some("clamp") => Wrap::Clamp,
                    Some(w) => {
                        self.warn(&e.loc, &format!("wrap_mode \"{w}\" read as repeat"));
                        Wrap::Repeat
                    }
                };
                let filter = match p.string("filter_type")? {
                    None | Some("bilinear") => Filter::Bilinear,
                    Some("nearest") => Filter::Nearest,
                    Some(f) => {
                        self.warn(&e.loc, &format!("filter type {f} read as bilinear"));
                        Filter::Bilinear
                    }
                };
                let raw = p.bool("raw")?.unwrap_or(false);
                if let Some(g) = p.float("gamma")? {
                    self.warn(
                        &e.loc,
                        &format!("gamma {g} ignored: 8-bit images are read as sRGB"),
                    );
                }
                let image = match self.prefetched.bitmap(&path, raw) {
                    Some(image) => image,
                    None => Arc::new(Bitmap::read(&path, raw).map_err(|m| e.loc.error(m))?),
                };
                Texture::Bitmap {
                    image,
                    wrap,
                    filter,
                    to_uv,
                }
            }
            "checkerboard" => {
                let colour = |name: &str, default: f32| -> Result<Rgb> {
                    Ok(p.rgb(name, false)?.unwrap_or(Rgb::splat(default)))
                };
                Texture::Checkerboard {
                    color0: colour("color0", 0.4)?,
                    color1: colour("color1", 0.2)?,
                    to_uv,
                }
            }
            other => {
                self.warn(
                    &e.loc,
                    &format!("texture \"{other}\" is not supported: a constant 0.5 is used"),
                );
                p.mark_all_used();
                Texture::Checkerboard {
                    color0: Rgb::splat(0.5),
                    color1: Rgb::splat(0.5),
                    to_uv,
                }
            }
        };
        p.unused(&mut self.warnings);
        let id = self.textures.len() as u32;
        self.textures.push(texture);
        self.texture_ids.insert(key, id);
        Ok(id)
    }

    /// Mitsuba 3's `to_uv`, or 0.6's `uscale`, `vscale`, `uoffset`, `voffset`.
    fn uv_transform(&mut self, p: &Props) -> Result<UvTransform> {
        let mut t = UvTransform::default();
        if let Some(m) = p.transform("to_uv")? {
            t.scale = Vec2::new(m.x_axis.x, m.y_axis.y);
            t.offset = Vec2::new(m.w_axis.x, m.w_axis.y);
            if m.x_axis.y != 0.0 || m.y_axis.x != 0.0 {
                self.warn(
                    p.loc(),
                    "to_uv: rotation or shear ignored (scale and offset kept)",
                );
            }
        }
        for (name, value) in [
            ("uscale", &mut t.scale.x),
            ("vscale", &mut t.scale.y),
            ("uoffset", &mut t.offset.x),
            ("voffset", &mut t.offset.y),
        ] {
            if let Some(v) = p.float(name)? {
                *value = v;
            }
        }
        Ok(t)
    }
}

/// An IOR property: a number, or a name of Mitsuba's table.
fn ior(p: &Props, name: &str) -> Result<Option<IorDesc>> {
    if p.tag_of(name) == Some("string") {
        return Ok(p.string(name)?.map(|s| IorDesc::Name(s.to_string())));
    }
    Ok(p.float(name)?.map(IorDesc::Value))
}

/// A microfacet model's `distribution`, Beckmann unless given.
fn distribution(p: &Props) -> Result<Distribution> {
    match p.string("distribution")? {
        None | Some("beckmann") => Ok(Distribution::Beckmann),
        Some("ggx") => Ok(Distribution::Ggx),
        Some(other) => Err(p
            .loc()
            .error(format!("distribution \"{other}\" is not beckmann or ggx"))),
    }
}

/// What a `roughplastic` element's coating tables are made from, read as
/// [`Importer::bsdf`] reads it, where its roughness is one `alpha` number:
/// the tables take 64 × 2 integrals, and made ahead on any core
/// (prefetching) they no longer wait on the walk's one thread. None where
/// anything else decides them, or the element is wrong (the walk then
/// says so).
pub(super) fn coating(e: &Element, ids: &HashMap<String, &Element>) -> Option<MaterialDesc> {
    let p = Props::new(e, ids);
    if p.float("alpha_u").ok()?.is_some() || p.float("alpha_v").ok()?.is_some() {
        return None;
    }
    Some(MaterialDesc {
        kind: MaterialKind::RoughPlastic,
        distribution: Some(distribution(&p).ok()?),
        alpha: Some(p.float("alpha").ok()?.unwrap_or(0.1)),
        int_ior: ior(&p, "int_ior").ok()?,
        ext_ior: ior(&p, "ext_ior").ok()?,
        ..Default::default()
    })
}

/// Interior over exterior IOR, names or numbers, Mitsuba's defaults.
fn relative_ior(
    loc: &super::xml::Loc,
    int: Option<IorDesc>,
    ext: Option<IorDesc>,
    default_int: f32,
) -> Result<f32> {
    let value = |d: Option<IorDesc>, default: f32| -> Result<f32> {
        match d {
            None => Ok(default),
            Some(IorDesc::Value(v)) if v > 0.0 => Ok(v),
            Some(IorDesc::Value(v)) => Err(loc.error(format!("an IOR must be > 0, got {v}"))),
            Some(IorDesc::Name(n)) => crate::bsdf::presets::ior(&n)
                .ok_or_else(|| loc.error(format!("\"{n}\" is not a known IOR"))),
        }
    };
    Ok(value(int, default_int)? / value(ext, 1.000277)?)
}
