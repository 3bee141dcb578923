//! Ray queries against the scene's geometry: an 8-wide BVH over triangles
//! (obvhs builds the binary tree, `wide_bvh.rs` collapses and traverses it),
//! a flat soup for small meshes, an obvhs CWBVH over many spheres,
//! watertight ray/triangle intersection and a numerically careful ray/sphere
//! test.
//!
//! Triangles are stored in flat arrays in leaf order, so a leaf's triangles
//! are contiguous in memory and a hit's index addresses them directly.

pub mod blend;
mod block;
mod build;
mod instance;
mod interpolate;
mod known_visibility;
pub mod mask;
mod soup;
mod sphere;
pub(crate) mod triangle;
mod wide_bvh;

use crate::math::{OffsetMode, Ray, gamma};
use blend::Blends;
use glam::{Affine3A, Vec2, Vec3A};
use instance::Instances;
pub use instance::NO_INSTANCE;
pub use interpolate::sphere_uv;
use mask::Masks;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use soup::TriangleSoup;
use sphere::{SPHERE_LANES_MIN, SphereLanes, intersect_sphere};
use std::sync::Arc;
use wide_bvh::WideBvh;

/// Marks a primitive that is not a light.
pub const NO_LIGHT: u32 = u32::MAX;

/// An analytic sphere.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3A,
    pub radius: f32,
    pub material: u32,
    pub light: u32,
}

/// A triangle as given to [`Geometry::build`].
#[derive(Clone, Copy, Debug)]
pub struct TriangleInput {
    pub vertices: [Vec3A; 3],
    pub material: u32,
    /// Texture coordinates at the vertices; None gives (0, 0), (1, 0),
    /// (1, 1)'s barycentric default (b1, b2).
    pub uvs: Option<[Vec2; 3]>,
    /// Shading normals at the vertices (unit), interpolated at hits.
    pub normals: Option<[Vec3A; 3]>,
}

impl TriangleInput {
    /// Whether it has no representable area or normal: no hits, no
    /// emission, and nothing a renderer can do with it.
    pub fn is_degenerate(&self) -> bool {
        let [a, b, c] = self.vertices;
        let n = (b - a).cross(c - a);
        !(n.length_squared() > 0.0 && n.is_finite() && n.normalize().is_finite())
    }

    /// The parallelogram `corner + a u + b v`, a, b in [0, 1], as two
    /// triangles wound like (u, v): the quads of scene files and test scenes.
    pub fn quad(corner: Vec3A, u: Vec3A, v: Vec3A, material: u32) -> [TriangleInput; 2] {
        [
            // (a, b) as texture coordinates, as Mitsuba's rectangle.
            TriangleInput {
                vertices: [corner, corner + u, corner + u + v],
                material,
                uvs: Some([Vec2::ZERO, Vec2::X, Vec2::ONE]),
                normals: None,
            },
            TriangleInput {
                vertices: [corner, corner + u + v, corner + v],
                material,
                uvs: Some([Vec2::ZERO, Vec2::ONE, Vec2::Y]),
                normals: None,
            },
        ]
    }
}

/// Set in [`SurfaceHit::primitive`] for hits on moving objects, whose
/// indices are their own object's.
pub const MOVING_PRIMITIVE: u32 = 1 << 31;

/// What a closest-hit query found.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Hit point, computed from barycentrics (triangles) or re-projected onto
    /// the sphere, which is more accurate than `origin + t * direction`.
    pub point: Vec3A,
    /// Per-component bound on the rounding error of `point`, for spawning rays.
    pub error: Vec3A,
    /// Unit geometric normal: triangle winding order (counter-clockwise seen
    /// from the front) or outward for spheres. Not flipped towards the ray.
    pub normal: Vec3A,
    pub material: u32,
    /// Light id of the primitive or [`NO_LIGHT`].
    pub light: u32,
    /// Time of the ray that found the hit, inherited by rays spawned here.
    pub time: f32,
    /// Barycentric coordinates (b1, b2) of a triangle hit, from which
    /// [`Geometry::shading_normal`] and [`Geometry::uv`] interpolate only
    /// when asked (they fit in the record's padding).
    pub barycentric: Vec2,
    /// Which primitive: a triangle's index, or the triangle count plus a
    /// sphere's index (within one object, for diagnostics such as counting
    /// self-intersections).
    pub primitive: u32,
    /// Which instance the primitive belongs to, or [`NO_INSTANCE`]
    /// (it fits in the record's padding).
    pub instance: u32,
}

