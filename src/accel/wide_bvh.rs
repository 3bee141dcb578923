//! An 8-wide BVH traversed on the CPU: one SIMD slab test decides which of a
//! node's eight children a ray enters, and leaves hold up to eight triangles
//! tested as one block (`block.rs`).
//!
//! The tree comes from obvhs's binary BVH (PLOC and reinsertion); it is
//! collapsed here because obvhs's own 8-wide layout (CWBVH, Ylitie et al.
//! 2017) is made for GPUs: quantised child boxes decoded per node and leaves
//! of at most three triangles tested one at a time. `cargo bench --bench
//! micro -- rays_100k`, one thread: incoherent closest hit 1.55 -> 2.70 M
//! rays/s, any hit 2.56 -> 4.32 M against obvhs's CWBVH traversal.

use super::block::{Axes, Block, Boxes8, LANES, SlabAxes, TriangleHit};
use crate::math::Ray;
use glam::Vec3A;

mod collapse;

/// Traversal stack entries: a node pushes at most 7 children and pops one,
/// so a tree of depth d needs at most 7 d + 1.
const STACK_SIZE: usize = 128;

/// Deepest tree the stack can hold.
const MAX_DEPTH: usize = (STACK_SIZE - 1) / (LANES - 1);

/// Largest subtree made into one leaf block.
const LEAF_MAX: usize = LANES;

/// A child reference: a node index, or a leaf block index with the top bit set.
const LEAF_BIT: u32 = 1 << 31;

/// Aligned to cache lines: 256 bytes are then exactly four lines, not five
/// half-used ones (a `Vec` of 32-byte-aligned nodes may start mid-line).
#[derive(Clone, Debug)]
#[repr(align(64))]
struct Node {
    boxes: Boxes8,
    children: [u32; LANES],
}

/// Nodes and leaf blocks of an 8-wide BVH over triangles.
#[derive(Clone, Debug)]
pub struct WideBvh {
    nodes: Vec<Node>,
    leaves: Vec<Block>,
    /// The root when it is a single leaf (meshes of up to 8 triangles).
    root: u32,
}

