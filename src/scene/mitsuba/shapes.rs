//! Mitsuba's shape plugins: mesh files (obj, ply, serialized), the built-in
//! shapes (rectangle, cube, sphere, disk, cylinder) and instances of shape
//! groups, with their BSDFs and area emitters.

use super::meshes::MeshFile;
use super::props::{Colour, Props};
use super::xml::Element;
use super::{Emission, Importer};
use crate::accel::{NO_LIGHT, Sphere};
use crate::error::Result;
use crate::scene::mesh::{MeshData, Orientation, Placement};
use crate::scene::{MAX_COORDINATE, in_range};
use glam::{Mat4, Vec3A};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A mesh waiting to be placed (see [`Importer::place_pending`]).
pub(super) struct Pending<'a> {
    mesh: MeshData,
    at: Placement,
    /// The shape, for errors.
    e: &'a Element,
}

/// Segments of a tessellated disk or cylinder.
const SEGMENTS: u32 = 128;

impl<'a> Importer<'a> {
    /// One `<shape>`, placed by `parent` (an instance's transform).
    pub(super) fn shape(&mut self, e: &'a Element, parent: Mat4) -> Result<()> {
        let p = Props::new(e, self.ids);
        let kind = e.plugin();
        if kind == "shapegroup" {
            // Drawn only through instances.
            p.mark_all_used();
            return Ok(());
        }
        if kind == "instance" {
            let groups = p.objects("shape")?;
            let to_world = parent * p.transform("to_world")?.unwrap_or(Mat4::IDENTITY);
            p.unused(&mut self.warnings);
            for group in groups {
                if group.plugin() != "shapegroup" {
                    return Err(e.loc.error("an instance refers to a shapegroup"));
                }
                self.instance(e, group, to_world)?;
            }
            return Ok(());
        }
        let to_world = parent * p.transform("to_world")?.unwrap_or(Mat4::IDENTITY);
        let flip = p.bool("flip_normals")?.unwrap_or(false);
        let bsdf = p.objects("bsdf")?.first().copied();
        let emission = self.area_emitter(&p)?;
        for medium in p.objects("medium")? {
            self.warn(&medium.loc, "participating medium ignored");
        }
        let material = self.material(bsdf, emission)?;
        let (mesh, orientation, face_normals) = match kind {
            "obj" | "ply" | "serialized" => {
                let file = MeshFile::of(e, &p, self.doc)?.expect("a mesh shape");
                let face_normals = p.bool("face_normals")?.unwrap_or(false);
                let mesh = match self.prefetched.mesh(&file) {
                    Some(mesh) => mesh,
                    None => file.read()?,
                };
                if mesh.indices.is_empty() {
                    let what = format!(
                        "{} holds no triangles: the shape adds nothing",
                        file.path.display()
                    );
                    self.warn(&e.loc, &what);
                    p.unused(&mut self.warnings);
                    return Ok(());
                }
                (mesh, Orientation::Winding, face_normals)
            }
            "rectangle" => (MeshData::rectangle(), Orientation::Normal, false),
            "cube" => (MeshData::cube(), Orientation::Normal, false),
            "disk" | "cylinder" => {
                let mesh = if kind == "disk" {
                    MeshData::disk(SEGMENTS)
                } else {
                    let p0 = p.point("p0")?.unwrap_or(glam::Vec3::ZERO);
                    let p1 = p.point("p1")?.unwrap_or(glam::Vec3::Z);
                    let radius = p.float_or("radius", 1.0)?;
                    let axis = p1 - p0;
                    if axis.length_squared() == 0.0 || !(radius > 0.0) {
                        return Err(e.loc.error("a cylinder needs p0 != p1 and radius > 0"));
                    }
                    // Unit tube onto the given axis and radius.
                    let rotation = glam::Quat::from_rotation_arc(glam::Vec3::Z, axis.normalize());
                    let local = Mat4::from_translation(p0)
                        * Mat4::from_quat(rotation)
                        * Mat4::from_scale(glam::Vec3::new(radius, radius, axis.length()));
                    let cylinder = MeshData::cylinder(SEGMENTS);
                    self.warn(
                        &e.loc,
                        &format!(
                            "cylinder tessellated into {} triangles",
                            cylinder.indices.len()
                        ),
                    );
                    let placement = (to_world * local, Orientation::Normal, flip, false);
                    self.place_mesh(e, cylinder, placement, material)?;
                    p.unused(&mut self.warnings);
                    return Ok(());
                };
                self.warn(
                    &e.loc,
                    &format!("disk tessellated into {SEGMENTS} triangles (area kept)"),
                );
                (mesh, Orientation::Normal, false)
            }
            "sphere" => {
                let center = p.point("center")?.unwrap_or(glam::Vec3::ZERO);
                let radius = p.float_or("radius", 1.0)?;
                // The sphere's own frame: to_world ∘ translate(center) ∘ scale(radius).
                let m = to_world
                    * Mat4::from_translation(center)
                    * Mat4::from_scale(glam::Vec3::splat(radius));
                let axes = [m.x_axis, m.y_axis, m.z_axis].map(|a| a.truncate().length());
                let r = axes.iter().sum::<f32>() / 3.0;
                if axes.iter().any(|a| (a - r).abs() > 1e-4 * r) {
                    self.warn(&e.loc, &format!("a sphere scaled unevenly ({axes:?}) is rendered as a sphere of radius {r}"));
                }
                if flip {
                    self.warn(
                        &e.loc,
                        "flip_normals on a sphere ignored (spheres face outward)",
                    );
                }
                let center = Vec3A::from(m.w_axis.truncate());
                if !in_range(center) || !(r > 0.0 && r <= MAX_COORDINATE) {
                    return Err(e.loc.error("the sphere's center or radius is out of range"));
                }
                p.unused(&mut self.warnings);
                self.spheres.push(Sphere {
                    center,
                    radius: r,
                    material,
                    light: NO_LIGHT,
                });
                return Ok(());
            }
            other => {
                self.warn(
                    &e.loc,
                    &format!("shape \"{other}\" is not supported: skipped"),
                );
                p.mark_all_used();
                return Ok(());
            }
        };
        self.place_mesh(
            e,
            mesh,
            (to_world, orientation, flip, face_normals),
            material,
        )?;
        p.unused(&mut self.warnings);
        Ok(())
    }