impl SurfaceHit {
    /// A ray leaving the surface in `direction`, its origin moved off the
    /// surface by the hit's error bound (see [`crate::math::offset_ray_origin`]).
    #[inline]
    pub fn spawn_ray(&self, direction: Vec3A) -> Ray {
        Ray::new(
            crate::math::offset_ray_origin(self.point, self.error, self.normal, direction),
            direction,
        )
        .at_time(self.time)
    }
}

/// Per-triangle data read once per hit.
#[derive(Clone, Copy, Debug)]
struct TriangleShading {
    /// Unit geometric normal, precomputed: saves a cross product and a
    /// normalisation per hit.
    normal: Vec3A,
    material: u32,
    light: u32,
}

impl TriangleShading {
    fn new(&[p0, p1, p2]: &[Vec3A; 3], material: u32) -> Self {
        TriangleShading {
            normal: (p1 - p0).cross(p2 - p0).normalize(),
            material,
            light: NO_LIGHT,
        }
    }
}

/// How triangles are searched.
#[derive(Clone, Debug, Default)]
enum TriangleIndex {
    #[default]
    Empty,
    /// Every triangle tested, eight per instruction: faster below
    /// [`SOUP_MAX_TRIANGLES`] triangles.
    Soup(TriangleSoup),
    /// An 8-wide BVH with SIMD node tests and 8-triangle leaves.
    Bvh(WideBvh),
}

/// Which triangle index to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelChoice {
    /// A soup for small meshes, a BVH otherwise.
    #[default]
    Auto,
    Bvh,
    Soup,
}

/// Most spheres tested one by one without a BVH: for a handful of spheres the
/// CWBVH's traversal set-up costs more than the tests it saves. Measured
/// (path tracing, 2 threads, median of 5): `scenes/motion_blur.toml` with its
/// two balls at rest 2.06 -> 2.32 M paths/s, moving 1.70 -> 2.12 M paths/s.
pub const SPHERE_LIST_MAX: usize = 8;

/// Largest mesh tested without a BVH. `cargo bench --bench throughput --
/// rays` (closest hit, incoherent, one thread): on the 32-triangle Cornell
/// box the soup does 13.1 M rays/s, the 8-wide BVH 9.9 M. The two met at
/// about this size when the BVH was obvhs's CWBVH; with the 8-wide nodes
/// they meet at 40–50 (docs/performance.md, "Traversal and the BVH").
pub const SOUP_MAX_TRIANGLES: usize = 64;

/// The scene's geometry with its acceleration structures.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    tri_index: TriangleIndex,
    /// Vertices in BVH order.
    tri_vertices: Vec<[Vec3A; 3]>,
    /// What a hit needs besides the position, one cache line per triangle.
    tri_shading: Vec<TriangleShading>,
    /// Texture coordinates per triangle in BVH order; empty when no
    /// material reads textures (hits then carry barycentrics).
    tri_uvs: Vec<[Vec2; 3]>,
    /// Vertex normals per triangle in BVH order; empty when no triangle
    /// has any (hits then shade with the geometric normal).
    tri_normals: Vec<[Vec3A; 3]>,
    sphere_bvh: Option<CwBvh>,
    /// The spheres in lanes of eight, where they have no BVH.
    sphere_lanes: Vec<SphereLanes>,
    spheres: Vec<Sphere>,
    /// Objects in linear motion, each tested by moving the ray instead.
    moving: Vec<MovingGeometry>,
    /// How rays spawned at hits leave the surface.
    offset: OffsetMode,
    /// A BVH came out deeper than its traversal stack and its primitives
    /// are tested one by one instead.
    bvh_too_deep: bool,
    /// Whether hits interpolate the triangles' texture coordinates.
    keep_uvs: bool,
    /// Whether hits interpolate vertex normals.
    keep_normals: bool,
    /// Opacity masks, where some material has one: queries then pass
    /// through the hits a mask drops.
    masks: Option<Arc<Masks>>,
    /// Blends of two materials, where some material is one: hits then
    /// take one of the two by a hash of their point.
    blends: Option<Arc<Blends>>,
    /// Shared geometry placed by transforms.
    instances: Instances,
    /// No masks, blends, instances, moving objects or fixed offset
    /// ([`Geometry::is_plain`]). False until settled, so that a geometry
    /// built another way is never taken for plain.
    plain: bool,
}

