//! Building the geometry's acceleration structures: obvhs builds the
//! binary tree (PLOC, then reinsertion), `wide_bvh.rs` collapses it to
//! 8-wide nodes; small meshes stay a soup; many spheres get a CWBVH.

use super::*;
use glam::Vec3;
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance};
use rayon::prelude::*;

/// obvhs's `medium_build` for `count` primitives; above
/// [`LARGE_TREE`], with `fast_build`'s shorter PLOC search and at most
/// [`REINSERTION_MAX_CANDIDATES`] reinsertions a batch. On the kitchen
/// (1.05M triangles) and a million-triangle sphere the trees' SAH cost
/// stayed where it was and the build took 0.15 s less; smaller trees keep
/// the preset, as the living-room rendered no faster with the shorter
/// search (docs/performance.md, "Loading and memory").
fn build_params(count: usize) -> BvhBuildParams {
    let medium = BvhBuildParams::medium_build();
    if count < LARGE_TREE {
        return medium;
    }
    BvhBuildParams {
        ploc_search_distance: PlocSearchDistance::Low,
        search_depth_threshold: 2,
        reinsertion_batch_ratio: (medium.reinsertion_batch_ratio)
            .min(REINSERTION_MAX_CANDIDATES / (2 * count) as f32),
        ..medium
    }
}

/// Primitives from which a tree is built with [`build_params`]'s cheaper
/// settings.
const LARGE_TREE: usize = 500_000;

/// Reinsertion's candidates per batch at most, for a large tree (a binary
/// tree has about two nodes a primitive).
const REINSERTION_MAX_CANDIDATES: f32 = 40_000.0;

/// obvhs traverses a CWBVH with a stack of this many entries; a deeper tree
/// would silently lose nodes (its push saturates).
const CWBVH_STACK_DEPTH: u32 = 32;

/// Levels of the CWBVH below `node` (1 for a node with only leaves).
fn cwbvh_depth(bvh: &CwBvh, node: usize) -> u32 {
    let n = &bvh.nodes[node];
    let deepest_child = (0..8)
        .filter(|&c| !n.is_child_empty(c) && !n.is_leaf(c))
        .map(|c| cwbvh_depth(bvh, n.child_node_index(c) as usize))
        .max()
        .unwrap_or(0);
    1 + deepest_child
}

/// obvhs's binary BVH over `prims`: PLOC, then reinsertion.
pub(super) fn build_bvh2<T: obvhs::Boundable>(prims: &[T]) -> Bvh2 {
    build_bvh2_with(prims, build_params(prims.len()))
}

