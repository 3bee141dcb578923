//! Instanced geometry: a prototype's triangles and BVH stored once and
//! placed any number of times by affine transforms (Mitsuba's `shapegroup`
//! and `instance`). A query moves the ray into the prototype's space,
//! searches its BVH and moves the hit back, as pbrt-v4's
//! `TransformedPrimitive`; a top-level CWBVH over the instances' bounds
//! finds which ones a ray meets where there are many.

use super::build::build_shallow_cwbvh;
use super::{Geometry, SurfaceHit, bvh_ray};
use crate::math::{Ray, gamma};
use glam::{Affine3A, Mat3A, Vec2, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use std::sync::Arc;

/// Set in [`SurfaceHit::instance`] for hits on geometry that is not instanced.
pub const NO_INSTANCE: u32 = u32::MAX;

/// Most instances tested one by one without a top-level BVH, as for spheres.
const INSTANCE_LIST_MAX: usize = 8;

/// One placement of a prototype.
#[derive(Clone, Debug)]
pub(super) struct Instance {
    prototype: u32,
    to_world: Affine3A,
    to_local: Affine3A,
    /// The inverse transpose of `to_world`'s linear part, for normals.
    normal_to_world: Mat3A,
}

/// The prototypes and their placements.
#[derive(Clone, Debug, Default)]
pub(super) struct Instances {
    prototypes: Vec<Arc<Geometry>>,
    /// Each prototype's bounds in its own space, computed once.
    prototype_bounds: Vec<Aabb>,
    list: Vec<Instance>,
    /// Over `list`'s world bounds, in its order, where there are many.
    bvh: Option<CwBvh>,
}

/// The world bounds of `local` placed by `to_world`: its eight corners moved.
pub(super) fn transformed_bounds(local: &Aabb, to_world: &Affine3A) -> Aabb {
    let (min, max) = (local.min, local.max);
    let mut b = Aabb::empty();
    for corner in 0..8 {
        let pick = |axis: usize| if corner >> axis & 1 == 0 { min } else { max };
        let p = Vec3A::new(pick(0).x, pick(1).y, pick(2).z);
        b.extend(to_world.transform_point3a(p));
    }
    b
}

impl Instances {
    /// Places `prototypes[prototype]` by each `to_world` of `placements`;
    /// every transform must be invertible and keep orientation (the loader
    /// copies mirrored instances instead: see `Geometry::add_instances`).
    pub(super) fn new(prototypes: Vec<Arc<Geometry>>, placements: &[(u32, Affine3A)]) -> Self {
        let mut list: Vec<Instance> = placements
            .iter()
            .map(|&(prototype, to_world)| Instance {
                prototype,
                to_world,
                to_local: to_world.inverse(),
                normal_to_world: to_world.matrix3.inverse().transpose(),
            })
            .collect();
        let prototype_bounds: Vec<Aabb> = prototypes.iter().map(|p| p.bounds()).collect();
        let mut bvh = None;
        if list.len() > INSTANCE_LIST_MAX {
            let bounds: Vec<Aabb> = list
                .iter()
                .map(|i| transformed_bounds(&prototype_bounds[i.prototype as usize], &i.to_world))
                .collect();
            // Too deep to traverse (many coincident instances): tested one by one.
            if let Some(tree) = build_shallow_cwbvh(&bounds) {
                list = tree
                    .primitive_indices
                    .iter()
                    .map(|&i| list[i as usize].clone())
                    .collect();
                bvh = Some(tree);
            }
        }
        Instances {
            prototypes,
            prototype_bounds,
            list,
            bvh,
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    pub(super) fn len(&self) -> usize {
        self.list.len()
    }

    /// Triangles drawn, counting each instance's.
    pub(super) fn triangles_drawn(&self) -> usize {
        self.list
            .iter()
            .map(|i| self.prototypes[i.prototype as usize].triangle_count())
            .sum()
    }

    /// Bytes of the prototypes (each once) and the placements.
    pub(super) fn memory_bytes(&self) -> usize {
        self.prototypes
            .iter()
            .map(|p| p.memory_bytes())
            .sum::<usize>()
            + std::mem::size_of_val(&self.list[..])
            + self
                .bvh
                .as_ref()
                .map_or(0, |b| std::mem::size_of_val(&b.nodes[..]))
    }

    pub(super) fn bounds(&self) -> Aabb {
        self.list.iter().fold(Aabb::empty(), |b, i| {
            b.union(&transformed_bounds(
                &self.prototype_bounds[i.prototype as usize],
                &i.to_world,
            ))
        })
    }

    /// The instances' surface area: per triangle, |M e1 × M e2| / 2 =
    /// |det M · M⁻ᵀ (e1 × e2)| / 2.
    pub(super) fn area(&self) -> f64 {
        self.list
            .iter()
            .map(|i| {
                let det = i.to_world.matrix3.determinant().abs() as f64;
                let p = &self.prototypes[i.prototype as usize];
                let sum: f64 = p
                    .tri_vertices
                    .iter()
                    .map(|[a, b, c]| (i.normal_to_world * (*b - *a).cross(*c - *a)).length() as f64)
                    .sum();
                0.5 * det * sum
            })
            .sum()
    }

    pub(super) fn has_shading_normals(&self) -> bool {
        self.prototypes.iter().any(|p| p.has_shading_normals())
    }

    /// Every instance's triangles in world space, with their materials,
    /// uvs and normals, for what needs them one by one (radiosity).
    pub(super) fn flattened(&self) -> Vec<super::TriangleInput> {
        let mut out = Vec::with_capacity(self.triangles_drawn());
        for i in &self.list {
            let p = &self.prototypes[i.prototype as usize];
            for t in 0..p.triangle_count() {
                out.push(super::TriangleInput {
                    vertices: p.tri_vertices[t].map(|v| i.to_world.transform_point3a(v)),
                    material: p.tri_shading[t].material,
                    uvs: p.tri_uvs.get(t).copied(),
                    normals: p
                        .tri_normals
                        .get(t)
                        .map(|n| n.map(|n| (i.normal_to_world * n).normalize())),
                });
            }
        }
        out
    }

    /// The closest instance hit nearer than `best` (or `ray.t_max`).
    #[inline(always)]
    pub(super) fn closest(&self, ray: &Ray, best: Option<SurfaceHit>) -> Option<SurfaceHit> {
        let mut best = best;
        let search = |index: usize, t_max: f32, best: &mut Option<SurfaceHit>| {
            let instance = &self.list[index];
            let local = instance.local_ray(ray, t_max);
            let found =
                self.prototypes[instance.prototype as usize].intersect_static::<false>(&local);
            if let Some(hit) = found {
                *best = Some(instance.to_world_hit(hit, index as u32));
            }
        };
        match &self.bvh {
            None => {
                for index in 0..self.list.len() {
                    let t_max = best.map_or(ray.t_max, |h| h.t);
                    search(index, t_max, &mut best);
                }
            }
            Some(bvh) => {
                let mut hit = obvhs::ray::RayHit::none();
                let t_max = best.map_or(ray.t_max, |h| h.t);
                bvh.ray_traverse(bvh_ray(ray, t_max), &mut hit, |r, index| {
                    search(index, r.tmax, &mut best);
                    best.map_or(f32::INFINITY, |h| h.t)
                });
            }
        }
        best
    }

    /// True when some instance blocks `ray` in (0, ray.t_max).
    #[inline(always)]
    pub(super) fn any(&self, ray: &Ray) -> bool {
        let blocks = |index: usize| {
            let instance = &self.list[index];
            let local = instance.local_ray(ray, ray.t_max);
            self.prototypes[instance.prototype as usize].occluded_static::<false>(&local)
        };
        match &self.bvh {
            None => (0..self.list.len()).any(blocks),
            Some(bvh) => !bvh.ray_traverse_miss(bvh_ray(ray, ray.t_max), |_, index| {
                if blocks(index) { 0.0 } else { f32::INFINITY }
            }),
        }
    }

    /// The prototype of `hit` and its instance.
    #[inline]
    fn of(&self, hit: &SurfaceHit) -> (&Geometry, &Instance) {
        let instance = &self.list[hit.instance as usize];
        (&self.prototypes[instance.prototype as usize], instance)
    }

    /// [`Geometry::shading_normal`] of an instance hit.
    #[inline]
    pub(super) fn shading_normal(&self, hit: &SurfaceHit) -> Vec3A {
        let (prototype, instance) = self.of(hit);
        match prototype.local_shading_normal(hit) {
            Some(n) => (instance.normal_to_world * n).normalize_or(hit.normal),
            None => hit.normal,
        }
    }

    /// [`Geometry::uv`] of an instance hit: the prototype's, unchanged.
    #[inline]
    pub(super) fn uv(&self, hit: &SurfaceHit) -> Vec2 {
        self.of(hit).0.local_uv(hit)
    }

    /// [`Geometry::uv_derivatives`] of an instance hit, moved to world space.
    #[inline]
    pub(super) fn uv_derivatives(&self, hit: &SurfaceHit) -> Option<(Vec3A, Vec3A)> {
        let (prototype, instance) = self.of(hit);
        let (dpdu, dpdv) = prototype.local_uv_derivatives(hit)?;
        let m = instance.to_world.matrix3;
        Some((m * dpdu, m * dpdv))
    }
}

impl Instance {
    /// `ray` in the prototype's space; its parameter t means the same point.
    #[inline(always)]
    fn local_ray(&self, ray: &Ray, t_max: f32) -> Ray {
        Ray {
            origin: self.to_local.transform_point3a(ray.origin),
            direction: self.to_local.transform_vector3a(ray.direction),
            t_max,
            time: ray.time,
        }
    }

    /// A hit found in the prototype's space, moved to world space, with the
    /// transform's rounding added to its error bound (pbrt-v4's
    /// `Transform::operator()(Point3fi)`).
    #[inline(always)]
    fn to_world_hit(&self, hit: SurfaceHit, index: u32) -> SurfaceHit {
        let m = self.to_world.matrix3;
        let abs = Mat3A::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let point = self.to_world.transform_point3a(hit.point);
        let error = (1.0 + gamma(3)) * (abs * hit.error)
            + gamma(3) * (abs * hit.point.abs() + self.to_world.translation.abs());
        SurfaceHit {
            point,
            error,
            normal: (self.normal_to_world * hit.normal).normalize_or(hit.normal),
            instance: index,
            ..hit
        }
    }
}