/// Geometry translated by `velocity * time`: at time t it is hit where the
/// ray shifted by `-velocity * t` hits the geometry at rest. Moving objects
/// are few (a ball, a car), so they are tested one after the other, each with
/// its own BVH; a static scene has none and pays one empty-list check.
#[derive(Clone, Debug)]
struct MovingGeometry {
    geometry: Geometry,
    velocity: Vec3A,
}

/// The obvhs ray for `ray`. A direction component of -0.0 must become +0.0:
/// obvhs takes the ray octant from `< 0.0` but the reciprocal's sign from the
/// sign bit, and with the two disagreeing the traversal misses everything
/// (found by `closest_of_sphere_and_triangle_wins`). Adding +0.0 maps -0.0 to
/// +0.0 and leaves every other value unchanged.
#[inline]
fn bvh_ray(ray: &Ray, t_max: f32) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new(ray.origin, ray.direction + Vec3A::ZERO, 0.0, t_max)
}

impl Geometry {
    /// Adds an object that moves by `velocity` per unit of time; `geometry`
    /// is its position at time 0. Lights never move (their sampling assumes
    /// fixed positions), so `geometry` must hold no light.
    pub fn add_moving(&mut self, geometry: Geometry, velocity: Vec3A) {
        debug_assert!(geometry.moving.is_empty());
        self.moving.push(MovingGeometry { geometry, velocity });
        self.update_plain();
    }

    /// True when queries meet only geometry at rest: no masks, instances,
    /// moving objects or fixed offset ([`Geometry::intersect_as`]).
    #[inline(always)]
    pub fn is_plain(&self) -> bool {
        self.plain
    }

    /// Settles [`Geometry::is_plain`] after what it reads has changed.
    fn update_plain(&mut self) {
        self.plain = self.masks.is_none()
            && self.blends.is_none()
            && self.instances.is_empty()
            && self.moving.is_empty()
            && !matches!(self.offset, OffsetMode::Fixed(_));
    }

    /// True when there are spheres, at rest or moving.
    pub fn has_spheres(&self) -> bool {
        !self.spheres.is_empty() || self.moving.iter().any(|m| m.geometry.has_spheres())
    }

    /// True when the triangle BVH would have been too deep to traverse and
    /// every triangle is tested instead (pathological overlapping geometry).
    pub fn bvh_too_deep(&self) -> bool {
        self.bvh_too_deep || self.moving.iter().any(|m| m.geometry.bvh_too_deep)
    }

    /// True when some object moves.
    pub fn has_motion(&self) -> bool {
        !self.moving.is_empty()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.tri_vertices.len()
    }

    /// Bytes held by the geometry and its acceleration structures (heap
    /// arrays at their length, not capacity), for the memory-per-triangle
    /// figure of `cargo bench --bench scaling`.
    pub fn memory_bytes(&self) -> usize {
        self.memory_parts().iter().map(|(_, bytes)| bytes).sum()
    }

    /// [`Geometry::memory_bytes`] by part, for the render summary.
    pub fn memory_parts(&self) -> [(&'static str, usize); 7] {
        use std::mem::size_of_val;
        let bvh = |b: &CwBvh| {
            size_of_val(&b.nodes[..])
                + size_of_val(&b.primitive_indices[..])
                + b.exact_node_aabbs
                    .as_ref()
                    .map_or(0, |a| size_of_val(&a[..]))
        };
        let index = match &self.tri_index {
            TriangleIndex::Empty => 0,
            TriangleIndex::Soup(soup) => soup.memory_bytes(),
            TriangleIndex::Bvh(b) => b.memory_bytes(),
        };
        let elsewhere = self
            .moving
            .iter()
            .map(|m| m.geometry.memory_bytes())
            .sum::<usize>()
            + self.instances.memory_bytes();
        [
            ("vertices", size_of_val(&self.tri_vertices[..])),
            ("normals and materials", size_of_val(&self.tri_shading[..])),
            ("uv", size_of_val(&self.tri_uvs[..])),
            ("shading normals", size_of_val(&self.tri_normals[..])),
            ("BVH", index),
            (
                "spheres",
                self.sphere_bvh.as_ref().map_or(0, bvh)
                    + size_of_val(&self.spheres[..])
                    + size_of_val(&self.sphere_lanes[..]),
            ),
            ("instances and moving objects", elsewhere),
        ]
    }

    /// Triangle vertices in BVH order.
    pub fn triangles(&self) -> &[[Vec3A; 3]] {
        &self.tri_vertices
    }

    /// Material of triangle `i` (BVH order).
    pub fn triangle_material(&self, i: usize) -> u32 {
        self.tri_shading[i].material
    }

    /// Light of triangle `i` (BVH order), or [`NO_LIGHT`].
    pub fn triangle_light(&self, i: usize) -> u32 {
        self.tri_shading[i].light
    }

    /// Unit geometric normal of triangle `i` (BVH order).
    pub fn triangle_normal(&self, i: usize) -> Vec3A {
        self.tri_shading[i].normal
    }

    /// Spheres in BVH order.
    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }

