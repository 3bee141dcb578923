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
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, Ordering};

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

impl Node {
    /// A slot before it is filled.
    fn empty() -> Node {
        Node {
            boxes: Boxes8::new(&[]),
            children: [0; LANES],
        }
    }
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
        vertices: &(dyn Fn(usize) -> [Vec3A; 3] + Sync),
    ) -> Option<(Self, Vec<usize>)> {
        Self::from_bvh2_splitting(bvh2, count, vertices, PARALLEL_MIN)
    }

    /// [`WideBvh::from_bvh2`], subtrees of at least `parallel_min`
    /// triangles collapsed in parallel.
    fn from_bvh2_splitting(
        bvh2: &Bvh2,
        count: usize,
        vertices: &(dyn Fn(usize) -> [Vec3A; 3] + Sync),
        parallel_min: usize,
    ) -> Option<(Self, Vec<usize>)> {
        if bvh2.nodes.is_empty() {
            return None;
        }
        let tree = Tree {
            bvh2,
            counts: subtree_counts(bvh2),
            vertices,
            parallel_min,
        };
        // Sized exactly first, so that subtrees fill their own parts of the
        // arrays on every core (a tree too deep is refused before any work).
        let large = Mutex::new(HashMap::new());
        let size = tree.size(0, 1, &large)?;
        let large = large.into_inner().unwrap_or_else(|e| e.into_inner());
        let mut nodes = Vec::with_capacity(size.nodes);
        nodes.par_extend(rayon::iter::repeat_n(Node::empty(), size.nodes));
        let mut leaves = Vec::with_capacity(size.leaves);
        leaves.par_extend(rayon::iter::repeat_n(Block::empty(), size.leaves));
        let mut order = vec![0; count];
        let parts = Parts::new(&mut nodes, &mut leaves, &mut order);
        let root = tree.collapse(0, 1, parts, &large)?;
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

/// The binary tree being collapsed.
struct Tree<'a> {
    bvh2: &'a Bvh2,
    /// Primitives below each binary node.
    counts: Vec<AtomicU32>,
    vertices: &'a (dyn Fn(usize) -> [Vec3A; 3] + Sync),
    /// Subtrees of at least this many triangles are collapsed in parallel.
    parallel_min: usize,
}

/// Wide nodes and leaf blocks of a subtree.
#[derive(Clone, Copy)]
struct Size {
    nodes: usize,
    leaves: usize,
}

/// Subtrees of at least this many triangles are collapsed on every core
/// (a subtree's task then does enough to pay for itself).
const PARALLEL_MIN: usize = 1 << 14;

/// The parts of the arrays that a subtree fills, in the order a sequential
/// collapse would (each node before its children, children in lane order),
/// and the index of each part's first element in the whole array.
struct Parts<'o> {
    nodes: &'o mut [Node],
    leaves: &'o mut [Block],
    order: &'o mut [usize],
    first: [usize; 3],
}

impl<'o> Parts<'o> {
    fn new(nodes: &'o mut [Node], leaves: &'o mut [Block], order: &'o mut [usize]) -> Self {
        Parts {
            nodes,
            leaves,
            order,
            first: [0; 3],
        }
    }

    /// Splits off the front: `size` and `prims` triangles' worth.
    fn split_off_front(&mut self, size: Size, prims: usize) -> Parts<'o> {
        let (nodes, rest) = std::mem::take(&mut self.nodes).split_at_mut(size.nodes);
        self.nodes = rest;
        let (leaves, rest) = std::mem::take(&mut self.leaves).split_at_mut(size.leaves);
        self.leaves = rest;
        let (order, rest) = std::mem::take(&mut self.order).split_at_mut(prims);
        self.order = rest;
        let front = Parts {
            nodes,
            leaves,
            order,
            first: self.first,
        };
        self.first[0] += size.nodes;
        self.first[1] += size.leaves;
        self.first[2] += prims;
        front
    }
}

