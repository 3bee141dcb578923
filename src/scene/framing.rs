//! A camera and light for scenes that bring none: bare meshes, and Mitsuba
//! files without a sensor.

use super::environment::{Environment, Radiance};
use super::mesh::Orientation;
use super::{Limits, SceneInput};
use crate::accel::{Sphere, TriangleInput};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::math::Rgb;
use crate::scene::light::LightSampling;
use glam::{Mat3A, Mat4, Vec3A};
use rayon::prelude::*;
use std::path::Path;

/// Looks at the bounding box from the front (+z, y up), all of it in view.
/// Instances count by their placed boxes.
pub fn default_camera(
    triangles: &[TriangleInput],
    spheres: &[Sphere],
    instances: &super::InstancesInput,
) -> Camera {
    let (lo, hi) =
        bounds(triangles, spheres, instances).unwrap_or((Vec3A::splat(-1.0), Vec3A::ONE));
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let fov_y: f32 = 40.0;
    let distance = radius / (0.5 * fov_y.to_radians()).sin();
    let eye = center + Vec3A::new(0.0, 0.3, 1.0).normalize() * distance;
    Camera::look_at(eye, center, Vec3A::Y, fov_y, 512, 512, 0.0, distance)
}

/// The box around the triangles, the spheres and the instances' placed
/// boxes; None for an empty scene.
pub fn bounds(
    triangles: &[TriangleInput],
    spheres: &[Sphere],
    instances: &super::InstancesInput,
) -> Option<(Vec3A, Vec3A)> {
    let empty = || (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY));
    let (mut lo, mut hi) = (triangles.par_iter().with_min_len(1 << 12))
        .fold(empty, |(lo, hi), t| {
            let [a, b, c] = t.vertices;
            (lo.min(a).min(b).min(c), hi.max(a).max(b).max(c))
        })
        .reduce(empty, |(a, b), (c, d)| (a.min(c), b.max(d)));
    for (_, v) in instances.placed_corners().flatten().flatten() {
        (lo, hi) = (lo.min(v), hi.max(v));
    }
    for s in spheres {
        (lo, hi) = (lo.min(s.center - s.radius), hi.max(s.center + s.radius));
    }
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// A mesh file on its own: grey diffuse, a constant white environment.
pub fn bare_mesh(path: &Path, limits: &Limits) -> Result<SceneInput> {
    let is_ply = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ply"));
    let mut triangles = Vec::new();
    if is_ply {
        let mesh = super::ply::load_ply(path)?;
        mesh.validate().map_err(|m| Error::at(path, None, m))?;
        mesh.triangles(
            Mat4::IDENTITY,
            Orientation::Winding,
            false,
            false,
            0,
            &mut triangles,
        );
    } else {
        let obj = super::obj::load_obj(path)?;
        triangles.extend(obj.triangles.into_iter().map(|t| TriangleInput {
            vertices: t.vertices,
            material: 0,
            uvs: t.uvs,
            normals: t.normals,
        }));
    }
    if triangles.is_empty() {
        return Err(Error::at(path, None, "no triangles: nothing to render"));
    }
    if triangles.len() > limits.max_triangles {
        return Err(Error::at(
            path,
            None,
            format!(
                "{} triangles, more than {} (raise the limit with --max-triangles)",
                triangles.len(),
                limits.max_triangles
            ),
        ));
    }
    let camera = default_camera(&triangles, &[], &Default::default());
    Ok(SceneInput {
        camera,
        materials: vec![super::load::default_material()],
        textures: Vec::new(),
        environment: Some(Environment::new(
            Radiance::Constant(Rgb::ONE),
            1.0,
            Mat3A::IDENTITY,
        )),
        triangles,
        spheres: Vec::new(),
        point_lights: Vec::new(),
        moving: Vec::new(),
        instances: Default::default(),
        sphere_sampling: LightSampling::SolidAngle,
        triangle_sampling: LightSampling::Area,
        warnings: vec![format!(
            "{}: a bare mesh: grey diffuse, lit by a white constant environment, default camera",
            path.display()
        )],
        hints: Default::default(),
    })
}