    /// Marks triangle `i` (BVH order) as light `light`.
    pub fn set_triangle_light(&mut self, i: usize, light: u32) {
        self.tri_shading[i].light = light;
    }

    /// Marks sphere `i` (BVH order) as light `light`.
    pub fn set_sphere_light(&mut self, i: usize, light: u32) {
        self.spheres[i].light = light;
    }

    /// Bounding box of everything.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::empty();
        for t in &self.tri_vertices {
            b = b.union(&Aabb::from_points(t));
        }
        for s in &self.spheres {
            b = b.union(&Aabb::new(
                s.center - Vec3A::splat(s.radius),
                s.center + Vec3A::splat(s.radius),
            ));
        }
        b = b.union(&self.instances.bounds());
        for m in &self.moving {
            // Swept over the unit time interval.
            let at_rest = m.geometry.bounds();
            b = b.union(&at_rest).union(&Aabb::new(
                at_rest.min + m.velocity,
                at_rest.max + m.velocity,
            ));
        }
        b
    }

    /// True when some triangle shades with interpolated vertex normals.
    pub fn has_shading_normals(&self) -> bool {
        !self.tri_normals.is_empty()
            || self.moving.iter().any(|m| m.geometry.has_shading_normals())
            || self.instances.has_shading_normals()
    }

    /// Sets how rays spawned at hits leave the surface.
    pub fn set_offset(&mut self, offset: OffsetMode) {
        self.offset = offset;
        self.update_plain();
    }

    /// How rays spawned at hits leave the surface.
    pub fn offset(&self) -> OffsetMode {
        self.offset
    }

    /// Closest hit along `ray` in (0, ray.t_max), at `ray.time`.
    ///
    /// This, [`Geometry::occluded`], the sampler's draws and the light
    /// sample are always inlined into the integrators' loops: LLVM kept
    /// them out of line, and every call spilled the path's vector state (on
    /// x86-64 all vector registers are caller-saved). Profile-guided
    /// optimisation inlined them and ran 6-12% faster; inlining them by hand
    /// cut callgrind's count on a Cornell box path from 7374 to 6859
    /// instructions and gives most of that gain without a profile.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        self.intersect_as::<false>(ray)
    }

    /// [`Geometry::intersect`], where `PLAIN` promises [`Geometry::is_plain`]
    /// (checked once per path by the caller): then only the geometry at
    /// rest is traversed, and what masks, instances, moving objects and a
    /// fixed offset need stays out of the caller's loop. With it inline
    /// the path loop carried a second traversal (a moving object's) and
    /// spilled for it: the glossy room took 7.6% more instructions than
    /// before those features (docs/performance.md).
    #[inline(always)]
    pub fn intersect_as<const PLAIN: bool>(&self, ray: &Ray) -> Option<SurfaceHit> {
        if PLAIN {
            debug_assert!(self.plain);
            return self.intersect_static::<true>(ray);
        }
        let mut hit = match &self.masks {
            None => self.intersect_all(ray),
            Some(masks) => self.intersect_masked(ray, masks),
        };
        if let (OffsetMode::Fixed(_), Some(h)) = (self.offset, &mut hit) {
            h.error = self.offset.spawn_error(h.error, h.normal);
        }
        if let (Some(blends), Some(h)) = (&self.blends, &mut hit) {
            h.material = blends.material_at(h, || self.uv(h));
        }
        hit
    }

    #[inline(always)]
    fn intersect_all(&self, ray: &Ray) -> Option<SurfaceHit> {
        let mut best = self.intersect_static::<true>(ray);
        if !self.instances.is_empty() {
            best = self.instances.closest(ray, best);
        }
        if self.moving.is_empty() {
            return best;
        }
        for m in &self.moving {
            let shift = ray.time * m.velocity;
            let t_max = best.map_or(ray.t_max, |h| h.t);
            let local = Ray {
                origin: ray.origin - shift,
                t_max,
                ..*ray
            };
            if let Some(mut hit) = m.geometry.intersect_static::<false>(&local) {
                hit.point += shift;
                // Its arrays are the object's own: interpolation reads none.
                hit.primitive |= MOVING_PRIMITIVE;
                // The translation back adds one rounding per component.
                hit.error += gamma(1) * hit.point.abs();
                best = Some(hit);
            }
        }
        best
    }

    /// Sets the materials' opacities: from now on every query passes
    /// through the hits their masks drop. Scenes without a mask keep none.
    pub fn set_masks(&mut self, masks: Masks) {
        self.masks = Masks::any(&masks.by_material).then(|| Arc::new(masks));
        self.update_plain();
    }

    /// Sets the materials' blends: from now on a hit on a blend takes one
    /// of its two materials. Scenes without a blend keep none.
    pub fn set_blends(&mut self, blends: Blends) {
        self.blends = Blends::any(&blends.by_material).then(|| Arc::new(blends));
        self.update_plain();
    }

    /// True when some surface has an opacity mask.
    pub fn has_masks(&self) -> bool {
        self.masks.is_some()
    }

    /// Closest hit among the geometry at rest.
    #[inline(always)]
    fn intersect_static<const LANES: bool>(&self, ray: &Ray) -> Option<SurfaceHit> {
        let mut best_t = ray.t_max;
        let (mut best_tri, mut best_b1, mut best_b2) = (u32::MAX, 0.0, 0.0);
        let mut vertices = None;
        match &self.tri_index {
            TriangleIndex::Empty => {}
            TriangleIndex::Soup(soup) => {
                if let Some((i, t, b1, b2)) = soup.closest(ray, best_t, &self.tri_vertices) {
                    (best_tri, best_t, best_b1, best_b2) = (i as u32, t, b1, b2);
                }
            }
            TriangleIndex::Bvh(bvh) => {
                let found = |i: usize| self.prefetch_shading(i);
                if let Some(((i, t, b1, b2), v)) =
                    bvh.closest(ray, best_t, &self.tri_vertices, found)
                {
                    (best_tri, best_t, best_b1, best_b2) = (i as u32, t, b1, b2);
                    vertices = Some(v);
                }
            }
        }
        let mut best_sphere = u32::MAX;
        if LANES && self.sphere_bvh.is_none() && !self.sphere_lanes.is_empty() {
            for lanes in &self.sphere_lanes {
                if let Some((i, t)) = lanes.closest(ray.origin, ray.direction, best_t) {
                    best_t = t;
                    best_sphere = i as u32;
                }
            }
        } else if self.sphere_bvh.is_none() {
            for (i, s) in self.spheres.iter().enumerate() {
                if let Some(t) =
                    intersect_sphere(ray.origin, ray.direction, s.center, s.radius, best_t)
                {
                    best_t = t;
                    best_sphere = i as u32;
                }
            }
        } else if let Some(bvh) = &self.sphere_bvh {
            let mut hit = obvhs::ray::RayHit::none();
            bvh.ray_traverse(bvh_ray(ray, best_t), &mut hit, |r, id| {
                let s = &self.spheres[id];
                intersect_sphere(r.origin, r.direction, s.center, s.radius, r.tmax)
                    .unwrap_or(f32::INFINITY)
            });
            if hit.t < best_t {
                best_t = hit.t;
                best_sphere = hit.primitive_id;
            }
        }
        if best_sphere != u32::MAX {
            let s = &self.spheres[best_sphere as usize];
            let normal = (ray.at(best_t) - s.center).normalize();
            let local = s.radius * normal;
            let point = s.center + local;
            return Some(SurfaceHit {
                t: best_t,
                point,
                barycentric: Vec2::ZERO,
                // Re-projection onto the sphere (gamma(5), pbrt-v4 6.8.5) plus
                // the translation by the centre.
                error: gamma(5) * local.abs() + gamma(1) * point.abs(),
                normal,
                material: s.material,
                light: s.light,
                time: ray.time,
                primitive: self.tri_vertices.len() as u32 + best_sphere,
                instance: NO_INSTANCE,
            });
        }
        if best_tri == u32::MAX {
            return None;
        }
        let i = best_tri as usize;
        let vertices = vertices.unwrap_or_else(|| self.tri_vertices[i]);
        Some(self.triangle_hit(ray, best_tri, vertices, best_t, best_b1, best_b2))
    }

    /// The hit record of triangle `index` at (t, b1, b2).
    #[inline(always)]
    fn triangle_hit(
        &self,
        ray: &Ray,
        index: u32,
        [p0, p1, p2]: [Vec3A; 3],
        best_t: f32,
        best_b1: f32,
        best_b2: f32,
    ) -> SurfaceHit {
        let shading = self.tri_shading[index as usize];
        let b0 = 1.0 - best_b1 - best_b2;
        let point = b0 * p0 + best_b1 * p1 + best_b2 * p2;
        SurfaceHit {
            t: best_t,
            point,
            barycentric: Vec2::new(best_b1, best_b2),
            // Barycentric interpolation (pbrt-v4 6.8.4).
            error: gamma(7) * ((b0 * p0).abs() + (best_b1 * p1).abs() + (best_b2 * p2).abs()),
            normal: shading.normal,
            material: shading.material,
            light: shading.light,
            time: ray.time,
            primitive: index,
            instance: NO_INSTANCE,
        }
    }

    /// True when anything blocks `ray` in (0, ray.t_max) at `ray.time`
    /// (shadow rays).
    #[inline(always)]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_as::<false>(ray)
    }

    /// [`Geometry::occluded`], where `PLAIN` promises [`Geometry::is_plain`]
    /// as for [`Geometry::intersect_as`].
    #[inline(always)]
    pub fn occluded_as<const PLAIN: bool>(&self, ray: &Ray) -> bool {
        if PLAIN {
            debug_assert!(self.plain);
            return self.occluded_static::<true>(ray);
        }
        if let Some(masks) = &self.masks {
            return self.occluded_masked(ray, masks);
        }
        self.occluded_static::<true>(ray) || self.occluded_elsewhere(ray)
    }

    /// Occlusion by instances and moving objects.
    #[inline(always)]
    fn occluded_elsewhere(&self, ray: &Ray) -> bool {
        (!self.instances.is_empty() && self.instances.any(ray))
            || self.moving.iter().any(|m| {
                m.geometry.occluded_static::<false>(&Ray {
                    origin: ray.origin - ray.time * m.velocity,
                    ..*ray
                })
            })
    }

    #[inline(always)]
    fn occluded_static<const LANES: bool>(&self, ray: &Ray) -> bool {
        self.triangle_blocks(ray, &mut |_| true) || self.spheres_block::<LANES>(ray)
    }

    /// True when a triangle at rest that `accept` (called with its index)
    /// accepts is hit in (0, ray.t_max).
    #[inline(always)]
    fn triangle_blocks(&self, ray: &Ray, accept: &mut impl FnMut(usize) -> bool) -> bool {
        let (vertices, t_max) = (&self.tri_vertices, ray.t_max);
        match &self.tri_index {
            TriangleIndex::Empty => false,
            TriangleIndex::Soup(soup) => soup.any_where(ray, t_max, vertices, accept),
            TriangleIndex::Bvh(bvh) => bvh.any_where(ray, t_max, vertices, accept),
        }
    }

    /// True when a sphere at rest is hit in (0, ray.t_max).
    #[inline(always)]
    fn spheres_block<const LANES: bool>(&self, ray: &Ray) -> bool {
        if LANES && self.sphere_bvh.is_none() && !self.sphere_lanes.is_empty() {
            return self
                .sphere_lanes
                .iter()
                .any(|lanes| lanes.any(ray.origin, ray.direction, ray.t_max));
        }
        if self.sphere_bvh.is_none() {
            return self.spheres.iter().any(|s| {
                intersect_sphere(ray.origin, ray.direction, s.center, s.radius, ray.t_max).is_some()
            });
        }
        if let Some(bvh) = &self.sphere_bvh {
            let miss = bvh.ray_traverse_miss(bvh_ray(ray, ray.t_max), |r, id| {
                let s = &self.spheres[id];
                intersect_sphere(r.origin, r.direction, s.center, s.radius, r.tmax)
                    .unwrap_or(f32::INFINITY)
            });
            if !miss {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests;
