//! Scene files: TOML in, a validated [`SceneInput`] out. Every error names the
//! scene file and the line of the entry at fault (or the OBJ/MTL file and line).

use super::appearance::{
    build_environment, build_material, build_texture, material_opacity, material_textures,
};
use super::description::*;
use super::material::{Bsdf, Material, NormalMap};
use super::obj::load_obj;
use super::{Limits, LoadOptions, MAX_COORDINATE, MovingInput, SceneInput, in_range};
use crate::accel::{NO_LIGHT, Sphere, TriangleInput};
use crate::camera::Camera;
use crate::error::{Error, Result, line_of};
use crate::filter::PixelFilter;
use crate::math::Rgb;
use crate::scene::light::{Light, SpotCone};
use glam::{EulerRot, Mat4, Quat, Vec3, Vec3A};
use std::collections::HashMap;
use std::path::Path;
use toml::Spanned;

/// Reads a scene of any format the loader knows, by its extension: tracelab
/// TOML, Mitsuba XML, glTF 2.0, or a bare OBJ or PLY mesh (framed by a default camera
/// and lit by a constant environment).
pub fn load_any(path: &Path, options: &LoadOptions) -> Result<SceneInput> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let not_toml = |what: &str| {
        if !options.defines.is_empty() {
            return Err(Error::at(
                path,
                None,
                format!("-D applies to Mitsuba XML files, not {what}"),
            ));
        }
        Ok(())
    };
    match extension.as_deref() {
        Some("xml") => super::mitsuba::load_mitsuba(path, options),
        Some("obj" | "ply") => {
            not_toml("meshes")?;
            super::framing::bare_mesh(path, &options.limits)
        }
        Some("gltf" | "glb") => {
            not_toml("glTF files")?;
            super::gltf::load_gltf(path, options)
        }
        _ => {
            not_toml("TOML scenes")?;
            load_scene_file(path, &options.limits)
        }
    }
}

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
        m.set_textures(
            material_textures(name, desc.get_ref(), &texture_ids)
                .map_err(|m| at(desc.span(), m))?,
        );
        m.opacity =
            material_opacity(name, desc.get_ref(), &texture_ids).map_err(|m| at(desc.span(), m))?;
        m.normal_map =
            normal_map(name, desc.get_ref(), &texture_ids).map_err(|m| at(desc.span(), m))?;
        if let Some(t) = &desc.get_ref().emission_texture {
            m.emission_texture = Some(*texture_ids.get(t).ok_or_else(|| {
                at(
                    desc.span(),
                    format!("material `{name}`: unknown texture `{t}` for `emission_texture`"),
                )
            })?);
            if desc.get_ref().emission.is_none() {
                m.emission = crate::math::Rgb::ONE;
            }
        }
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
    let mut warnings = Vec::new();
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
        if obj.triangles.is_empty() {
            warnings.push(format!(
                "{}:{}: mesh file `{}` holds no triangles: it adds nothing",
                path.display(),
                line_of(text, mesh.span().start),
                desc.file
            ));
        }
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
        if let Some(angle) = desc.smooth_angle {
            if !(angle.is_finite() && (0.0..=180.0).contains(&angle)) || desc.face_normals {
                return Err(at(
                    mesh.span(),
                    format!(
                        "mesh `{}`: `smooth_angle` must be in [0, 180] degrees and not with `face_normals`, got {angle}",
                        desc.file
                    ),
                ));
            }
            super::mesh::smooth_by_angle(&mut mesh_triangles, angle);
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
        let emissive = materials[material as usize].is_emissive();
        if let Some(wanted) = s.triangles {
            // About 4 rings² triangles with twice as many segments as rings.
            let rings = ((wanted as f64 / 4.0).sqrt().ceil() as u32).max(2);
            let count = 4 * rings as usize * rings as usize;
            if wanted == 0 || triangles.len() + count > limits.max_triangles {
                return Err(at(
                    sphere.span(),
                    format!(
                        "sphere: `triangles` must be in 1..={} (--max-triangles), got {wanted}",
                        limits.max_triangles.saturating_sub(triangles.len())
                    ),
                ));
            }
            let mesh = crate::scene::mesh::uv_sphere(center, s.radius, rings, 2 * rings)
                .into_iter()
                .map(|vertices| TriangleInput {
                    vertices,
                    material,
                    uvs: None,
                    normals: None,
                });
            match motion_of(s.velocity, sphere.span(), emissive)? {
                Some(velocity) => moving.push(MovingInput {
                    triangles: mesh.collect(),
                    spheres: Vec::new(),
                    velocity,
                }),
                None => triangles.extend(mesh),
            }
            continue;
        }
        let primitive = Sphere {
            center,
            radius: s.radius,
            material,
            light: NO_LIGHT,
        };
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
        instances: Default::default(),
        sphere_sampling: file.lights.sphere_sampling,
        triangle_sampling: file.lights.triangle_sampling,
        warnings,
        hints: Default::default(),
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

/// Grey diffuse, for meshes that name no material.
pub(super) fn default_material() -> Material {
    Material {
        name: "default".into(),
        bsdf: Bsdf::Diffuse {
            albedo: Rgb::splat(0.8),
        },
        emission: Rgb::ZERO,
        two_sided_emission: false,
        emission_texture: None,
        textures: Default::default(),
        opacity: Default::default(),
        normal_map: None,
        blend: None,
    }
}

/// The normal or bump map of material `name`, its textures named in `ids`.
fn normal_map(
    name: &str,
    d: &MaterialDesc,
    ids: &HashMap<String, u32>,
) -> std::result::Result<Option<NormalMap>, String> {
    let id = |field: &str, t: &String| {
        ids.get(t)
            .copied()
            .ok_or_else(|| format!("material `{name}`: unknown texture `{t}` for `{field}`"))
    };
    match (&d.normal_map_texture, &d.bump_map_texture) {
        (Some(_), Some(_)) => Err(format!(
            "material `{name}`: give `normal_map_texture` or `bump_map_texture`, not both"
        )),
        (Some(t), None) => Ok(Some(NormalMap::Tangent {
            texture: id("normal_map_texture", t)?,
            scale: 1.0,
        })),
        (None, Some(t)) => match d.bump_scale.unwrap_or(1.0) {
            scale if scale.is_finite() => Ok(Some(NormalMap::Bump {
                texture: id("bump_map_texture", t)?,
                scale,
            })),
            scale => Err(format!(
                "material `{name}`: `bump_scale` must be finite, got {scale}"
            )),
        },
        (None, None) if d.bump_scale.is_some() => Err(format!(
            "material `{name}`: `bump_scale` without `bump_map_texture`"
        )),
        (None, None) => Ok(None),
    }
}
