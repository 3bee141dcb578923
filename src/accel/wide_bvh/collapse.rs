//! The collapse of obvhs's binary BVH into the 8-wide tree: sized first,
//! then filled on every core, large subtrees each into their own parts of
//! the arrays, so that no step of a large scene's load waits on one core
//! (docs/performance.md, "Loading and memory").

use super::{LEAF_BIT, LEAF_MAX, MAX_DEPTH, Node, WideBvh};
use crate::accel::block::{Block, Boxes8, LANES};
use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, Ordering};

impl Node {
    /// A slot before it is filled.
    fn empty() -> Node {
        Node {
            boxes: Boxes8::new(&[]),
            children: [0; LANES],
        }
    }
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
    use crate::accel::build::build_bvh2;
    use crate::sampling::hash::{hash_combine, to_unit_float};
    use obvhs::aabb::Aabb;

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
}