impl Tree<'_> {
    /// Primitives below binary node `index`.
    fn prim_count(&self, index: u32) -> usize {
        self.counts[index as usize].load(Ordering::Relaxed) as usize
    }

    /// What binary node `index` becomes: a block of its triangles, a node
    /// over blocks of a binary leaf too large for one, or a node over the
    /// children opened below it (see [`Tree::open`]).
    fn kind(&self, index: u32) -> Kind {
        let node = &self.bvh2.nodes[index as usize];
        if node.is_leaf() && node.prim_count as usize > LANES {
            Kind::SplitLeaf(node.prim_count as usize)
        } else if self.prim_count(index) <= LEAF_MAX {
            Kind::Leaf
        } else {
            let (children, count) = self.open(index);
            Kind::Node(children, count)
        }
    }

    /// A node's children: opened, largest surface area first, until there
    /// are eight (the usual collapse, as in Embree's BVH8 builder).
    fn open(&self, index: u32) -> ([u32; LANES], usize) {
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
        (children, count)
    }

    /// The size of what binary node `index` at `depth` collapses into, or
    /// None where [`Tree::collapse`] fails. The sizes of large nodes'
    /// children go into `large`, for [`Tree::collapse`] to split the
    /// arrays by; their subtrees are sized in parallel.
    fn size(&self, index: u32, depth: usize, large: &Mutex<HashMap<u32, Size>>) -> Option<Size> {
        if depth > MAX_DEPTH {
            return None;
        }
        match self.kind(index) {
            Kind::SplitLeaf(prims) => {
                let blocks = prims.div_ceil(LANES);
                (blocks <= LANES).then_some(Size {
                    nodes: 1,
                    leaves: blocks,
                })
            }
            Kind::Leaf => Some(Size {
                nodes: 0,
                leaves: 1,
            }),
            Kind::Node(children, count) => {
                let children = &children[..count];
                let sizes: Vec<Size> = if self.prim_count(index) >= self.parallel_min {
                    let sizes = (children.par_iter())
                        .map(|&c| self.size(c, depth + 1, large))
                        .collect::<Option<Vec<Size>>>()?;
                    let mut large = large.lock().unwrap_or_else(|e| e.into_inner());
                    large.extend(children.iter().copied().zip(sizes.iter().copied()));
                    sizes
                } else {
                    (children.iter())
                        .map(|&c| self.size(c, depth + 1, large))
                        .collect::<Option<Vec<Size>>>()?
                };
                Some(sizes.iter().fold(
                    Size {
                        nodes: 1,
                        leaves: 0,
                    },
                    |a, s| Size {
                        nodes: a.nodes + s.nodes,
                        leaves: a.leaves + s.leaves,
                    },
                ))
            }
        }
    }

    /// Collapses binary node `index` at `depth` into `parts`, which are
    /// exactly its size; returns its reference. Large subtrees' children
    /// are collapsed in parallel, each into its own part.
    fn collapse(
        &self,
        index: u32,
        depth: usize,
        mut parts: Parts,
        large: &HashMap<u32, Size>,
    ) -> Option<u32> {
        let parallel = match self.kind(index) {
            Kind::Node(children, count)
                if self.prim_count(index) >= self.parallel_min && depth <= MAX_DEPTH =>
            {
                Some((children, count))
            }
            _ => None,
        };
        let Some((children, count)) = parallel else {
            let mut builder = Builder {
                tree: self,
                parts,
                next: [0; 3],
                scratch: Vec::with_capacity(LEAF_MAX),
            };
            return builder.collapse(index, depth);
        };
        let node = parts.split_off_front(
            Size {
                nodes: 1,
                leaves: 0,
            },
            0,
        );
        let mut jobs = Vec::with_capacity(count);
        for &c in &children[..count] {
            jobs.push((c, parts.split_off_front(large[&c], self.prim_count(c))));
        }
        let refs = (jobs.into_par_iter())
            .map(|(c, part)| self.collapse(c, depth + 1, part, large))
            .collect::<Option<Vec<u32>>>()?;
        let mut boxes = [(Vec3A::ZERO, Vec3A::ZERO); LANES];
        let mut children_refs = [0u32; LANES];
        for lane in 0..count {
            let aabb = self.bvh2.nodes[children[lane] as usize].aabb();
            boxes[lane] = (aabb.min, aabb.max);
            children_refs[lane] = refs[lane];
        }
        node.nodes[0] = Node {
            boxes: Boxes8::new(&boxes[..count]),
            children: children_refs,
        };
        Some(node.first[0] as u32)
    }
}

/// See [`Tree::kind`].
enum Kind {
    SplitLeaf(usize),
    Leaf,
    Node([u32; LANES], usize),
}

/// Collapses a subtree on one thread into its parts.
struct Builder<'t, 'a, 'o> {
    tree: &'t Tree<'a>,
    parts: Parts<'o>,
    /// The next free element of each part.
    next: [usize; 3],
    /// A leaf's primitives, reused.
    scratch: Vec<usize>,
}

