//! Scene files: TOML in, a validated [`SceneInput`] out. Every error names the
//! scene file and the line of the entry at fault (or the OBJ/MTL file and line).

use super::description::*;
use super::environment::{Environment, Radiance as EnvRadiance};
use super::material::{Bsdf, Material, MaterialTextures};
use super::obj::load_obj;
use super::{Limits, MAX_COORDINATE, MovingInput, SceneInput, in_range};
use crate::accel::{NO_LIGHT, Sphere, TriangleInput};
use crate::bsdf::{
    Conductor, Distribution, Microfacet, Plastic, RoughConductor, RoughDielectric, RoughDiffuse,
    RoughPlastic, ThinDielectric, presets,
};
use crate::camera::Camera;
use crate::error::{Error, Result, line_of};
use crate::filter::PixelFilter;
use crate::math::Rgb;
use crate::scene::light::{Light, SpotCone};
use crate::texture::{Bitmap, Filter as TextureFilter, Texture, UvTransform, Wrap};
use glam::{EulerRot, Mat4, Quat, Vec2, Vec3, Vec3A};
use std::collections::HashMap;
use std::path::Path;
use toml::Spanned;

/// Reads a scene file and everything it references.
pub fn load_scene_file(path: &Path, limits: &Limits) -> Result<SceneInput> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::at(path, None, format!("cannot read scene file: {e}")))?;
    parse_scene(path, &text, limits)
}