    /// One instance of `group`: shared where the group is triangles only,
    /// copied where it holds a sphere (spheres are not instanced) or the
    /// transform mirrors (see `InstancesInput`). The group is read once,
    /// on its first instance; a copy reads it again, its warnings not
    /// repeated. Emitters in the group are copied when the scene is built;
    /// an instance within a group is copied into the group's triangles.
    fn instance(&mut self, e: &'a Element, group: &'a Element, to_world: Mat4) -> Result<()> {
        let key = group as *const Element;
        let prototype = match self.groups.get(&key) {
            // An instance inside a group being read is copied into it.
            _ if self.reading_group => None,
            Some(&p) => p,
            None => {
                // The group's triangles are read into a list of their own.
                self.place_pending()?;
                let triangles = std::mem::take(&mut self.triangles);
                let spheres = self.spheres.len();
                self.reading_group = true;
                let read: Result<()> = group
                    .children
                    .iter()
                    .filter(|c| c.tag == "shape")
                    .try_for_each(|child| self.shape(child, Mat4::IDENTITY));
                self.reading_group = false;
                read?;
                let local = std::mem::replace(&mut self.triangles, triangles);
                let p = if self.spheres.len() == spheres {
                    let shared = &mut self.instances.prototypes;
                    shared.push(local);
                    let stored: usize = shared.iter().map(Vec::len).sum();
                    if self.triangles.len() + stored > self.limits.max_triangles {
                        return Err(e.loc.error(format!(
                            "more than {} triangles (raise the limit with --max-triangles)",
                            self.limits.max_triangles
                        )));
                    }
                    Some(shared.len() as u32 - 1)
                } else {
                    self.spheres.truncate(spheres);
                    None
                };
                self.groups.insert(key, p);
                p
            }
        };
        let affine = glam::Affine3A::from_mat4(to_world);
        let shared = prototype.filter(|_| to_world.determinant() > 0.0);
        match shared {
            Some(p) => {
                if !(affine.is_finite() && affine.matrix3.determinant().is_normal()) {
                    return Err(e
                        .loc
                        .error("the instance's to_world is singular or not finite"));
                }
                self.instances.placements.push((p, affine));
            }
            None => {
                // Warnings were given when the group was first read.
                let (warnings, read) = (self.warnings.len(), self.groups.contains_key(&key));
                for child in group.children.iter().filter(|c| c.tag == "shape") {
                    self.shape(child, to_world)?;
                }
                if read {
                    self.warnings.truncate(warnings);
                }
            }
        }
        Ok(())
    }

