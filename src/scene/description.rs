//! The scene file format: plain serde structs mirroring the TOML, with spans
//! kept on every entry so that errors found after parsing can name the line.
//!
//! ```toml
//! [camera]
//! eye = [278, 273, -800]
//! look_at = [278, 273, 0]
//! up = [0, 1, 0]           # default
//! fov_y = 39.3             # degrees, vertical
//! width = 256
//! height = 256
//! aperture_radius = 0.0    # thin lens; 0 = pinhole
//! focus_distance = 800     # default: distance from eye to look_at
//! shutter = [0, 1]         # exposure interval; default [0, 0] (instantaneous)
//!
//! [[mesh]]
//! file = "cornell_box.obj" # relative to this file; materials from its MTL
//! scale = 1.0              # or [sx, sy, sz]
//! rotate = [0, 30, 0]      # degrees about x, then y, then z
//! translate = [0, 0, 0]
//! material = "glass"       # optional: override every face's material
//! velocity = [0, 0, 0]     # motion per unit time (meshes, spheres, quads; not emitters)
//! smooth_angle = 30        # no `vn` in the file: smooth normals across edges below 30 degrees
//!
//! [[sphere]]
//! center = [0, 1, 0]
//! radius = 0.5
//! material = "glass"
//! triangles = 100000       # optional: a UV sphere mesh of about this many triangles
//!
//! [[quad]]                 # corner + s u + t v, s, t in [0, 1]; normal u x v
//! corner = [0, 0, 0]
//! u = [1, 0, 0]
//! v = [0, 0, 1]
//! material = "white"
//!
//! [[point_light]]
//! position = [0, 5, 0]
//! intensity = [10, 10, 10] # W/sr
//!
//! [materials.glass]        # defines a material, or overrides an MTL one of the same name
//! type = "dielectric"      # diffuse | glossy | mirror | dielectric
//! ior = 1.5
//!
//! [lights]
//! sphere_sampling = "solid-angle"   # or "area" (default solid-angle)
//! triangle_sampling = "area"        # or "solid-angle" (default area, as Mitsuba)
//! ```

use crate::scene::light::LightSampling;
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub camera: Spanned<CameraDesc>,
    #[serde(default)]
    pub mesh: Vec<Spanned<MeshDesc>>,
    #[serde(default)]
    pub sphere: Vec<Spanned<SphereDesc>>,
    #[serde(default)]
    pub quad: Vec<Spanned<QuadDesc>>,
    #[serde(default)]
    pub point_light: Vec<Spanned<PointLightDesc>>,
    #[serde(default)]
    pub spot_light: Vec<Spanned<SpotLightDesc>>,
    #[serde(default)]
    pub directional_light: Vec<Spanned<DirectionalLightDesc>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDesc>>,
    #[serde(default)]
    pub textures: BTreeMap<String, Spanned<TextureDesc>>,
    pub environment: Option<Spanned<EnvironmentDesc>>,
    #[serde(default)]
    pub lights: LightOptions,
}

/// `[textures.NAME]`: Mitsuba's `bitmap` and `checkerboard`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDesc {
    #[serde(rename = "type")]
    pub kind: TextureKind,
    /// bitmap: an image file (PNG, JPEG, TGA, EXR, HDR), relative to the scene.
    pub file: Option<String>,
    /// bitmap: read 8-bit values as data, without sRGB decoding.
    pub raw: Option<bool>,
    /// bitmap: "repeat" (default), "mirror" or "clamp".
    pub wrap: Option<String>,
    /// bitmap: "bilinear" (default) or "nearest".
    pub filter: Option<String>,
    /// checkerboard: the two colours (Mitsuba: 0.4 and 0.2).
    pub color0: Option<[f32; 3]>,
    pub color1: Option<[f32; 3]>,
    /// uv · uv_scale + uv_offset (Mitsuba's `to_uv`).
    pub uv_scale: Option<[f32; 2]>,
    pub uv_offset: Option<[f32; 2]>,
}