impl WideBvh {
    /// Bytes of nodes and leaves.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..]) + std::mem::size_of_val(&self.leaves[..])
    }

    /// Closest hit in (0, t_max), front to back, with the hit triangle's
    /// vertices. `found` hears of each triangle that becomes the closest
    /// so far (to ask for what the caller reads at the hit while the
    /// traversal goes on).
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        triangles: &[[Vec3A; 3]],
        mut found: impl FnMut(usize),
    ) -> Option<(TriangleHit, [Vec3A; 3])> {
        let axes = Axes::new(ray);
        let slabs = SlabAxes::new(ray);
        let mut best = None;
        let mut best_t = t_max;
        let mut best_leaf = 0;
        let mut stack = [(0u32, 0.0f32); STACK_SIZE];
        stack[0] = (self.root, 0.0);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (child, t_near) = stack[top];
            if t_near > best_t {
                continue;
            }
            if child & LEAF_BIT != 0 {
                let leaf = (child & !LEAF_BIT) as usize;
                // A changed triangle index, not a smaller t: the scalar
                // retest of edge cases may return a hit at exactly best_t.
                let before = best.map(|h: TriangleHit| h.0);
                self.leaves[leaf].closest(&axes, ray, triangles, &mut best_t, &mut best);
                if let Some(hit) = best
                    && Some(hit.0) != before
                {
                    best_leaf = leaf;
                    found(hit.0);
                }
                continue;
            }
            let node = &self.nodes[child as usize];
            let (mut reached, distances) = slabs.reaches(&node.boxes, best_t);
            // Push the reached children farthest first, so that the nearest
            // is visited next and its hit culls the others.
            let start = top;
            while reached != 0 {
                let lane = reached.trailing_zeros() as usize;
                reached &= reached - 1;
                let entry = (node.children[lane], distances[lane]);
                self.prefetch(entry.0);
                let mut k = top;
                while k > start && stack[k - 1].1 < entry.1 {
                    stack[k] = stack[k - 1];
                    k -= 1;
                }
                stack[k] = entry;
                top += 1;
            }
        }
        best.map(|hit| {
            let leaf = &self.leaves[best_leaf];
            (hit, leaf.vertices(hit.0 - leaf.first as usize))
        })
    }

    /// Asks for the cache lines of a child the ray will visit, as soon as
    /// the slab test finds it: on large meshes the traversal waits mostly
    /// on the first loads of nodes and leaf blocks, and several children's
    /// loads can then be in flight at once.
    #[inline(always)]
    fn prefetch(&self, child: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let (start, bytes) = if child & LEAF_BIT != 0 {
                let leaf = &self.leaves[(child & !LEAF_BIT) as usize];
                (
                    leaf as *const Block as *const i8,
                    std::mem::size_of::<Block>(),
                )
            } else {
                let node = &self.nodes[child as usize];
                (
                    node as *const Node as *const i8,
                    std::mem::size_of::<Node>(),
                )
            };
            for offset in (0..bytes).step_by(64) {
                // SAFETY: prefetching is a hint; it never faults, and the
                // addresses lie inside one element of a live vector.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.add(offset)) };
            }
        }
    }

    /// True when a triangle that `accept` (called with its index) accepts
    /// is hit in (0, t_max).
    #[inline(always)]
    pub fn any_where(
        &self,
        ray: &Ray,
        t_max: f32,
        triangles: &[[Vec3A; 3]],
        accept: &mut impl FnMut(usize) -> bool,
    ) -> bool {
        let axes = Axes::new(ray);
        let slabs = SlabAxes::new(ray);
        let mut stack = [0u32; STACK_SIZE];
        stack[0] = self.root;
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let child = stack[top];
            if child & LEAF_BIT != 0 {
                let leaf = &self.leaves[(child & !LEAF_BIT) as usize];
                if leaf.any_where(&axes, ray, triangles, t_max, accept) {
                    return true;
                }
                continue;
            }
            let node = &self.nodes[child as usize];
            let (mut reached, _) = slabs.reaches(&node.boxes, t_max);
            while reached != 0 {
                let lane = reached.trailing_zeros() as usize;
                reached &= reached - 1;
                stack[top] = node.children[lane];
                self.prefetch(stack[top]);
                top += 1;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::build::{build_bvh2, build_wide_bvh};
    use crate::accel::triangle::ShearedRay;
    use crate::sampling::hash::{hash_combine, to_unit_float};
    use obvhs::aabb::Aabb;

    /// Brute force over every triangle: the nearest t, or None.
    fn nearest(ray: &Ray, triangles: &[[Vec3A; 3]]) -> Option<f32> {
        let sheared = ShearedRay::new(ray);
        let mut best = f32::INFINITY;
        for tri in triangles {
            if let Some((t, _, _)) = sheared.intersect(tri, best) {
                best = t;
            }
        }
        best.is_finite().then_some(best)
    }

    fn check_against_brute_force(input: &[[Vec3A; 3]], rays: impl Iterator<Item = Ray>) {
        let (bvh, order) = build_wide_bvh(input).expect("shallow tree");
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(
            sorted,
            (0..input.len()).collect::<Vec<_>>(),
            "a permutation"
        );
        let triangles: Vec<[Vec3A; 3]> = order.iter().map(|&i| input[i]).collect();
        let mut hits = 0;
        for (i, ray) in rays.enumerate() {
            let expected = nearest(&ray, &triangles);
            let found = bvh.closest(&ray, f32::INFINITY, &triangles, |_| {});
            assert_eq!(found.map(|h| h.0.1), expected, "ray {i}");
            if let Some(((index, t, _, _), vertices)) = found {
                assert_eq!(vertices, triangles[index], "ray {i}");
                // The reported triangle is hit at the reported t.
                let own = ShearedRay::new(&ray).intersect(&triangles[index], f32::INFINITY);
                assert_eq!(own.map(|h| h.0), Some(t), "ray {i}");
                hits += 1;
            }
            assert_eq!(
                bvh.any_where(&ray, f32::INFINITY, &triangles, &mut |_| true),
                expected.is_some()
            );
            if let Some(t) = expected {
                // Nothing is nearer than the nearest hit.
                assert!(
                    !bvh.any_where(&ray, t * 0.999, &triangles, &mut |_| true),
                    "ray {i}"
                );
            }
        }
        assert!(hits > 100, "the rays must exercise hits ({hits})");
    }

    #[test]
    fn agrees_with_brute_force_on_random_triangles() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let input: Vec<[Vec3A; 3]> = (0..3000u64)
            .map(|i| {
                let centre = Vec3A::new(u(1, i), u(2, i), u(3, i)) * 2.0 - Vec3A::ONE;
                let size = if i % 100 == 0 { 0.8 } else { 0.05 };
                let p = |k| centre + (Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) - 0.5) * size;
                [p(10), p(20), p(30)]
            })
            .collect();
        let rays = (0..4000u64).map(|i| {
            let origin = Vec3A::new(u(4, i), u(5, i), u(6, i)) * 3.0 - Vec3A::splat(1.5);
            let direction = Vec3A::new(u(7, i), u(8, i), u(9, i)) * 2.0 - Vec3A::ONE;
            Ray::new(origin, direction.normalize())
        });
        check_against_brute_force(&input, rays);
    }

    /// A grid of axis-aligned unit squares and rays with zero direction
    /// components starting on the grid's planes: the slab test's NaN case.
    #[test]
    fn axis_aligned_grid_with_axis_parallel_rays() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let mut input = Vec::new();
        for axis in 0..3 {
            for layer in 0..4 {
                for a in 0..4 {
                    for b in 0..4 {
                        let corner = |da: f32, db: f32| {
                            let mut p = Vec3A::splat(layer as f32);
                            p[(axis + 1) % 3] = a as f32 + da;
                            p[(axis + 2) % 3] = b as f32 + db;
                            p
                        };
                        input.push([corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0)]);
                        input.push([corner(0.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)]);
                    }
                }
            }
        }
        let grid = |v: f32| (v * 8.0).round() / 2.0 - 0.5;
        let rays = (0..6000u64).filter_map(|i| {
            let origin = Vec3A::new(grid(u(1, i)), grid(u(2, i)), grid(u(3, i)));
            let mut direction = Vec3A::new(u(4, i), u(5, i), u(6, i)) * 2.0 - Vec3A::ONE;
            for axis in 0..3 {
                if u(7 + axis as u64, i) < 0.4 {
                    direction[axis] = 0.0;
                }
            }
            (direction != Vec3A::ZERO).then(|| Ray::new(origin, direction.normalize()))
        });
        check_against_brute_force(&input, rays);
    }

    #[test]
    fn leaves_hold_up_to_eight_and_nodes_are_wide() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let input: Vec<[Vec3A; 3]> = (0..1000u64)
            .map(|i| {
                let c = Vec3A::new(u(1, i), u(2, i), u(3, i));
                [c, c + Vec3A::X * 0.01, c + Vec3A::Y * 0.01]
            })
            .collect();
        let aabbs: Vec<Aabb> = input.iter().map(|t| Aabb::from_points(t)).collect();
        let (bvh, _) = WideBvh::from_bvh2(&build_bvh2(&aabbs), input.len(), &|i| input[i]).unwrap();
        // Collapsing makes far fewer nodes than a binary tree's n - 1.
        assert!(bvh.nodes.len() < 1000 / 4, "{} nodes", bvh.nodes.len());
        assert!(bvh.leaves.len() < 1000 / 2, "{} leaves", bvh.leaves.len());
    }
}
