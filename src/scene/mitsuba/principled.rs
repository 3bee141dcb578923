//! Mitsuba 3's `principled` onto [`crate::bsdf::Principled`]: its
//! parameters as it reads them (`specular` or `eta`, never both; every
//! other one in [0, 1]), `base_color`, `roughness` and `metallic` textured
//! at each hit, any other texture read as its mean with a warning.

use super::Importer;
use super::props::{Colour, Props};
use super::xml::Element;
use crate::bsdf::{Bsdf, Principled};
use crate::error::Result;
use crate::math::Rgb;
use crate::scene::description::{MaterialDesc, MaterialKind};
use crate::scene::material::{Material, MaterialTextures};

impl<'a> Importer<'a> {
    pub(super) fn principled(
        &mut self,
        e: &'a Element,
        p: &Props<'a>,
        name: &str,
        two_sided: bool,
    ) -> Result<Material> {
        let mut textures = MaterialTextures::default();
        let base_color = Rgb::from(self.principled_colour(p, &mut textures.diffuse)?);
        let scalar = |this: &mut Self, key: &str, default: f32, slot: Option<&mut Option<u32>>| {
            let value = match p.colour(key, false)? {
                None => default,
                Some(Colour::Value(c)) => c.x,
                Some(Colour::Texture(t)) => {
                    let id = this.texture(t)?;
                    let mean = this.textures[id as usize].mean().x;
                    match slot {
                        Some(slot) => *slot = Some(id),
                        None => this.warn(
                            &t.loc,
                            &format!("principled: textured {key} read as its mean {mean:.3}"),
                        ),
                    }
                    mean
                }
            };
            if !(0.0..=1.0).contains(&value) {
                return Err(e
                    .loc
                    .error(format!("principled {key} {value} is not in [0, 1]")));
            }
            Ok(value)
        };
        let roughness = scalar(self, "roughness", 0.5, Some(&mut textures.alpha))?;
        let metallic = scalar(self, "metallic", 0.0, Some(&mut textures.metallic))?;
        let anisotropic = scalar(self, "anisotropic", 0.0, None)?;
        let spec_trans = scalar(self, "spec_trans", 0.0, None)?;
        let spec_tint = scalar(self, "spec_tint", 0.0, None)?;
        let sheen = scalar(self, "sheen", 0.0, None)?;
        let sheen_tint = scalar(self, "sheen_tint", 0.0, None)?;
        let flatness = scalar(self, "flatness", 0.0, None)?;
        let clearcoat = scalar(self, "clearcoat", 0.0, None)?;
        let clearcoat_gloss = scalar(self, "clearcoat_gloss", 0.0, None)?;
        textures.alpha_v = textures.alpha;
        let eta = match (p.float("eta")?, p.float("specular")?) {
            (Some(_), Some(_)) => {
                return Err(e
                    .loc
                    .error("principled takes `eta` or `specular`, not both"));
            }
            (Some(eta), None) if eta > 0.0 && eta.is_finite() => eta,
            (Some(eta), None) => {
                return Err(e.loc.error(format!("principled eta {eta} is not positive")));
            }
            (None, specular) => {
                let specular = specular.unwrap_or(0.5);
                if !(0.0..=1.0).contains(&specular) {
                    return Err(e
                        .loc
                        .error(format!("principled specular {specular} is not in [0, 1]")));
                }
                // Burley's mapping of specular 0.5 to an IOR of 1.5 (F0 = 0.04).
                2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
            }
        };
        // η = 1 lets nothing be reflected, which transmission cannot have.
        let eta = if spec_trans > 0.0 && eta == 1.0 {
            1.001
        } else {
            eta
        };
        for rate in [
            "diffuse_reflectance_sampling_rate",
            "main_specular_sampling_rate",
            "clearcoat_sampling_rate",
        ] {
            // Sampling rates change noise, not the image.
            let _ = p.float(rate)?;
        }
        p.unused(&mut self.warnings);
        let lobe = Principled {
            base: base_color.to_array(),
            alpha: Principled::alphas(roughness, anisotropic),
            roughness,
            anisotropic,
            metallic,
            spec_trans,
            eta,
            spec_tint,
            sheen,
            sheen_tint,
            flatness,
            clearcoat,
            clearcoat_alpha: 0.1 + (0.001 - 0.1) * clearcoat_gloss,
        };
        // The material's other parts (name, emission, maps) as any other's.
        let shell = MaterialDesc {
            kind: MaterialKind::Diffuse,
            albedo: Some(base_color.to_array()),
            ..Default::default()
        };
        let mut m = self.built(name, shell, MaterialTextures::default(), Some(e))?;
        m.bsdf = Bsdf::Principled { lobe, two_sided };
        m.set_textures(textures);
        Ok(m)
    }

    /// `base_color` (0.5), a colour or a texture (its id in `slot`).
    fn principled_colour(&mut self, p: &Props<'a>, slot: &mut Option<u32>) -> Result<[f32; 3]> {
        match p.colour("base_color", false)? {
            None => Ok([0.5; 3]),
            Some(Colour::Value(c)) => Ok(c.to_array()),
            Some(Colour::Texture(t)) => {
                let id = self.texture(t)?;
                *slot = Some(id);
                Ok(self.textures[id as usize].mean().min(Rgb::ONE).to_array())
            }
        }
    }
}
