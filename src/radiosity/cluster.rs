//! Clusters (Smits, Arvo and Greenberg 1994; Sillion 1995): a hierarchy
//! above the triangles of a surface, so that two complex objects exchange
//! light through a few links between groups of triangles instead of one
//! link per pair of triangles ("the form factor between two cows").
//!
//! The tree is a binary bounding-sphere hierarchy built by median splits of
//! the triangles' centroids along the longest axis. A link between clusters
//! a and b (centres c_a, c_b, distance r, unit direction d from a to b)
//! carries
//!
//!   F_ab ≈ P_a(d) P_b(−d) / (π r² A_a),
//!
//! P(d) the cluster's area projected towards d:
//! - **isotropic** (Sillion): P = A / 4, the mean projected area of a
//!   closed convex surface over all directions;
//! - **oriented** (Smits et al.): P(d) = Σ A_k max(0, n_k · d) over the
//!   cluster's triangles, exact for a cluster that does not shadow itself.
//!
//! The oracle accepts a link when its form factor, bounded by putting the
//! two bounding spheres as close as they could be (r − ρ_a − ρ_b in place of
//! r), is below ε both ways; otherwise the larger cluster is split. Two
//! triangles exchange by the contour integral ([`point_to_polygon`]) at the
//! seven points of a degree-5 rule on the sender, which is also what the
//! reference, the sum over every pair of triangles, uses.

use super::form_factor::point_to_polygon;
pub use crate::scene::mesh::uv_sphere;
use glam::Vec3A;
use rayon::prelude::*;
use std::f32::consts::PI;

/// How a cluster's projected area is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClusterKind {
    /// A / 4 in every direction (Sillion 1995).
    Isotropic,
    /// Σ A_k max(0, n_k · d) (Smits, Arvo and Greenberg 1994).
    Oriented,
}

/// The oracle's default ε: links carry form factors below it.
pub const DEFAULT_EPSILON: f32 = 1e-3;

/// One node of the tree: a triangle range, its bounding sphere and area.
#[derive(Clone, Copy, Debug)]
struct Node {
    center: Vec3A,
    radius: f32,
    area: f32,
    /// Triangles `first..first + count` of the tree's order.
    first: u32,
    count: u32,
    /// Children at `children` and `children + 1`, or none for a leaf.
    children: u32,
}

const LEAF: u32 = u32::MAX;

/// A cluster hierarchy over one object's triangles.
#[derive(Clone, Debug)]
pub struct ClusterTree {
    nodes: Vec<Node>,
    /// Triangles in tree order, their unit normals and areas.
    triangles: Vec<[Vec3A; 3]>,
    normals: Vec<Vec3A>,
    areas: Vec<f32>,
    /// Per triangle in tree order, its index in the input.
    order: Vec<u32>,
}

