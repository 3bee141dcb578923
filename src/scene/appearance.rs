//! The parts of a scene file that describe appearance: materials (Mitsuba's
//! models and parameter names), textures and the environment, each checked
//! with a message that names the entry.

use super::description::*;
use super::environment::{Environment, Radiance as EnvRadiance};
use super::material::{Bsdf, Material, MaterialTextures};
use crate::bsdf::{
    Conductor, Distribution, Microfacet, Plastic, RoughConductor, RoughDielectric, RoughDiffuse,
    RoughPlastic, ThinDielectric, presets,
};
use crate::math::Rgb;
use crate::scene::material::Opacity;
use crate::texture::{Bitmap, Filter as TextureFilter, Texture, UvTransform, Wrap};
use glam::{EulerRot, Vec2};
use std::collections::HashMap;
use std::path::Path;

pub(super) fn build_environment(
    d: &EnvironmentDesc,
    dir: &Path,
) -> std::result::Result<Environment, String> {
    let scale = d.scale.unwrap_or(1.0);
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(format!(
            "environment: `scale` must be finite and >= 0, got {scale}"
        ));
    }
    let rotate = d.rotate.unwrap_or([0.0; 3]);
    if !rotate.iter().all(|x| x.is_finite()) {
        return Err(format!(
            "environment: `rotate` must be finite, got {rotate:?}"
        ));
    }
    let to_world = glam::Mat3A::from_euler(
        EulerRot::ZYX,
        rotate[2].to_radians(),
        rotate[1].to_radians(),
        rotate[0].to_radians(),
    );
    match d.kind.as_str() {
        "constant" => {
            if d.file.is_some() || d.rotate.is_some() {
                return Err("environment: a constant takes `radiance` and `scale` only".into());
            }
            let radiance = d.radiance.unwrap_or([1.0; 3]);
            if !radiance.iter().all(|x| x.is_finite() && *x >= 0.0) {
                return Err(format!(
                    "environment: `radiance` must be finite and >= 0, got {radiance:?}"
                ));
            }
            Ok(Environment::new(
                EnvRadiance::Constant(Rgb::from(radiance)),
                scale,
                to_world,
            ))
        }
        "envmap" => {
            if d.radiance.is_some() {
                return Err("environment: an envmap takes `file`, `scale` and `rotate`".into());
            }
            let file = d
                .file
                .as_ref()
                .ok_or("environment: an envmap needs `file`")?;
            let map =
                Bitmap::read(&dir.join(file), false).map_err(|e| format!("environment: {e}"))?;
            Ok(Environment::new(
                EnvRadiance::Map(std::sync::Arc::new(map)),
                scale,
                to_world,
            ))
        }
        other => Err(format!(
            "environment: `type` must be \"constant\" or \"envmap\", got \"{other}\""
        )),
    }
}