/// Parses scene text; `path` locates referenced files and names errors.
pub fn parse_scene(path: &Path, text: &str, limits: &Limits) -> Result<SceneInput> {
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        Error::at(path, line, e.message())
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let at = |span: std::ops::Range<usize>, msg: String| {
        Error::at(path, Some(line_of(text, span.start)), msg)
    };

    let camera = build_camera(&file.camera, limits).map_err(|m| at(file.camera.span(), m))?;

    // Materials named in the scene file come first; MTL materials of the
    // same name are replaced by them.
    let mut textures = Vec::new();
    let mut texture_ids: HashMap<String, u32> = HashMap::new();
    for (name, desc) in &file.textures {
        let t = build_texture(name, desc.get_ref(), &dir).map_err(|m| at(desc.span(), m))?;
        texture_ids.insert(name.clone(), textures.len() as u32);
        textures.push(t);
    }
    let mut materials: Vec<Material> = Vec::new();
    let mut by_name: HashMap<String, u32> = HashMap::new();
    for (name, desc) in &file.materials {
        let mut m = build_material(name, desc.get_ref()).map_err(|m| at(desc.span(), m))?;
        m.textures = material_textures(name, desc.get_ref(), &texture_ids)
            .map_err(|m| at(desc.span(), m))?;
        by_name.insert(name.clone(), materials.len() as u32);
        materials.push(m);
    }
    let lookup = |name: &str, span: std::ops::Range<usize>, by_name: &HashMap<String, u32>| {
        by_name.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&String> = by_name.keys().collect();
            known.sort();
            at(
                span,
                format!("unknown material `{name}` (defined: {known:?})"),
            )
        })
    };

    let mut triangles: Vec<TriangleInput> = Vec::new();
    let mut spheres = Vec::new();
    let mut moving: Vec<MovingInput> = Vec::new();
    // Where an object's primitives go: the static lists, or a moving object
    // of its own. Lights may not move (their sampling assumes fixed positions).
    let motion_of = |velocity: [f32; 3],
                     span: std::ops::Range<usize>,
                     emissive: bool|
     -> Result<Option<Vec3A>> {
        let v = finite3("velocity", velocity).map_err(|m| at(span.clone(), m))?;
        if v == Vec3A::ZERO {
            return Ok(None);
        }
        if emissive {
            return Err(at(
                span,
                "`velocity`: emitters cannot move (light sampling assumes fixed lights)".into(),
            ));
        }
        Ok(Some(v))
    };
    for mesh in &file.mesh {
        let desc = mesh.get_ref();
        let obj_path = dir.join(&desc.file);
        if !obj_path.is_file() {
            return Err(at(
                mesh.span(),
                format!(
                    "mesh file `{}` not found (looked for {})",
                    desc.file,
                    obj_path.display()
                ),
            ));
        }
        let transform = mesh_transform(desc).map_err(|m| at(mesh.span(), m))?;
        let obj = load_obj(&obj_path)?;
        let override_id = match &desc.material {
            Some(name) => Some(lookup(name, mesh.span(), &by_name)?),
            None => None,
        };
        // Ids of this OBJ's MTL materials in the scene's table.
        let mut obj_ids = Vec::with_capacity(obj.materials.len());
        for m in obj.materials {
            let id = match by_name.get(&m.name) {
                Some(&id) => id,
                None => {
                    by_name.insert(m.name.clone(), materials.len() as u32);
                    materials.push(m);
                    materials.len() as u32 - 1
                }
            };
            obj_ids.push(id);
        }
        let mut default_id = None;
        let mut mesh_triangles = Vec::with_capacity(obj.triangles.len());
        // Normals transform by the inverse transpose.
        let normal_matrix = glam::Mat3A::from_mat4(transform).inverse().transpose();
        for t in obj.triangles {
            let (vertices, mtl) = (t.vertices, t.material);
            let material = match (override_id, mtl) {
                (Some(id), _) => id,
                (None, Some(i)) if i < obj_ids.len() => obj_ids[i],
                _ => *default_id.get_or_insert_with(|| {
                    materials.push(default_material());
                    materials.len() as u32 - 1
                }),
            };
            let vertices = vertices.map(|v| transform.transform_point3a(v));
            let normals = t
                .normals
                .filter(|_| !desc.face_normals)
                .map(|n| n.map(|n| (normal_matrix * n).normalize_or_zero()))
                .filter(|n| n.iter().all(|v| *v != Vec3A::ZERO && v.is_finite()));
            mesh_triangles.push(TriangleInput {
                vertices,
                material,
                uvs: t.uvs,
                normals,
            });
            if triangles.len() + mesh_triangles.len() > limits.max_triangles {
                return Err(at(
                    mesh.span(),
                    format!(
                        "more than {} triangles (raise the limit with --max-triangles)",
                        limits.max_triangles
                    ),
                ));
            }
        }
        if !mesh_triangles
            .iter()
            .all(|t| t.vertices.iter().all(|&v| in_range(v)))
        {
            return Err(at(
                mesh.span(),
                format!(
                    "mesh `{}`: after its transform, coordinates reach beyond ±{MAX_COORDINATE:e}",
                    desc.file
                ),
            ));
        }
        let emissive = mesh_triangles
            .iter()
            .any(|t| materials[t.material as usize].is_emissive());
        match motion_of(desc.velocity, mesh.span(), emissive)? {
            Some(velocity) => moving.push(MovingInput {
                triangles: mesh_triangles,
                spheres: Vec::new(),
                velocity,
            }),
            None => triangles.extend(mesh_triangles),
        }
    }

    for quad in &file.quad {
        let q = quad.get_ref();
        let material = lookup(&q.material, quad.span(), &by_name)?;
        let (c, u, v) = (Vec3A::from(q.corner), Vec3A::from(q.u), Vec3A::from(q.v));
        if !(in_range(c) && in_range(u) && in_range(v) && in_range(c + u + v)) {
            return Err(at(
                quad.span(),
                format!(
                    "quad: `corner`, `u` and `v` must be finite and within ±{MAX_COORDINATE:e}"
                ),
            ));
        }
        let halves = TriangleInput::quad(c, u, v, material);
        let emissive = materials[material as usize].is_emissive();
        match motion_of(q.velocity, quad.span(), emissive)? {
            Some(velocity) => moving.push(MovingInput {
                triangles: halves.to_vec(),
                spheres: Vec::new(),
                velocity,
            }),
            None => triangles.extend(halves),
        }
    }

    for sphere in &file.sphere {
        let s = sphere.get_ref();
        let material = lookup(&s.material, sphere.span(), &by_name)?;
        let center = Vec3A::from(s.center);
        if !in_range(center) || !(s.radius >= 0.0 && s.radius <= MAX_COORDINATE) {
            return Err(at(
                sphere.span(),
                format!(
                    "sphere: `center` must be finite and `radius` in [0, {MAX_COORDINATE:e}], got {}",
                    s.radius
                ),
            ));
        }
        let primitive = Sphere {
            center,
            radius: s.radius,
            material,
            light: NO_LIGHT,
        };
        let emissive = materials[material as usize].is_emissive();
        match motion_of(s.velocity, sphere.span(), emissive)? {
            Some(velocity) => moving.push(MovingInput {
                triangles: Vec::new(),
                spheres: vec![primitive],
                velocity,
            }),
            None => spheres.push(primitive),
        }
    }

    let mut point_lights = Vec::new();
    for light in &file.point_light {
        let l = light.get_ref();
        let position = Vec3A::from(l.position);
        let intensity = Rgb::from(l.intensity);
        if !position.is_finite() || !intensity.is_finite() || intensity.min_element() < 0.0 {
            return Err(at(
                light.span(),
                "point_light: `position` must be finite, `intensity` finite and >= 0".into(),
            ));
        }
        point_lights.push(Light::Point {
            position,
            intensity,
        });
    }

    for spot in &file.spot_light {
        let d = spot.get_ref();
        let bad = |m: String| at(spot.span(), format!("spot_light: {m}"));
        let (position, target) = (Vec3A::from(d.position), Vec3A::from(d.target));
        let axis = (target - position).normalize_or_zero();
        if !in_range(position) || axis == Vec3A::ZERO {
            return Err(bad(
                "`position` and `target` must be finite and distinct".into()
            ));
        }
        if !d.intensity.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(bad("`intensity` must be finite and >= 0".into()));
        }
        let cutoff = d.cutoff_angle.unwrap_or(20.0);
        let beam = d.beam_width.unwrap_or(0.75 * cutoff);
        if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
            return Err(bad(format!(
                "need 0 < cutoff_angle <= 90 and 0 <= beam_width <= cutoff_angle degrees, got {cutoff} and {beam}"
            )));
        }
        point_lights.push(Light::Spot {
            position,
            intensity: Rgb::from(d.intensity),
            cone: SpotCone {
                axis,
                cutoff: cutoff.to_radians(),
                beam_width: beam.to_radians(),
            },
        });
    }
    for light in &file.directional_light {
        let d = light.get_ref();
        let direction = Vec3A::from(d.direction).normalize_or_zero();
        if direction == Vec3A::ZERO || !direction.is_finite() {
            return Err(at(
                light.span(),
                "directional_light: `direction` must be a finite non-zero vector".into(),
            ));
        }
        if !d.irradiance.iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(at(
                light.span(),
                "directional_light: `irradiance` must be finite and >= 0".into(),
            ));
        }
        point_lights.push(Light::Directional {
            direction,
            irradiance: Rgb::from(d.irradiance),
            center: Vec3A::ZERO,
            radius: 1.0,
        });
    }
    let environment = match &file.environment {
        None => None,
        Some(e) => Some(build_environment(e.get_ref(), &dir).map_err(|m| at(e.span(), m))?),
    };
    Ok(SceneInput {
        environment,
        textures,
        camera,
        materials,
        triangles,
        spheres,
        point_lights,
        moving,
        sphere_sampling: file.lights.sphere_sampling,
        triangle_sampling: file.lights.triangle_sampling,
    })
}