impl ClusterTree {
    /// Builds the tree over `triangles` (degenerate ones are kept, with no
    /// area). Leaves hold one triangle.
    pub fn build(triangles: &[[Vec3A; 3]]) -> ClusterTree {
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let centroids: Vec<Vec3A> = triangles
            .iter()
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len());
        if !triangles.is_empty() {
            nodes.push(Node {
                center: Vec3A::ZERO,
                radius: 0.0,
                area: 0.0,
                first: 0,
                count: triangles.len() as u32,
                children: LEAF,
            });
            let mut stack = vec![0usize];
            while let Some(i) = stack.pop() {
                let (first, count) = (nodes[i].first as usize, nodes[i].count as usize);
                if count == 1 {
                    continue;
                }
                let range = &mut order[first..first + count];
                let (lo, hi) = range.iter().fold(
                    (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                    |(lo, hi), &t| (lo.min(centroids[t as usize]), hi.max(centroids[t as usize])),
                );
                let axis = (hi - lo).max_position();
                let half = count / 2;
                range.select_nth_unstable_by(half, |a, b| {
                    centroids[*a as usize][axis].total_cmp(&centroids[*b as usize][axis])
                });
                nodes[i].children = nodes.len() as u32;
                for (f, c) in [(first, half), (first + half, count - half)] {
                    stack.push(nodes.len());
                    nodes.push(Node {
                        first: f as u32,
                        count: c as u32,
                        ..nodes[i]
                    });
                }
                let last = nodes.len();
                nodes[last - 1].children = LEAF;
                nodes[last - 2].children = LEAF;
            }
        }
        let triangles: Vec<[Vec3A; 3]> = order.iter().map(|&t| triangles[t as usize]).collect();
        let cross: Vec<Vec3A> = triangles
            .iter()
            .map(|[a, b, c]| (*b - *a).cross(*c - *a))
            .collect();
        let mut tree = ClusterTree {
            normals: cross.iter().map(|c| c.normalize_or_zero()).collect(),
            areas: cross.iter().map(|c| 0.5 * c.length()).collect(),
            nodes,
            triangles,
            order,
        };
        for node in &mut tree.nodes {
            let tris = &tree.triangles[node.first as usize..(node.first + node.count) as usize];
            let (lo, hi) = tris.iter().flatten().fold(
                (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(*p), hi.max(*p)),
            );
            node.center = 0.5 * (lo + hi);
            node.radius = tris
                .iter()
                .flatten()
                .map(|p| (*p - node.center).length())
                .fold(0.0, f32::max);
            node.area = tree.areas[node.first as usize..(node.first + node.count) as usize]
                .iter()
                .sum();
        }
        tree
    }

    /// The total area.
    pub fn area(&self) -> f32 {
        self.nodes.first().map_or(0.0, |n| n.area)
    }

    /// The triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Nodes in the tree (2n − 1 for n triangles).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Node `i`'s bounding sphere (centre, radius) and area.
    pub(crate) fn sphere(&self, i: usize) -> (Vec3A, f32, f32) {
        let n = &self.nodes[i];
        (n.center, n.radius, n.area)
    }

    /// Node `i`'s triangles in tree order (`first..first + count`) and its
    /// first child (the second follows), or None for a leaf.
    pub(crate) fn range(&self, i: usize) -> (usize, usize, Option<usize>) {
        let n = &self.nodes[i];
        let children = (n.children != LEAF).then_some(n.children as usize);
        (n.first as usize, n.count as usize, children)
    }

    /// The input index of the triangle at tree position `t`.
    pub(crate) fn input_index(&self, t: usize) -> u32 {
        self.order[t]
    }

    /// Triangle `t` (tree order): its vertices and unit normal.
    pub(crate) fn triangle(&self, t: usize) -> ([Vec3A; 3], Vec3A) {
        (self.triangles[t], self.normals[t])
    }

    /// The area of node `i` projected towards unit direction `d`.
    pub(crate) fn projected(&self, i: usize, d: Vec3A, kind: ClusterKind) -> f32 {
        let n = &self.nodes[i];
        match kind {
            ClusterKind::Isotropic if n.count > 1 => 0.25 * n.area,
            _ => {
                let range = n.first as usize..(n.first + n.count) as usize;
                self.normals[range.clone()]
                    .iter()
                    .zip(&self.areas[range])
                    .map(|(normal, a)| a * normal.dot(d).max(0.0))
                    .sum()
            }
        }
    }
}

/// The seven points and weights of a degree-5 rule on a triangle
/// (Stroud T2:5-1), as barycentric (b1, b2) and weights summing to 1.
const RULE: [(f32, f32, f32); 7] = {
    const A: f32 = 0.101_286_51;
    const B: f32 = 0.797_426_97;
    const C: f32 = 0.470_142_06;
    const D: f32 = 0.059_715_87;
    const WA: f32 = 0.125_939_18;
    const WC: f32 = 0.132_394_15;
    [
        (1.0 / 3.0, 1.0 / 3.0, 0.225),
        (A, A, WA),
        (A, B, WA),
        (B, A, WA),
        (C, C, WC),
        (C, D, WC),
        (D, C, WC),
    ]
};