/// `[[spot_light]]`: Mitsuba's `spot`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpotLightDesc {
    pub position: [f32; 3],
    /// The point the spot aims at.
    pub target: [f32; 3],
    pub intensity: [f32; 3],
    /// Degrees from the axis where the light ends (Mitsuba: 20).
    pub cutoff_angle: Option<f32>,
    /// Degrees from the axis of full intensity (Mitsuba: 3/4 of the cutoff).
    pub beam_width: Option<f32>,
}

/// `[[directional_light]]`: Mitsuba's `directional`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightDesc {
    /// The direction the light travels in.
    pub direction: [f32; 3],
    pub irradiance: [f32; 3],
}

/// `[environment]`: light from infinity (Mitsuba's `constant` and `envmap`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// "constant" or "envmap".
    #[serde(rename = "type")]
    pub kind: String,
    /// constant: the radiance from every direction (Mitsuba: 1).
    pub radiance: Option<[f32; 3]>,
    /// envmap: a lat-long image (EXR, HDR, PFM or any bitmap), relative to the scene.
    pub file: Option<String>,
    /// envmap: a factor on the map (Mitsuba's `scale`).
    pub scale: Option<f32>,
    /// envmap: rotation to world, degrees about x, y, z (applied z, y, x).
    pub rotate: Option<[f32; 3]>,
}

/// Kinds of texture.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum TextureKind {
    Bitmap,
    Checkerboard,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub eye: [f32; 3],
    pub look_at: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
    #[serde(default)]
    pub aperture_radius: f32,
    pub focus_distance: Option<f32>,
    #[serde(default)]
    pub shutter: [f32; 2],
    /// Pixel filter: "box" (default), "tent" or "gaussian" (Mitsuba's).
    pub filter: Option<String>,
    /// Tent and Gaussian: radius in pixels (Mitsuba: 1 and 4 stddev).
    pub filter_radius: Option<f32>,
    /// Gaussian: standard deviation in pixels (Mitsuba: 0.5).
    pub filter_stddev: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// A uniform or per-axis scale.
#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f32),
    PerAxis([f32; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

/// `[[mesh]]`: an OBJ file with a transform.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    pub file: String,
    #[serde(default)]
    pub scale: Scale,
    #[serde(default)]
    pub rotate: [f32; 3],
    #[serde(default)]
    pub translate: [f32; 3],
    pub material: Option<String>,
    #[serde(default)]
    pub velocity: [f32; 3],
    /// Shade flat, ignoring the file's `vn` normals (Mitsuba's `face_normals`).
    #[serde(default)]
    pub face_normals: bool,
    /// Where the file has no `vn` normals: smooth ones, across edges whose
    /// faces meet within this many degrees (Blender's auto smooth).
    pub smooth_angle: Option<f32>,
}

/// `[[sphere]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDesc {
    pub center: [f32; 3],
    pub radius: f32,
    pub material: String,
    /// A UV sphere mesh of about this many triangles (flat shaded) in
    /// place of the exact sphere: what radiosity, which meshes triangles,
    /// can solve, and a large mesh for tests and benches.
    pub triangles: Option<u32>,
    #[serde(default)]
    pub velocity: [f32; 3],
}

/// `[[quad]]`: the parallelogram `corner + s u + t v`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadDesc {
    pub corner: [f32; 3],
    pub u: [f32; 3],
    pub v: [f32; 3],
    pub material: String,
    #[serde(default)]
    pub velocity: [f32; 3],
}

/// `[[point_light]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightDesc {
    pub position: [f32; 3],
    pub intensity: [f32; 3],
}

/// Kinds of material in `[materials.NAME]`.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    #[default]
    Diffuse,
    Glossy,
    Mirror,
    Dielectric,
    /// Oren–Nayar (Mitsuba 0.6's `roughdiffuse`).
    RoughDiffuse,
    Conductor,
    RoughConductor,
    ThinDielectric,
    RoughDielectric,
    Plastic,
    RoughPlastic,
}