fn finite3(name: &str, v: [f32; 3]) -> std::result::Result<Vec3A, String> {
    let v3 = Vec3A::from(v);
    if v3.is_finite() {
        Ok(v3)
    } else {
        Err(format!("`{name}` must be finite, got {v:?}"))
    }
}

fn build_camera(
    span: &Spanned<CameraDesc>,
    limits: &Limits,
) -> std::result::Result<Camera, String> {
    let c = span.get_ref();
    let eye = finite3("camera.eye", c.eye)?;
    let look_at = finite3("camera.look_at", c.look_at)?;
    let up = finite3("camera.up", c.up)?;
    if (look_at - eye).length_squared() == 0.0 {
        return Err("`camera.look_at` must differ from `camera.eye`".into());
    }
    if (look_at - eye)
        .normalize()
        .cross(up.normalize_or_zero())
        .length_squared()
        < 1e-12
    {
        return Err("`camera.up` must not be parallel to the view direction".into());
    }
    if !(c.fov_y > 0.0 && c.fov_y < 180.0) {
        return Err(format!(
            "`camera.fov_y` must be in (0, 180) degrees, got {}",
            c.fov_y
        ));
    }
    limits
        .check_resolution(c.width, c.height)
        .map_err(|e| format!("camera: {e}"))?;
    if !(c.aperture_radius.is_finite() && c.aperture_radius >= 0.0) {
        return Err(format!(
            "`camera.aperture_radius` must be >= 0, got {}",
            c.aperture_radius
        ));
    }
    let focus = c.focus_distance.unwrap_or((look_at - eye).length());
    if !(focus.is_finite() && focus > 0.0) {
        return Err(format!("`camera.focus_distance` must be > 0, got {focus}"));
    }
    let [open, close] = c.shutter;
    if !(open.is_finite() && close.is_finite() && close >= open) {
        return Err(format!(
            "`camera.shutter` must be [open, close] with finite open <= close, got {:?}",
            c.shutter
        ));
    }
    let positive = |name: &str, v: Option<f32>, default: f32| match v.unwrap_or(default) {
        x if x.is_finite() && x > 0.0 => Ok(x),
        x => Err(format!("`camera.{name}` must be > 0, got {x}")),
    };
    let filter = match c.filter.as_deref() {
        None | Some("box") => {
            if c.filter_radius.is_some() || c.filter_stddev.is_some() {
                return Err("the box filter takes no `filter_radius` or `filter_stddev`".into());
            }
            PixelFilter::Box
        }
        Some("tent") => {
            if c.filter_stddev.is_some() {
                return Err("the tent filter takes no `filter_stddev`".into());
            }
            PixelFilter::Tent {
                radius: positive("filter_radius", c.filter_radius, 1.0)?,
            }
        }
        Some("gaussian") => {
            let stddev = positive("filter_stddev", c.filter_stddev, 0.5)?;
            PixelFilter::Gaussian {
                stddev,
                radius: positive("filter_radius", c.filter_radius, 4.0 * stddev)?,
            }
        }
        Some(other) => {
            return Err(format!(
                "`camera.filter` must be \"box\", \"tent\" or \"gaussian\", got \"{other}\""
            ));
        }
    };
    Ok(Camera::look_at(
        eye,
        look_at,
        up,
        c.fov_y,
        c.width,
        c.height,
        c.aperture_radius,
        focus,
    )
    .with_shutter(open, close)
    .with_filter(filter))
}