pub(super) fn build_texture(
    name: &str,
    d: &TextureDesc,
    dir: &Path,
) -> std::result::Result<Texture, String> {
    let pair = |field: &str, v: Option<[f32; 2]>, default: Vec2| match v {
        None => Ok(default),
        Some(p) if p.iter().all(|x| x.is_finite()) => Ok(Vec2::from(p)),
        Some(p) => Err(format!(
            "texture `{name}`: `{field}` must be finite, got {p:?}"
        )),
    };
    let to_uv = UvTransform {
        scale: pair("uv_scale", d.uv_scale, Vec2::ONE)?,
        offset: pair("uv_offset", d.uv_offset, Vec2::ZERO)?,
    };
    let colour = |field: &str, v: Option<[f32; 3]>, default: f32| match v {
        None => Ok(Rgb::splat(default)),
        Some(c) if c.iter().all(|x| x.is_finite() && *x >= 0.0) => Ok(Rgb::from(c)),
        Some(c) => Err(format!(
            "texture `{name}`: `{field}` must be finite and >= 0, got {c:?}"
        )),
    };
    let only = |allowed: &[&str]| -> std::result::Result<(), String> {
        let present = [
            ("file", d.file.is_some()),
            ("raw", d.raw.is_some()),
            ("wrap", d.wrap.is_some()),
            ("filter", d.filter.is_some()),
            ("color0", d.color0.is_some()),
            ("color1", d.color1.is_some()),
        ];
        match present.iter().find(|(f, p)| *p && !allowed.contains(f)) {
            Some((f, _)) => Err(format!(
                "texture `{name}`: field `{f}` does not apply to type {:?}",
                d.kind
            )),
            None => Ok(()),
        }
    };
    match d.kind {
        TextureKind::Checkerboard => {
            only(&["color0", "color1"])?;
            Ok(Texture::Checkerboard {
                color0: colour("color0", d.color0, 0.4)?,
                color1: colour("color1", d.color1, 0.2)?,
                to_uv,
            })
        }
        TextureKind::Bitmap => {
            only(&["file", "raw", "wrap", "filter"])?;
            let file = d
                .file
                .as_ref()
                .ok_or_else(|| format!("texture `{name}`: a bitmap needs `file`"))?;
            let wrap = match d.wrap.as_deref() {
                None | Some("repeat") => Wrap::Repeat,
                Some("mirror") => Wrap::Mirror,
                Some("clamp") => Wrap::Clamp,
                Some(w) => {
                    return Err(format!(
                        "texture `{name}`: `wrap` must be repeat, mirror or clamp, got \"{w}\""
                    ));
                }
            };
            let filter = match d.filter.as_deref() {
                None | Some("bilinear") => TextureFilter::Bilinear,
                Some("nearest") => TextureFilter::Nearest,
                Some(f) => {
                    return Err(format!(
                        "texture `{name}`: `filter` must be bilinear or nearest, got \"{f}\""
                    ));
                }
            };
            let image = Bitmap::read(&dir.join(file), d.raw.unwrap_or(false))
                .map_err(|e| format!("texture `{name}`: {e}"))?;
            Ok(Texture::Bitmap {
                image: std::sync::Arc::new(image),
                wrap,
                filter,
                to_uv,
            })
        }
    }
}

/// The texture slots of material `name`, each checked against its model.
pub(super) fn material_textures(
    name: &str,
    d: &MaterialDesc,
    ids: &HashMap<String, u32>,
) -> std::result::Result<MaterialTextures, String> {
    use MaterialKind as K;
    let id = |field: &str,
              v: &Option<String>,
              applies: bool|
     -> std::result::Result<Option<u32>, String> {
        let Some(t) = v else { return Ok(None) };
        if !applies {
            return Err(format!(
                "material `{name}`: `{field}` does not apply to type {:?}",
                d.kind
            ));
        }
        ids.get(t).copied().map(Some).ok_or_else(|| {
            let mut known: Vec<&String> = ids.keys().collect();
            known.sort();
            format!("material `{name}`: unknown texture `{t}` (defined: {known:?})")
        })
    };
    let plastic = matches!(d.kind, K::Plastic | K::RoughPlastic);
    let albedo = id(
        "albedo_texture",
        &d.albedo_texture,
        matches!(d.kind, K::Diffuse | K::RoughDiffuse),
    )?;
    let diffuse = id(
        "diffuse_reflectance_texture",
        &d.diffuse_reflectance_texture,
        plastic,
    )?;
    let specular = id(
        "specular_reflectance_texture",
        &d.specular_reflectance_texture,
        plastic
            || matches!(
                d.kind,
                K::Conductor | K::RoughConductor | K::ThinDielectric | K::RoughDielectric
            ),
    )?;
    let alpha = id(
        "alpha_texture",
        &d.alpha_texture,
        matches!(
            d.kind,
            K::RoughConductor | K::RoughDielectric | K::RoughPlastic
        ),
    )?;
    Ok(MaterialTextures {
        diffuse: albedo.or(diffuse),
        specular,
        alpha,
        alpha_v: alpha,
        metallic: None,
        coating: None,
    })
}