/// An index of refraction: a number, or a name of Mitsuba's table ("bk7").
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(untagged)]
pub enum IorDesc {
    Value(f32),
    Name(String),
}

/// `[materials.NAME]`. Which fields apply depends on `type`; the loader
/// rejects the others so that a typo never goes unnoticed.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    #[serde(rename = "type")]
    pub kind: MaterialKind,
    /// diffuse, glossy: diffuse albedo.
    pub albedo: Option<[f32; 3]>,
    /// glossy: Phong lobe albedo.
    pub specular: Option<[f32; 3]>,
    /// glossy: Phong exponent.
    pub exponent: Option<f32>,
    /// mirror: reflectance.
    pub reflectance: Option<[f32; 3]>,
    /// dielectric: interior / exterior index of refraction.
    pub ior: Option<f32>,
    /// dielectric: transmittance tint.
    pub tint: Option<[f32; 3]>,
    /// Models added for real scenes take Mitsuba's parameter names:
    /// roughdiffuse: RMS slope; rough*: isotropic roughness α.
    pub alpha: Option<f32>,
    /// roughconductor, roughdielectric: anisotropic roughness.
    pub alpha_u: Option<f32>,
    pub alpha_v: Option<f32>,
    /// rough*: "beckmann" (Mitsuba's default) or "ggx".
    pub distribution: Option<crate::bsdf::Distribution>,
    /// Dielectrics and plastics: interior and exterior IOR.
    pub int_ior: Option<IorDesc>,
    pub ext_ior: Option<IorDesc>,
    /// Conductors: a named material ("Au", "Cu", ...), or `eta` and `k`.
    pub conductor: Option<String>,
    pub eta: Option<[f32; 3]>,
    pub k: Option<[f32; 3]>,
    pub specular_reflectance: Option<[f32; 3]>,
    pub specular_transmittance: Option<[f32; 3]>,
    /// Plastics: the base's albedo.
    pub diffuse_reflectance: Option<[f32; 3]>,
    /// Plastics: internal scattering darkens and saturates the base.
    pub nonlinear: Option<bool>,
    /// One-sided models (everything but diffuse, glossy, mirror and the
    /// dielectrics) give their back the front's response (Mitsuba's
    /// `twosided`); by default they are black seen from behind.
    pub twosided: Option<bool>,
    /// Textures (names in `[textures]`) for the diffuse colour (`albedo`
    /// or `diffuse_reflectance`), the specular tint and the roughness.
    pub albedo_texture: Option<String>,
    pub diffuse_reflectance_texture: Option<String>,
    pub specular_reflectance_texture: Option<String>,
    pub alpha_texture: Option<String>,
    /// Mitsuba's `mask`: the fraction of the surface that is there, in
    /// [0, 1], or a texture's luminance (any type; not on emitters).
    pub opacity: Option<f32>,
    pub opacity_texture: Option<String>,
    /// A tangent-space normal map (a texture name; declare it `raw`).
    pub normal_map_texture: Option<String>,
    /// A bump map: a height texture's name and the height's scale (1).
    pub bump_map_texture: Option<String>,
    pub bump_scale: Option<f32>,
    /// Emitted radiance (any type).
    pub emission: Option<[f32; 3]>,
    /// A texture (a name in `[textures]`) that multiplies `emission`
    /// (which is then 1 unless given).
    pub emission_texture: Option<String>,
    /// Emit from both sides (any type).
    pub two_sided: Option<bool>,
}

/// `[lights]`: how lights are sampled.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightOptions {
    #[serde(default)]
    pub sphere_sampling: LightSampling,
    #[serde(default = "area")]
    pub triangle_sampling: LightSampling,
}

fn area() -> LightSampling {
    LightSampling::Area
}

impl Default for LightOptions {
    fn default() -> Self {
        LightOptions {
            sphere_sampling: LightSampling::SolidAngle,
            triangle_sampling: LightSampling::Area,
        }
    }
}