    /// The triangles placed so far and waiting to be placed.
    fn triangle_count(&self) -> usize {
        self.triangles.len() + self.pending_triangles
    }

    /// Adds `mesh`'s triangles placed by (to_world, orientation, flip,
    /// face_normals) (see [`MeshData::triangles`]), checked against the
    /// triangle limit. A mesh of the top level waits for
    /// [`Importer::place_pending`]; one in a shape group, read into its
    /// prototype, is placed now.
    fn place_mesh(
        &mut self,
        e: &'a Element,
        mesh: MeshData,
        (to_world, orientation, flip, face_normals): (Mat4, Orientation, bool, bool),
        material: u32,
    ) -> Result<()> {
        if self.triangle_count() + mesh.indices.len() > self.limits.max_triangles {
            return Err(e.loc.error(format!(
                "more than {} triangles (raise the limit with --max-triangles)",
                self.limits.max_triangles
            )));
        }
        let at = Placement::new(to_world, orientation, flip, face_normals, material);
        self.pending_triangles += mesh.indices.len();
        self.pending.push(Pending { at, mesh, e });
        if self.reading_group {
            self.place_pending()?;
        }
        Ok(())
    }

    /// Places the waiting meshes into `triangles`, in file order, on every
    /// core: on a scene of a million triangles, making them on one thread
    /// was a tenth of the load (docs/performance.md, "Loading and memory").
    /// An error names the first shape, in file order, whose mesh is
    /// invalid or lands out of range.
    pub(super) fn place_pending(&mut self) -> Result<()> {
        let pending = std::mem::take(&mut self.pending);
        self.pending_triangles = 0;
        let invalid = (pending.par_iter())
            .map(|p| p.mesh.validate())
            .position_first(|r| r.is_err());
        if let Some(i) = invalid {
            let message = pending[i].mesh.validate().unwrap_err();
            return Err(pending[i].e.loc.error(message));
        }
        // Where each mesh's triangles start.
        let mut starts = Vec::with_capacity(pending.len());
        let mut total = 0;
        for p in &pending {
            starts.push(total);
            total += p.mesh.indices.len();
        }
        let mesh_of = |k: usize| starts.partition_point(|&s| s <= k) - 1;
        let base = self.triangles.len();
        // The first triangle out of range, checked as it is made (a second
        // pass read the million triangles again).
        let outside = AtomicUsize::new(usize::MAX);
        self.triangles
            .par_extend((0..total).into_par_iter().with_min_len(1 << 12).map(|k| {
                let i = mesh_of(k);
                let t = pending[i].mesh.triangle(&pending[i].at, k - starts[i]);
                if !t.vertices.iter().all(|&v| in_range(v)) {
                    outside.fetch_min(k, Ordering::Relaxed);
                }
                t
            }));
        let outside = Some(outside.into_inner()).filter(|&k| k != usize::MAX);
        if let Some(k) = outside {
            self.triangles.truncate(base);
            return Err(pending[mesh_of(k)].e.loc.error(format!(
                "after its transform, the shape reaches beyond ±{MAX_COORDINATE:e}"
            )));
        }
        Ok(())
    }

    /// The radiance of a shape's `area` emitter, if it has one, and the
    /// texture that multiplies it where it is textured.
    fn area_emitter(&mut self, p: &Props<'a>) -> Result<Option<Emission>> {
        let emitters = p.objects("emitter")?;
        let Some(&e) = emitters.first() else {
            return Ok(None);
        };
        if e.plugin() != "area" {
            return Err(e.loc.error(format!(
                "a shape's emitter must be `area`, not `{}`",
                e.plugin()
            )));
        }
        let ep = Props::new(e, self.ids);
        let (radiance, texture) = match ep.colour("radiance", true)? {
            None => (crate::math::Rgb::ONE, None),
            Some(Colour::Value(c)) => (c, None),
            Some(Colour::Texture(t)) => (crate::math::Rgb::ONE, Some(self.texture(t)?)),
        };
        ep.unused(&mut self.warnings);
        if !(radiance.min_element() >= 0.0) {
            return Err(e.loc.error("radiance must be >= 0"));
        }
        Ok(Some(Emission { radiance, texture }))
    }
}
