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
use obvhs::bvh2::Bvh2;

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
    /// Collapses `bvh2` (built over `count` triangles, triangle i's
    /// corners `vertices(i)`). Returns the tree and the order in which the
    /// caller must store the triangles (tree triangle i is triangle
    /// `order[i]`), or None when the tree would be deeper than the
    /// traversal stack allows.
    pub fn from_bvh2(
        bvh2: &Bvh2,
        count: usize,
        vertices: &dyn Fn(usize) -> [Vec3A; 3],
    ) -> Option<(Self, Vec<usize>)> {
        if bvh2.nodes.is_empty() {
            return None;
        }
        let mut builder = Builder {
            bvh2,
            counts: subtree_counts(bvh2),
            vertices,
            // Leaves hold 5–6 triangles and nodes 3–4 leaves on Bitterli's
            // interiors: reserved above that, the arrays are not copied
            // and faulted in again at each doubling, and the address
            // space reserved costs no memory until it is written.
            nodes: Vec::with_capacity(count / 12 + 1),
            leaves: Vec::with_capacity(count / 4 + 1),
            order: Vec::with_capacity(count),
            scratch: Vec::with_capacity(LEAF_MAX),
        };
        let root = builder.collapse(0, 1)?;
        // Not shrunk: the unused capacity was never written, so it holds no
        // memory, and shrinking these cache-aligned arrays would copy them.
        let Builder {
            nodes,
            leaves,
            order,
            ..
        } = builder;
        Some((
            WideBvh {
                nodes,
                leaves,
                root,
            },
            order,
        ))
    }

    /// Bytes of nodes and leaves.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..]) + std::mem::size_of_val(&self.leaves[..])
    }

    /// Closest hit in (0, t_max), front to back, with the hit triangle's vertices.
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        triangles: &[[Vec3A; 3]],
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
                if best.map(|h| h.0) != before {
                    best_leaf = leaf;
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

struct Builder<'a> {
    bvh2: &'a Bvh2,
    /// Primitives below each binary node.
    counts: Vec<u32>,
    vertices: &'a dyn Fn(usize) -> [Vec3A; 3],
    nodes: Vec<Node>,
    leaves: Vec<Block>,
    order: Vec<usize>,
    /// A leaf's primitives, reused.
    scratch: Vec<usize>,
}