/// The opacity of material `name`: its texture's (a name in `ids`), its
/// constant, or opaque.
pub(super) fn material_opacity(
    name: &str,
    d: &MaterialDesc,
    ids: &HashMap<String, u32>,
) -> std::result::Result<Opacity, String> {
    match (&d.opacity_texture, d.opacity) {
        (Some(_), Some(_)) => Err(format!(
            "material `{name}`: give `opacity` or `opacity_texture`, not both"
        )),
        (Some(t), None) => ids.get(t).map(|&i| Opacity::Texture(i)).ok_or_else(|| {
            format!("material `{name}`: unknown texture `{t}` for `opacity_texture`")
        }),
        (None, Some(a)) if (0.0..=1.0).contains(&a) => Ok(if a == 1.0 {
            Opacity::Opaque
        } else {
            Opacity::Constant(a)
        }),
        (None, Some(a)) => Err(format!(
            "material `{name}`: `opacity` must be in [0, 1], got {a}"
        )),
        (None, None) => Ok(Opacity::Opaque),
    }
}

pub(super) fn build_material(
    name: &str,
    d: &MaterialDesc,
) -> std::result::Result<Material, String> {
    let colour = |field: &str,
                  v: Option<[f32; 3]>,
                  default: Rgb,
                  max: f32|
     -> std::result::Result<Rgb, String> {
        match v {
            None => Ok(default),
            Some(c) if c.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= max) => {
                Ok(Rgb::from(c))
            }
            Some(c) => Err(format!(
                "material `{name}`: `{field}` must be in [0, {max}], got {c:?}"
            )),
        }
    };
    use MaterialKind as K;
    const ROUGH: [&str; 4] = ["distribution", "alpha", "alpha_u", "alpha_v"];
    let allowed: Vec<&str> = match d.kind {
        K::Diffuse => vec!["albedo"],
        K::Glossy => vec!["albedo", "specular", "exponent"],
        K::Mirror => vec!["reflectance"],
        K::Dielectric => vec!["ior", "tint"],
        K::RoughDiffuse => vec!["albedo", "alpha", "twosided"],
        K::Conductor => vec!["conductor", "eta", "k", "specular_reflectance", "twosided"],
        K::RoughConductor => [
            &["conductor", "eta", "k", "specular_reflectance", "twosided"][..],
            &ROUGH,
        ]
        .concat(),
        K::ThinDielectric => vec![
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
        ],
        K::RoughDielectric => [
            &[
                "int_ior",
                "ext_ior",
                "specular_reflectance",
                "specular_transmittance",
            ][..],
            &ROUGH,
        ]
        .concat(),
        K::Plastic => vec![
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "specular_reflectance",
            "nonlinear",
            "twosided",
        ],
        K::RoughPlastic => vec![
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "specular_reflectance",
            "nonlinear",
            "twosided",
            "distribution",
            "alpha",
        ],
    };
    let present = [
        ("albedo", d.albedo.is_some()),
        ("specular", d.specular.is_some()),
        ("exponent", d.exponent.is_some()),
        ("reflectance", d.reflectance.is_some()),
        ("ior", d.ior.is_some()),
        ("tint", d.tint.is_some()),
        ("alpha", d.alpha.is_some()),
        ("alpha_u", d.alpha_u.is_some()),
        ("alpha_v", d.alpha_v.is_some()),
        ("distribution", d.distribution.is_some()),
        ("int_ior", d.int_ior.is_some()),
        ("ext_ior", d.ext_ior.is_some()),
        ("conductor", d.conductor.is_some()),
        ("eta", d.eta.is_some()),
        ("k", d.k.is_some()),
        ("specular_reflectance", d.specular_reflectance.is_some()),
        ("specular_transmittance", d.specular_transmittance.is_some()),
        ("diffuse_reflectance", d.diffuse_reflectance.is_some()),
        ("nonlinear", d.nonlinear.is_some()),
        ("twosided", d.twosided.is_some()),
    ];
    for (field, is_present) in present {
        if is_present && !allowed.contains(&field) {
            return Err(format!(
                "material `{name}`: field `{field}` does not apply to type {:?} (it takes {allowed:?})",
                d.kind
            ));
        }
    }
    let ior =
        |field: &str, v: &Option<IorDesc>, default: f32| -> std::result::Result<f32, String> {
            let value = match v {
                None => default,
                Some(IorDesc::Value(x)) => *x,
                Some(IorDesc::Name(n)) => presets::ior(n).ok_or_else(|| {
                    let names: Vec<&str> = presets::IORS.iter().map(|(n, _)| *n).collect();
                    format!(
                        "material `{name}`: `{field}` \"{n}\" is not a known IOR (known: {})",
                        names.join(", ")
                    )
                })?,
            };
            if value.is_finite() && value > 0.0 {
                Ok(value)
            } else {
                Err(format!(
                    "material `{name}`: `{field}` must be > 0, got {value}"
                ))
            }
        };
    // Interior over exterior; Mitsuba's defaults (BK7 glass, polypropylene
    // plastic, in air).
    let relative_ior = |default_int: f32| -> std::result::Result<f32, String> {
        Ok(ior("int_ior", &d.int_ior, default_int)? / ior("ext_ior", &d.ext_ior, 1.000277)?)
    };
    let roughness =
        |field: &str, v: Option<f32>, default: f32| -> std::result::Result<f32, String> {
            let a = v.unwrap_or(default);
            if a.is_finite() && a >= 0.0 {
                Ok(a)
            } else {
                Err(format!(
                    "material `{name}`: `{field}` must be >= 0, got {a}"
                ))
            }
        };
    let microfacet = || -> std::result::Result<Microfacet, String> {
        let alpha = roughness("alpha", d.alpha, 0.1)?;
        if d.alpha.is_some() && (d.alpha_u.is_some() || d.alpha_v.is_some()) {
            return Err(format!(
                "material `{name}`: give either `alpha` or `alpha_u` and `alpha_v`, not both"
            ));
        }
        Ok(Microfacet::new(
            d.distribution.unwrap_or(Distribution::Beckmann),
            roughness("alpha_u", d.alpha_u, alpha)?,
            roughness("alpha_v", d.alpha_v, alpha)?,
        ))
    };
    let conductor = || -> std::result::Result<(Rgb, Rgb, Rgb), String> {
        let tint = colour(
            "specular_reflectance",
            d.specular_reflectance,
            Rgb::ONE,
            1.0,
        )?;
        match (&d.conductor, d.eta, d.k) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(format!(
                "material `{name}`: give either `conductor` or `eta` and `k`, not both"
            )),
            (Some(n), None, None) => {
                let (eta, k) = presets::conductor(n).ok_or_else(|| {
                    let names: Vec<&str> = presets::CONDUCTORS.iter().map(|(n, _, _)| *n).collect();
                    format!(
                        "material `{name}`: conductor \"{n}\" is unknown (known: {})",
                        names.join(", ")
                    )
                })?;
                Ok((Rgb::from(eta), Rgb::from(k), tint))
            }
            // Mitsuba's default is "none", a perfect mirror (η 0, k 1).
            (None, eta, k) => Ok((
                colour("eta", eta, Rgb::ZERO, f32::MAX)?,
                colour("k", k, Rgb::ONE, f32::MAX)?,
                tint,
            )),
        }
    };
    // A dielectric's reflection and transmission tints.
    let tints = || -> std::result::Result<(Rgb, Rgb), String> {
        Ok((
            colour(
                "specular_reflectance",
                d.specular_reflectance,
                Rgb::ONE,
                1.0,
            )?,
            colour(
                "specular_transmittance",
                d.specular_transmittance,
                Rgb::ONE,
                1.0,
            )?,
        ))
    };
    let two_sided = d.twosided.unwrap_or(false);
    let bsdf = match d.kind {
        K::Diffuse => Bsdf::Diffuse {
            albedo: colour("albedo", d.albedo, Rgb::splat(0.8), 1.0)?,
        },
        K::Glossy => {
            let exponent = d.exponent.unwrap_or(50.0);
            if !(exponent.is_finite() && exponent >= 0.0) {
                return Err(format!(
                    "material `{name}`: `exponent` must be >= 0, got {exponent}"
                ));
            }
            Bsdf::glossy(
                colour("albedo", d.albedo, Rgb::splat(0.3), 1.0)?,
                colour("specular", d.specular, Rgb::splat(0.5), 1.0)?,
                exponent,
            )
        }
        K::Mirror => Bsdf::Mirror {
            reflectance: colour("reflectance", d.reflectance, Rgb::ONE, 1.0)?,
        },
        K::Dielectric => {
            let eta = d.ior.unwrap_or(1.5);
            if !(eta.is_finite() && eta > 0.0) {
                return Err(format!("material `{name}`: `ior` must be > 0, got {eta}"));
            }
            Bsdf::Dielectric {
                eta,
                tint: colour("tint", d.tint, Rgb::ONE, 1.0)?,
            }
        }
        K::RoughDiffuse => Bsdf::RoughDiffuse {
            lobe: RoughDiffuse {
                albedo: colour("albedo", d.albedo, Rgb::splat(0.5), 1.0)?,
                alpha: roughness("alpha", d.alpha, 0.2)?,
            },
            two_sided,
        },
        K::Conductor => {
            let (eta, k, tint) = conductor()?;
            Bsdf::Conductor {
                lobe: Conductor { eta, k, tint },
                two_sided,
            }
        }
        K::RoughConductor => {
            let (eta, k, tint) = conductor()?;
            Bsdf::RoughConductor {
                lobe: RoughConductor {
                    microfacet: microfacet()?,
                    eta,
                    k,
                    tint,
                },
                two_sided,
            }
        }
        K::ThinDielectric => {
            let (reflectance, transmittance) = tints()?;
            Bsdf::ThinDielectric(ThinDielectric {
                eta: relative_ior(1.5046)?,
                reflectance,
                transmittance,
            })
        }
        K::RoughDielectric => {
            let (reflectance, transmittance) = tints()?;
            Bsdf::RoughDielectric(RoughDielectric {
                microfacet: microfacet()?,
                eta: relative_ior(1.5046)?,
                reflectance,
                transmittance,
            })
        }
        K::Plastic | K::RoughPlastic => {
            let eta = relative_ior(1.49)?;
            let diffuse = colour(
                "diffuse_reflectance",
                d.diffuse_reflectance,
                Rgb::splat(0.5),
                1.0,
            )?;
            let specular = colour(
                "specular_reflectance",
                d.specular_reflectance,
                Rgb::ONE,
                1.0,
            )?;
            let nonlinear = d.nonlinear.unwrap_or(false);
            if d.kind == K::Plastic {
                Bsdf::Plastic {
                    lobe: Plastic::new(eta, diffuse, specular, nonlinear),
                    two_sided,
                }
            } else {
                let microfacet = microfacet()?;
                Bsdf::RoughPlastic {
                    lobe: RoughPlastic::new(microfacet, eta, diffuse, specular, nonlinear),
                    two_sided,
                }
            }
        }
    };
    Ok(Material {
        name: name.to_string(),
        bsdf,
        emission: colour("emission", d.emission, Rgb::ZERO, f32::MAX)?,
        two_sided_emission: d.two_sided.unwrap_or(false),
        emission_texture: None,
        textures: Default::default(),
        opacity: Default::default(),
        normal_map: None,
        blend: None,
    })
}