fn mesh_transform(m: &MeshDesc) -> std::result::Result<Mat4, String> {
    let scale = match m.scale {
        Scale::Uniform(s) => Vec3::splat(s),
        Scale::PerAxis(s) => Vec3::from(s),
    };
    if !scale.is_finite() || scale.min_element().abs() == 0.0 {
        return Err(format!(
            "mesh `{}`: `scale` must be finite and non-zero",
            m.file
        ));
    }
    let rotate = Vec3::from(m.rotate);
    let translate = Vec3::from(m.translate);
    if !rotate.is_finite() || !translate.is_finite() {
        return Err(format!(
            "mesh `{}`: `rotate` and `translate` must be finite",
            m.file
        ));
    }
    // Rotation about x first, then y, then z.
    let rotation = Quat::from_euler(
        EulerRot::ZYX,
        rotate.z.to_radians(),
        rotate.y.to_radians(),
        rotate.x.to_radians(),
    );
    Ok(Mat4::from_scale_rotation_translation(
        scale, rotation, translate,
    ))
}

fn default_material() -> Material {
    Material {
        name: "default".into(),
        bsdf: Bsdf::Diffuse {
            albedo: Rgb::splat(0.8),
        },
        emission: Rgb::ZERO,
        two_sided_emission: false,
        textures: Default::default(),
    }
}

fn build_environment(d: &EnvironmentDesc, dir: &Path) -> std::result::Result<Environment, String> {
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

fn build_texture(name: &str, d: &TextureDesc, dir: &Path) -> std::result::Result<Texture, String> {
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
fn material_textures(
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
        matches!(d.kind, K::RoughConductor | K::RoughDielectric),
    )?;
    Ok(MaterialTextures {
        diffuse: albedo.or(diffuse),
        specular,
        alpha,
    })
}

fn build_material(name: &str, d: &MaterialDesc) -> std::result::Result<Material, String> {
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
        textures: Default::default(),
    })
}