impl Builder<'_> {
    /// Primitives below binary node `index`.
    fn prim_count(&self, index: u32) -> usize {
        self.counts[index as usize] as usize
    }

    /// Appends the primitives below binary node `index` to `out`.
    fn gather(&self, index: u32, out: &mut Vec<usize>) {
        let node = &self.bvh2.nodes[index as usize];
        if node.is_leaf() {
            let first = node.first_index as usize;
            let prims = &self.bvh2.primitive_indices[first..first + node.prim_count as usize];
            out.extend(prims.iter().map(|&p| p as usize));
        } else {
            self.gather(node.first_index, out);
            self.gather(node.first_index + 1, out);
        }
    }

    /// A leaf block over `prims` (at most eight), stored after the others.
    fn push_leaf(&mut self, prims: &[usize]) -> u32 {
        let mut vertices = [[Vec3A::ZERO; 3]; LANES];
        for (v, &p) in vertices.iter_mut().zip(prims) {
            *v = (self.vertices)(p);
        }
        let first = self.order.len();
        self.order.extend_from_slice(prims);
        self.leaves
            .push(Block::new(&vertices[..prims.len()], first));
        (self.leaves.len() - 1) as u32 | LEAF_BIT
    }

    /// The wide node or leaf for binary node `index` at `depth`. A subtree
    /// of at most eight triangles becomes one leaf block; otherwise the
    /// node's children are opened, largest surface area first, until there
    /// are eight (the usual collapse, as in Embree's BVH8 builder).
    fn collapse(&mut self, index: u32, depth: usize) -> Option<u32> {
        if depth > MAX_DEPTH {
            return None;
        }
        let node = &self.bvh2.nodes[index as usize];
        if node.is_leaf() && node.prim_count as usize > LANES {
            return self.split_leaf(index);
        }
        if self.prim_count(index) <= LEAF_MAX {
            let mut prims = std::mem::take(&mut self.scratch);
            prims.clear();
            self.gather(index, &mut prims);
            let leaf = self.push_leaf(&prims);
            self.scratch = prims;
            return Some(leaf);
        }
        let (mut children, mut count) = ([index; LANES], 1);
        while count < LANES {
            let area = |c: u32| self.bvh2.nodes[c as usize].aabb().half_area();
            let openable =
                |c: u32| !self.bvh2.nodes[c as usize].is_leaf() && self.prim_count(c) > LEAF_MAX;
            // The widest openable child; ties to the first, as max_by's last.
            let mut widest: Option<usize> = None;
            for i in (0..count).filter(|&i| openable(children[i])) {
                if widest.is_none_or(|w| area(children[i]) >= area(children[w])) {
                    widest = Some(i);
                }
            }
            let Some(i) = widest else { break };
            let first = self.bvh2.nodes[children[i] as usize].first_index;
            // swap_remove, then push both children.
            children[i] = children[count - 1];
            children[count - 1] = first;
            children[count] = first + 1;
            count += 1;
        }
        self.push_node(count, |builder, lane| {
            let c = children[lane];
            let aabb = *builder.bvh2.nodes[c as usize].aabb();
            Some(((aabb.min, aabb.max), builder.collapse(c, depth + 1)?))
        })
    }

    /// A binary leaf of more than eight triangles (obvhs leaves usually hold
    /// one): a node over blocks of eight, or None past 64 triangles.
    fn split_leaf(&mut self, index: u32) -> Option<u32> {
        let mut prims = Vec::new();
        self.gather(index, &mut prims);
        let chunks: Vec<Vec<usize>> = prims.chunks(LANES).map(<[usize]>::to_vec).collect();
        if chunks.len() > LANES {
            return None;
        }
        self.push_node(chunks.len(), |builder, lane| {
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for p in chunks[lane].iter().flat_map(|&p| (builder.vertices)(p)) {
                (lo, hi) = (lo.min(p), hi.max(p));
            }
            Some(((lo, hi), builder.push_leaf(&chunks[lane])))
        })
    }

    /// Adds a node with `count` children, `child(builder, lane)` giving
    /// each child's box and reference (building it).
    fn push_node(
        &mut self,
        count: usize,
        mut child: impl FnMut(&mut Self, usize) -> Option<((Vec3A, Vec3A), u32)>,
    ) -> Option<u32> {
        // Reserve this node's slot before its children take theirs.
        let slot = self.nodes.len();
        self.nodes.push(Node {
            boxes: Boxes8::new(&[]),
            children: [0; LANES],
        });
        let mut boxes = [(Vec3A::ZERO, Vec3A::ZERO); LANES];
        let mut refs = [0u32; LANES];
        for lane in 0..count {
            (boxes[lane], refs[lane]) = child(self, lane)?;
        }
        self.nodes[slot] = Node {
            boxes: Boxes8::new(&boxes[..count]),
            children: refs,
        };
        Some(slot as u32)
    }
}

/// Primitive counts below every node of `bvh2`, by an explicit post-order
/// walk (pathological inputs make deep binary trees).
fn subtree_counts(bvh2: &Bvh2) -> Vec<u32> {
    let mut counts = vec![0u32; bvh2.nodes.len()];
    let mut stack = vec![(0u32, false)];
    while let Some((index, children_done)) = stack.pop() {
        let node = &bvh2.nodes[index as usize];
        if node.is_leaf() {
            counts[index as usize] = node.prim_count;
        } else if children_done {
            counts[index as usize] =
                counts[node.first_index as usize] + counts[node.first_index as usize + 1];
        } else {
            stack.extend([
                (index, true),
                (node.first_index, false),
                (node.first_index + 1, false),
            ]);
        }
    }
    counts
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
            let found = bvh.closest(&ray, f32::INFINITY, &triangles);
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