impl Builder<'_, '_, '_> {
    /// Appends the primitives below binary node `index` to `out`.
    fn gather(&self, index: u32, out: &mut Vec<usize>) {
        let node = &self.tree.bvh2.nodes[index as usize];
        if node.is_leaf() {
            let first = node.first_index as usize;
            let prims = &self.tree.bvh2.primitive_indices[first..first + node.prim_count as usize];
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
            *v = (self.tree.vertices)(p);
        }
        let [_, leaf, first] = self.next;
        self.parts.order[first..first + prims.len()].copy_from_slice(prims);
        let first = self.parts.first[2] + first;
        self.parts.leaves[leaf] = Block::new(&vertices[..prims.len()], first);
        self.next[1] += 1;
        self.next[2] += prims.len();
        (self.parts.first[1] + leaf) as u32 | LEAF_BIT
    }

    /// The wide node or leaf for binary node `index` at `depth` (see
    /// [`Tree::kind`]).
    fn collapse(&mut self, index: u32, depth: usize) -> Option<u32> {
        if depth > MAX_DEPTH {
            return None;
        }
        match self.tree.kind(index) {
            Kind::SplitLeaf(_) => self.split_leaf(index),
            Kind::Leaf => {
                let mut prims = std::mem::take(&mut self.scratch);
                prims.clear();
                self.gather(index, &mut prims);
                let leaf = self.push_leaf(&prims);
                self.scratch = prims;
                Some(leaf)
            }
            Kind::Node(children, count) => self.push_node(count, |builder, lane| {
                let c = children[lane];
                let aabb = *builder.tree.bvh2.nodes[c as usize].aabb();
                Some(((aabb.min, aabb.max), builder.collapse(c, depth + 1)?))
            }),
        }
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
            for p in chunks[lane]
                .iter()
                .flat_map(|&p| (builder.tree.vertices)(p))
            {
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
        // This node's slot comes before its children's.
        let slot = self.next[0];
        self.next[0] += 1;
        let mut boxes = [(Vec3A::ZERO, Vec3A::ZERO); LANES];
        let mut refs = [0u32; LANES];
        for lane in 0..count {
            (boxes[lane], refs[lane]) = child(self, lane)?;
        }
        self.parts.nodes[slot] = Node {
            boxes: Boxes8::new(&boxes[..count]),
            children: refs,
        };
        Some((self.parts.first[0] + slot) as u32)
    }
}

/// Primitive counts below every node of `bvh2`: the top of the tree
/// split over the cores, each subtree below by an explicit post-order walk
/// (pathological inputs make deep binary trees).
fn subtree_counts(bvh2: &Bvh2) -> Vec<AtomicU32> {
    let counts: Vec<AtomicU32> = (bvh2.nodes.par_iter()).map(|_| AtomicU32::new(0)).collect();
    count_below(bvh2, 0, 0, &counts);
    counts
}

/// Fills `counts` below binary node `index` at `depth`; returns its count.
fn count_below(bvh2: &Bvh2, index: u32, depth: u32, counts: &[AtomicU32]) -> u32 {
    let node = &bvh2.nodes[index as usize];
    if !node.is_leaf() && depth < 12 {
        let count = |c| count_below(bvh2, c, depth + 1, counts);
        let (a, b) = rayon::join(|| count(node.first_index), || count(node.first_index + 1));
        counts[index as usize].store(a + b, Ordering::Relaxed);
        return a + b;
    }
    let mut stack = vec![(index, false)];
    while let Some((index, children_done)) = stack.pop() {
        let node = &bvh2.nodes[index as usize];
        let count = if node.is_leaf() {
            node.prim_count
        } else if children_done {
            let below = |c: u32| counts[c as usize].load(Ordering::Relaxed);
            below(node.first_index) + below(node.first_index + 1)
        } else {
            stack.extend([
                (index, true),
                (node.first_index, false),
                (node.first_index + 1, false),
            ]);
            continue;
        };
        counts[index as usize].store(count, Ordering::Relaxed);
    }
    counts[index as usize].load(Ordering::Relaxed)
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

    /// The parallel collapse fills the arrays exactly as the sequential
    /// one: the same nodes, blocks and triangle order.
    #[test]
    fn collapsing_in_parallel_builds_the_same_tree() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let input: Vec<[Vec3A; 3]> = (0..5000u64)
            .map(|i| {
                let centre = Vec3A::new(u(1, i), u(2, i), u(3, i));
                let p = |k| centre + (Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) - 0.5) * 0.02;
                [p(10), p(20), p(30)]
            })
            .collect();
        let aabbs: Vec<Aabb> = input.iter().map(|t| Aabb::from_points(t)).collect();
        let bvh2 = build_bvh2(&aabbs);
        let build = |parallel_min| {
            let (bvh, order) =
                WideBvh::from_bvh2_splitting(&bvh2, input.len(), &|i| input[i], parallel_min)
                    .expect("shallow tree");
            (format!("{bvh:?}"), order)
        };
        let sequential = build(usize::MAX);
        assert_eq!(build(64), sequential);
        assert_eq!(build(1000), sequential);
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