/// F from triangle `i` of `a` to triangle `j` of `b`, unoccluded: the
/// contour integral at the rule's points of i, where j faces them.
fn triangle_to_triangle(a: &ClusterTree, i: usize, b: &ClusterTree, j: usize) -> f32 {
    let [p0, p1, p2] = a.triangles[i];
    let (n, target, nj) = (a.normals[i], &b.triangles[j], b.normals[j]);
    RULE.iter()
        .map(|&(b1, b2, w)| {
            let p = (1.0 - b1 - b2) * p0 + b1 * p1 + b2 * p2;
            // Light leaves j's front only.
            if nj.dot(p - target[0]) <= 0.0 {
                0.0
            } else {
                w * point_to_polygon(p, n, target)
            }
        })
        .sum()
}

/// What a cluster form factor cost and gave.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClusterFormFactor {
    /// F from the first object to the second.
    pub f: f64,
    /// Links made (each one pair of clusters or triangles).
    pub links: u64,
}

/// F from object `a` to object `b` by links between their clusters,
/// refined until each carries less than `epsilon` both ways.
pub fn cluster_form_factor(
    a: &ClusterTree,
    b: &ClusterTree,
    kind: ClusterKind,
    epsilon: f32,
) -> ClusterFormFactor {
    if a.nodes.is_empty() || b.nodes.is_empty() || !(a.area() > 0.0) {
        return ClusterFormFactor::default();
    }
    let (sum, links) = link(a, 0, b, 0, kind, epsilon);
    ClusterFormFactor {
        f: sum / f64::from(a.area()),
        links,
    }
}

/// Σ A_p F_pq over the links that refine the pair (`i` of a, `j` of b),
/// and their number.
fn link(
    a: &ClusterTree,
    i: usize,
    b: &ClusterTree,
    j: usize,
    kind: ClusterKind,
    epsilon: f32,
) -> (f64, u64) {
    let (na, nb) = (&a.nodes[i], &b.nodes[j]);
    if na.count == 1 && nb.count == 1 {
        let f = triangle_to_triangle(a, na.first as usize, b, nb.first as usize);
        return (f64::from(f * na.area), 1);
    }
    let between = nb.center - na.center;
    let r = between.length();
    let gap = r - na.radius - nb.radius;
    if gap > 0.0 {
        let d = between / r;
        let exchange = a.projected(i, d, kind) * b.projected(j, -d, kind) / (PI * r * r);
        // Bounds of F both ways, the spheres brought as close as they can be.
        let closest = (r / gap) * (r / gap);
        let (f_ab, f_ba) = (exchange / na.area, exchange / nb.area);
        if closest * f_ab.max(f_ba) < epsilon {
            return (f64::from(exchange), 1);
        }
    }
    // Split the larger (a leaf cannot be).
    let split_a = nb.count == 1 || (na.count > 1 && na.radius >= nb.radius);
    let pairs = if split_a {
        let c = na.children as usize;
        [(c, j), (c + 1, j)]
    } else {
        let c = nb.children as usize;
        [(i, c), (i, c + 1)]
    };
    // Parallel near the root only, where the subtrees are large.
    let (x, y) = if na.count + nb.count > 2048 {
        rayon::join(
            || link(a, pairs[0].0, b, pairs[0].1, kind, epsilon),
            || link(a, pairs[1].0, b, pairs[1].1, kind, epsilon),
        )
    } else {
        (
            link(a, pairs[0].0, b, pairs[0].1, kind, epsilon),
            link(a, pairs[1].0, b, pairs[1].1, kind, epsilon),
        )
    };
    (x.0 + y.0, x.1 + y.1)
}

/// F from `a` to `b` as the area-weighted sum over every pair of
/// triangles: the reference the clusters are measured against, O(n m).
pub fn triangle_sum_form_factor(a: &ClusterTree, b: &ClusterTree) -> f64 {
    if !(a.area() > 0.0) {
        return 0.0;
    }
    let sum: f64 = (0..a.triangle_count())
        .into_par_iter()
        .map(|i| triangle_row(a, i, b))
        .sum();
    sum / f64::from(a.area())
}