/// [`build_bvh2`] with `params`' PLOC search and reinsertion.
fn build_bvh2_with<T: obvhs::Boundable>(prims: &[T], params: BvhBuildParams) -> Bvh2 {
    // `new`, not `with_capacity`: that sizes the Morton codes' buffer for
    // 128-bit codes, twice what the 64-bit sort uses.
    let mut bvh2 = PlocBuilder::new().build(
        params.ploc_search_distance,
        prims,
        (0..prims.len() as u32).collect::<Vec<_>>(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// The triangles' 8-wide BVH and the order to store them in, or None when
/// the tree would be deeper than its traversal stack (many nearly coincident
/// triangles, found by fuzzing, make PLOC produce chains).
#[cfg(test)]
pub(super) fn build_wide_bvh(triangles: &[[Vec3A; 3]]) -> Option<(WideBvh, Vec<usize>)> {
    let aabbs: Vec<Aabb> = triangles.iter().map(|t| Aabb::from_points(t)).collect();
    build_wide_bvh_with(&aabbs, &|i| triangles[i])
}

/// [`build_wide_bvh`] over `prims` (triangle i bounded by `prims[i]`, its
/// corners `vertices(i)`), so that a caller need not copy them first.
pub(super) fn build_wide_bvh_with<T: obvhs::Boundable>(
    prims: &[T],
    vertices: &(dyn Fn(usize) -> [Vec3A; 3] + Sync),
) -> Option<(WideBvh, Vec<usize>)> {
    let bvh2 = build_bvh2(prims);
    WideBvh::from_bvh2(&bvh2, prims.len(), vertices)
}

/// A CWBVH over `aabbs` (spheres), or None when it would be too deep to
/// traverse. The steps of obvhs's `build_cwbvh`, without its debug-build
/// validation, which panics on such a tree where this returns None.
pub(super) fn build_shallow_cwbvh(aabbs: &[Aabb]) -> Option<CwBvh> {
    let params = build_params(aabbs.len());
    let bvh2 = build_bvh2(aabbs);
    let bvh = bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false);
    (bvh.nodes.is_empty() || cwbvh_depth(&bvh, 0) < CWBVH_STACK_DEPTH).then_some(bvh)
}

impl Geometry {
    /// Builds the BVHs and stores the triangles in leaf order.
    pub fn build(triangles: &[TriangleInput], spheres: Vec<Sphere>) -> Self {
        Self::build_with(triangles, spheres, AccelChoice::Auto)
    }

    /// Builds with a chosen triangle index (for tests and benchmarks).
    pub fn build_with(
        triangles: &[TriangleInput],
        spheres: Vec<Sphere>,
        choice: AccelChoice,
    ) -> Self {
        Self::build_full(triangles.to_vec(), spheres, choice, false)
    }

    /// Builds, keeping texture coordinates for hits when `keep_uvs` (a
    /// material reads a texture): only then do they cost memory and time.
    /// The triangles are moved into the geometry's arrays, not copied.
    pub fn build_full(
        triangles: Vec<TriangleInput>,
        spheres: Vec<Sphere>,
        choice: AccelChoice,
        keep_uvs: bool,
    ) -> Self {
        Self::build_keeping(triangles, spheres, choice, keep_uvs, false)
    }

    /// [`Geometry::build_full`] without the degenerate triangles
    /// ([`TriangleInput::is_degenerate`]), left out as the triangles are
    /// packed: a scene's loader counts them, and filtering them first
    /// copied a million triangles on one core.
    pub fn build_without_degenerate(
        triangles: Vec<TriangleInput>,
        spheres: Vec<Sphere>,
        keep_uvs: bool,
    ) -> Self {
        Self::build_keeping(triangles, spheres, AccelChoice::Auto, keep_uvs, true)
    }

    fn build_keeping(
        triangles: Vec<TriangleInput>,
        spheres: Vec<Sphere>,
        choice: AccelChoice,
        keep_uvs: bool,
        drop_degenerate: bool,
    ) -> Self {
        let mut geometry = Geometry {
            keep_uvs,
            keep_normals: triangles.par_iter().any(|t| t.normals.is_some()),
            ..Geometry::default()
        };
        geometry.update_plain();
        let use_soup = match choice {
            AccelChoice::Auto => triangles.len() <= SOUP_MAX_TRIANGLES,
            AccelChoice::Bvh => false,
            AccelChoice::Soup => true,
        };
        geometry.store_triangles(triangles, use_soup, drop_degenerate);
        if spheres.len() <= SPHERE_LIST_MAX {
            if spheres.len() >= SPHERE_LANES_MIN {
                geometry.sphere_lanes = SphereLanes::pack(&spheres);
            }
            geometry.spheres = spheres;
        } else {
            let aabbs: Vec<Aabb> = spheres
                .iter()
                .map(|s| {
                    Aabb::new(
                        s.center - Vec3A::splat(s.radius),
                        s.center + Vec3A::splat(s.radius),
                    )
                })
                .collect();
            match build_shallow_cwbvh(&aabbs) {
                Some(bvh) => {
                    geometry.spheres = bvh
                        .primitive_indices
                        .iter()
                        .map(|&i| spheres[i as usize])
                        .collect();
                    geometry.sphere_bvh = Some(bvh);
                }
                None => {
                    geometry.sphere_lanes = SphereLanes::pack(&spheres);
                    geometry.spheres = spheres;
                    geometry.bvh_too_deep = true;
                }
            }
        }
        geometry
    }

    /// Stores the triangles as a soup or under a BVH; returns per stored
    /// triangle its index in `triangles` (without the degenerate ones when
    /// `drop_degenerate`).
    fn store_triangles(
        &mut self,
        triangles: Vec<TriangleInput>,
        use_soup: bool,
        drop_degenerate: bool,
    ) -> Vec<usize> {
        let packed = Packed::new(triangles, self.keep_uvs, self.keep_normals, drop_degenerate);
        if packed.corners.is_empty() {
            return Vec::new();
        }
        if !use_soup {
            let built = build_wide_bvh_with(&packed.corners, &|i| packed.corners[i].get());
            if let Some((bvh, order)) = built {
                self.tri_index = TriangleIndex::Bvh(bvh);
                self.store_in_order(packed, &order);
                return order;
            }
            // Correct at any depth, if slow: better than missed hits.
            self.bvh_too_deep = true;
        }
        let vertices: Vec<[Vec3A; 3]> = packed.corners.iter().map(Corners::get).collect();
        let order = TriangleSoup::order(&vertices);
        self.store_in_order(packed, &order);
        self.tri_index = TriangleIndex::Soup(TriangleSoup::new(&self.tri_vertices));
        order
    }

    /// A copy in which triangle `i` is replaced by `pieces[i]` where that
    /// is not empty: triangles within it (radiosity's discontinuity
    /// meshing), with its material, light, and texture coordinates and
    /// normals interpolated at their corners. Spheres, moving objects,
    /// masks and the offset mode are kept. Returns, per triangle of the
    /// copy, the triangle it comes from.
    pub fn with_pieces(&self, pieces: &[Vec<[Vec3A; 3]>]) -> (Geometry, Vec<u32>) {
        let mut inputs = Vec::with_capacity(self.tri_vertices.len());
        let mut origin = Vec::with_capacity(self.tri_vertices.len());
        for (i, v) in self.tri_vertices.iter().enumerate() {
            let material = self.tri_shading[i].material;
            let (uvs, normals) = (self.tri_uvs.get(i), self.tri_normals.get(i));
            match pieces.get(i).filter(|p| !p.is_empty()) {
                None => inputs.push(TriangleInput {
                    vertices: *v,
                    material,
                    uvs: uvs.copied(),
                    normals: normals.copied(),
                }),
                Some(parts) => {
                    let n = (v[1] - v[0]).cross(v[2] - v[0]);
                    let weights = |p: Vec3A| {
                        let inv = 1.0 / n.length_squared();
                        let b1 = (p - v[0]).cross(v[2] - v[0]).dot(n) * inv;
                        let b2 = (v[1] - v[0]).cross(p - v[0]).dot(n) * inv;
                        [1.0 - b1 - b2, b1, b2]
                    };
                    for part in parts {
                        let b = part.map(weights);
                        inputs.push(TriangleInput {
                            vertices: *part,
                            material,
                            uvs: uvs.map(|t| b.map(|w| w[0] * t[0] + w[1] * t[1] + w[2] * t[2])),
                            normals: normals.map(|t| {
                                b.map(|w| (w[0] * t[0] + w[1] * t[1] + w[2] * t[2]).normalize())
                            }),
                        });
                        origin.push(i as u32);
                    }
                    continue;
                }
            }
            origin.push(i as u32);
        }
        let mut geometry = Geometry {
            keep_uvs: self.keep_uvs,
            keep_normals: self.keep_normals,
            sphere_bvh: self.sphere_bvh.clone(),
            sphere_lanes: self.sphere_lanes.clone(),
            spheres: self.spheres.clone(),
            moving: self.moving.clone(),
            offset: self.offset,
            bvh_too_deep: self.bvh_too_deep,
            masks: self.masks.clone(),
            blends: self.blends.clone(),
            instances: self.instances.clone(),
            ..Geometry::default()
        };
        geometry.update_plain();
        let use_soup = inputs.len() <= SOUP_MAX_TRIANGLES;
        let order = geometry.store_triangles(inputs, use_soup, false);
        let from: Vec<u32> = order.iter().map(|&k| origin[k]).collect();
        for (slot, &old) in from.iter().enumerate() {
            geometry.tri_shading[slot].light = self.tri_shading[old as usize].light;
        }
        (geometry, from)
    }

    /// Places the prototypes: `placements` lists (prototype index, to
    /// world) pairs. A prototype holds triangles only, none of them a light
    /// (lights are sampled where they are), and every placement keeps
    /// orientation (a mirrored one flips the winding that the geometric
    /// normal follows): the loaders copy what breaks these rules.
    pub fn add_instances(&mut self, prototypes: Vec<Geometry>, placements: &[(u32, Affine3A)]) {
        debug_assert!(prototypes.iter().all(|p| {
            p.spheres.is_empty()
                && p.moving.is_empty()
                && p.instances.is_empty()
                && p.tri_shading.iter().all(|s| s.light == NO_LIGHT)
        }));
        debug_assert!(
            placements
                .iter()
                .all(|(_, m)| m.matrix3.determinant() > 0.0)
        );
        self.bvh_too_deep |= prototypes.iter().any(|p| p.bvh_too_deep);
        self.instances =
            instance::Instances::new(prototypes.into_iter().map(Arc::new).collect(), placements);
        self.update_plain();
    }

    /// Surface area of the triangles drawn, instances' included.
    pub fn triangle_area(&self) -> f32 {
        let own: f64 = self
            .tri_vertices
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length() as f64)
            .sum();
        (own + self.instances.area()) as f32
    }

    /// Number of instances.
    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// Triangles drawn: the geometry's own and every instance's.
    pub fn triangles_drawn(&self) -> usize {
        self.tri_vertices.len() + self.instances.triangles_drawn()
    }

    /// A copy in which every instance's triangles are the geometry's own,
    /// in world space: for what reads triangles one by one (radiosity's
    /// patches, the shortcuts' occluder lists). Lights keep their ids.
    pub fn flattened(&self) -> Geometry {
        if self.instances.is_empty() {
            return self.clone();
        }
        let (mut inputs, mut lights) = (Vec::new(), Vec::new());
        for (i, v) in self.tri_vertices.iter().enumerate() {
            inputs.push(TriangleInput {
                vertices: *v,
                material: self.tri_shading[i].material,
                uvs: self.tri_uvs.get(i).copied(),
                normals: self.tri_normals.get(i).copied(),
            });
            lights.push(self.tri_shading[i].light);
        }
        inputs.extend(self.instances.flattened());
        lights.resize(inputs.len(), NO_LIGHT);
        let mut geometry = Geometry {
            keep_uvs: self.keep_uvs,
            keep_normals: inputs.iter().any(|t| t.normals.is_some()),
            sphere_bvh: self.sphere_bvh.clone(),
            sphere_lanes: self.sphere_lanes.clone(),
            spheres: self.spheres.clone(),
            moving: self.moving.clone(),
            offset: self.offset,
            masks: self.masks.clone(),
            ..Geometry::default()
        };
        geometry.update_plain();
        let use_soup = inputs.len() <= SOUP_MAX_TRIANGLES;
        let order = geometry.store_triangles(inputs, use_soup, false);
        geometry.bvh_too_deep |= self.bvh_too_deep;
        for (slot, &k) in order.iter().enumerate() {
            geometry.tri_shading[slot].light = lights[k];
        }
        geometry
    }

    /// Stores `packed`'s triangle `order[i]` as triangle i, one array at
    /// a time on every core, each source array dropped once read and its
    /// pages returned (from the heap during a load, [`crate::heap`], they
    /// would otherwise stay through the peak).
    fn store_in_order(&mut self, packed: Packed, order: &[usize]) {
        let Packed {
            corners,
            materials,
            uvs,
            normals,
        } = packed;
        // A trim walks the arenas: worth it only for arrays of megabytes.
        let large = order.len() >= 1 << 16;
        let release = || {
            if large {
                crate::heap::release_free_pages();
            }
        };
        let order = || order.par_iter().with_min_len(4096);
        self.tri_vertices = order().map(|&i| corners[i].get()).collect();
        drop(corners);
        release();
        self.tri_shading = (order().zip(&self.tri_vertices))
            .map(|(&i, v)| TriangleShading::new(v, materials[i]))
            .collect();
        drop(materials);
        release();
        if self.keep_uvs {
            self.tri_uvs = order().map(|&i| uvs[i]).collect();
        }
        drop(uvs);
        release();
        if self.keep_normals {
            self.tri_normals = order().map(|&i| normals[i].map(Vec3A::from)).collect();
        }
    }
}

/// A triangle's corners unaligned: 36 bytes, not 48.
#[derive(Clone, Copy)]
struct Corners([Vec3; 3]);

impl Corners {
    fn get(&self) -> [Vec3A; 3] {
        self.0.map(Vec3A::from)
    }
}

/// Bounded where they lie: an array of boxes beside them was 32 bytes a
/// triangle more at the build's peak.
impl obvhs::Boundable for Corners {
    fn aabb(&self) -> Aabb {
        Aabb::from_points(&self.get())
    }
}

/// The triangles in input order while the BVH is built, 100 bytes a
/// triangle with normals and uv against `TriangleInput`'s 144 (on a
/// million triangles the build's peak; docs/performance.md, "Loading").
struct Packed {
    corners: Vec<Corners>,
    materials: Vec<u32>,
    /// Empty unless kept.
    uvs: Vec<[Vec2; 3]>,
    /// Empty unless kept; a triangle without gets its geometric normal.
    normals: Vec<[Vec3; 3]>,
}

impl Packed {
    /// Moves `triangles` in from the back a block at a time, the list
    /// shrinking behind (glibc shrinks a large block's mapping in place),
    /// so that the two are never held whole together; leaves the
    /// degenerate ones out when `drop_degenerate`.
    fn new(
        mut triangles: Vec<TriangleInput>,
        keep_uvs: bool,
        keep_normals: bool,
        drop_degenerate: bool,
    ) -> Packed {
        let count = triangles.len();
        let kept = |keep: bool| if keep { count } else { 0 };
        let mut packed = Packed {
            corners: Vec::with_capacity(count),
            materials: Vec::with_capacity(count),
            uvs: Vec::with_capacity(kept(keep_uvs)),
            normals: Vec::with_capacity(kept(keep_normals)),
        };
        const BLOCK: usize = 1 << 16;
        while !triangles.is_empty() {
            let rest = triangles.len().saturating_sub(BLOCK);
            let here = &triangles[rest..];
            // The block's triangles to keep, back to front.
            let kept: Vec<u32> = match drop_degenerate {
                true => (0..here.len() as u32)
                    .into_par_iter()
                    .rev()
                    .filter(|&k| !here[k as usize].is_degenerate())
                    .collect(),
                false => (0..here.len() as u32).rev().collect(),
            };
            // On every core: the new arrays' first touch (page faults) was
            // most of the packing's time.
            let block = || (kept.par_iter().with_min_len(1 << 10)).map(|&k| &here[k as usize]);
            packed
                .corners
                .par_extend(block().map(|t| Corners(t.vertices.map(Vec3::from))));
            packed.materials.par_extend(block().map(|t| t.material));
            if keep_uvs {
                let barycentric = [Vec2::ZERO, Vec2::X, Vec2::Y];
                packed
                    .uvs
                    .par_extend(block().map(|t| t.uvs.unwrap_or(barycentric)));
            }
            if keep_normals {
                packed.normals.par_extend(block().map(|t| {
                    let geometric = || [TriangleShading::new(&t.vertices, 0).normal; 3];
                    t.normals.unwrap_or_else(geometric).map(Vec3::from)
                }));
            }
            triangles.truncate(rest);
            triangles.shrink_to_fit();
        }
        packed.corners.reverse();
        packed.materials.reverse();
        packed.uvs.reverse();
        packed.normals.reverse();
        packed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SAH cost of a binary tree: its nodes' areas relative to the root's,
    /// a leaf's counted once for each of its primitives.
    fn sah(bvh: &Bvh2) -> f64 {
        let root = f64::from(bvh.nodes[0].aabb().half_area());
        let weight = |n: &obvhs::bvh2::node::Bvh2Node| match n.is_leaf() {
            true => f64::from(n.prim_count),
            false => 1.0,
        };
        (bvh.nodes.iter())
            .map(|n| f64::from(n.aabb().half_area()) * weight(n))
            .sum::<f64>()
            / root
    }

    /// A large tree's cheaper settings build as good a tree as the preset,
    /// on 600 000 triangles of a sphere in a box (the kitchen's and a
    /// million-triangle sphere's costs moved by under 0.3%): a tree 1%
    /// worse would fail.
    #[test]
    fn a_large_trees_cheaper_build_costs_no_sah() {
        let (rings, segments) = (400, 750);
        let point = |i: usize, j: usize| {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            Vec3A::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            )
        };
        let mut aabbs = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let quad = [
                    point(i, j),
                    point(i + 1, j),
                    point(i + 1, j + 1),
                    point(i, j + 1),
                ];
                aabbs.push(Aabb::from_points(&[quad[0], quad[1], quad[2]]));
                aabbs.push(Aabb::from_points(&[quad[0], quad[2], quad[3]]));
            }
        }
        // The box's six walls.
        for (axis, side) in (0..3).flat_map(|axis| [(axis, -3.0), (axis, 3.0)]) {
            let (mut lo, mut hi) = (Vec3A::splat(-3.0), Vec3A::splat(3.0));
            (lo[axis], hi[axis]) = (side, side);
            aabbs.push(Aabb::new(lo, hi));
        }
        assert!(aabbs.len() >= LARGE_TREE);
        let cheaper = sah(&build_bvh2(&aabbs));
        let preset = sah(&build_bvh2_with(&aabbs, BvhBuildParams::medium_build()));
        assert!(
            cheaper < 1.01 * preset,
            "SAH {cheaper} against the preset's {preset}"
        );
    }
}