/// A_i Σ_j F_ij: triangle `i` of `a` (in tree order) against every
/// triangle of `b`, one term of [`triangle_sum_form_factor`].
pub fn triangle_row(a: &ClusterTree, i: usize, b: &ClusterTree) -> f64 {
    let row: f64 = (0..b.triangle_count())
        .map(|j| f64::from(triangle_to_triangle(a, i, b, j)))
        .sum();
    row * f64::from(a.areas[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spheres(rings: u32, distance: f32) -> (ClusterTree, ClusterTree) {
        (
            ClusterTree::build(&uv_sphere(Vec3A::ZERO, 1.0, rings, 2 * rings)),
            ClusterTree::build(&uv_sphere(
                Vec3A::new(distance, 0.0, 0.0),
                1.0,
                rings,
                2 * rings,
            )),
        )
    }

    #[test]
    fn the_sphere_is_closed_and_outward() {
        let t = uv_sphere(Vec3A::ZERO, 1.0, 12, 24);
        let area: f32 = t
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
            .sum();
        // Inscribed: a little under 4π.
        assert!(area < 4.0 * PI && area > 0.97 * 4.0 * PI, "{area}");
        for [a, b, c] in &t {
            let n = (*b - *a).cross(*c - *a);
            assert!(n.dot(*a + *b + *c) > 0.0, "a triangle faces inwards");
        }
        let tree = ClusterTree::build(&t);
        assert_eq!(tree.node_count(), 2 * t.len() - 1);
        assert!((tree.area() - area).abs() < 1e-3 * area);
    }

    /// F between unit spheres 3 apart by Monte Carlo, 4e7 cosine-weighted
    /// rays (`bench/references/sphere_form_factor.py`): 0.029639, standard
    /// error 0.000027.
    const SPHERES_3_APART: f64 = 0.029639;

    /// The triangle sum approaches the spheres' form factor as the mesh
    /// refines (inscribed meshes fall short by O(1/n) in area, and F with
    /// it); at 24 rings within 1%, 37 standard errors of the reference.
    #[test]
    fn the_triangle_sum_converges_to_the_spheres_form_factor() {
        let errors: Vec<f64> = [6, 12, 24]
            .into_iter()
            .map(|rings| {
                let (a, b) = spheres(rings, 3.0);
                (triangle_sum_form_factor(&a, &b) - SPHERES_3_APART).abs() / SPHERES_3_APART
            })
            .collect();
        assert!(errors[2] < 0.01, "{errors:?}");
        assert!(errors[2] < errors[1] && errors[1] < errors[0], "{errors:?}");
    }

    /// Clusters against the sum of every pair: oriented clusters within 1%
    /// at the default ε with far fewer links than pairs; both kinds closer
    /// as ε falls (isotropic clusters, A/4 in every direction, misjudge a
    /// half sphere, so they need a smaller ε for the same error).
    #[test]
    fn clusters_agree_with_the_triangle_sum() {
        let (a, b) = spheres(16, 3.0);
        let reference = triangle_sum_form_factor(&a, &b);
        let pairs = (a.triangles.len() * b.triangles.len()) as u64;
        let error = |c: ClusterFormFactor| (c.f - reference).abs() / reference;
        for kind in [ClusterKind::Oriented, ClusterKind::Isotropic] {
            let errors: Vec<(f32, f64, u64)> = [1e-1, 1e-2, 1e-3, 1e-4, 1e-5]
                .into_iter()
                .map(|eps| {
                    let c = cluster_form_factor(&a, &b, kind, eps);
                    (eps, error(c), c.links)
                })
                .collect();
            eprintln!("{kind:?}: {errors:?} ({pairs} pairs)");
            assert!(errors[4].1 < 0.002, "{kind:?}: {errors:?}");
            assert!(errors[4].1 < errors[0].1, "{kind:?}: {errors:?}");
        }
        let default = cluster_form_factor(&a, &b, ClusterKind::Oriented, DEFAULT_EPSILON);
        assert!(error(default) < 0.01, "{default:?} vs {reference}");
        assert!(default.links * 10 < pairs, "{} links", default.links);
    }
}
