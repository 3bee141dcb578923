//! Clusters above the patches (Smits, Arvo and Greenberg 1994; Sillion
//! 1995): a binary tree of bounding spheres over the patches' roots
//! ([`ClusterTree`]: median splits of the centroids along the longest
//! axis), so that the solve starts from one self-link of the whole scene
//! instead of one link per pair of patches, and two complex objects
//! exchange light through a few links between groups of triangles.
//!
//! A link with a cluster at one end carries the exchange of two small
//! sources ([`crate::radiosity::cluster`]): from source q to gatherer p,
//! centres r apart in unit direction d (p to q), a patch of p with normal n
//! receives the irradiance
//!
//!   w(n, d) P_q(−d) / (π r²) V B_q,
//!
//! P the projected area (oriented: Σ A_k max(0, n_k · d) over the
//! triangles; isotropic: A / 4), V the share of a few shadow rays between
//! the two ends that arrive, B_q the source's area-mean radiance, and w
//! the patch's share: max(0, n · d) for oriented clusters (each patch by
//! its own cosine), 1/4 for isotropic ones (all alike). An element gathering
//! from a cluster takes the mean of that at its centroid and corners.
//!
//! The oracle is the elements' BF oracle with the exchange bounded by the
//! spheres brought as close as they can be: A_p F_pq ≤ P̂_p P̂_q / (π g²),
//! g = r − ρ_p − ρ_q and P̂ the projected area widened by the angle the
//! pair subtends. Overlapping spheres, or a bound above ε, split the end
//! with the larger sphere (an element into its four children).
//!
//! Push: a patch takes the irradiance of its ancestor clusters' links with
//! its own normal, every step (the cost is the links above each patch, not
//! the patches below each link). Pull: a cluster sends the area mean of
//! its patches' sent radiance.

use super::{Hierarchy, Link, NONE, Node, PARTIAL_SHARE, luminance, partly_visible};
use crate::accel::Geometry;
use crate::math::{Rgb, gamma, ray_between};
use crate::radiosity::cluster::{ClusterKind, ClusterTree};
use crate::radiosity::form_factor::faces;
use crate::sampling::hash::{hash_combine, to_unit_float};
use crate::sampling::warp::square_to_uniform_triangle;
use glam::{Vec2, Vec3A};
use rayon::prelude::*;
use std::f32::consts::PI;

/// A node reference with this bit set is a cluster (the index of a node of
/// the cluster tree); otherwise it is an element node.
pub(super) const CLUSTER: u32 = 1 << 31;

#[inline]
pub(super) fn is_cluster(r: u32) -> bool {
    r != NONE && r & CLUSTER != 0
}

/// Shadow rays per link with a cluster at one end.
const CLUSTER_RAYS: u32 = 8;

/// A cluster of at most this many patches paired with an element is split
/// before the element, whatever their sizes: elements split because their
/// sphere overlapped a nearby small cluster's were refined past what their
/// own oracle asks, and the indirect room's masked RMSE rose from 0.00514
/// (no clusters) to 0.0080; with 16: 0.00514, and the 100 k sphere's room
/// 0.00220 (0.00225 splitting the larger sphere always; 64: 0.00223, 256:
/// 0.00244 with 8% more links).
const SMALL_CLUSTER: usize = 16;

/// Tries at finding a triangle of a cluster that faces the other end.
const FACING_TRIES: u32 = 8;

/// A link gathered by a cluster.
#[derive(Clone, Copy, Debug)]
pub(super) struct ClusterLink {
    pub source: u32,
    /// The source's centre.
    pub center: Vec3A,
    /// P_q(−d) V / π, d from the cluster's centre: irradiance per unit of
    /// the source's radiance at unit distance, facing it.
    pub intensity: f32,
    /// The same at the cluster's centre (over r²).
    pub g: f32,
    /// An element source's area times its unit normal (zero for a
    /// cluster), so that its projected area is taken towards each point.
    pub area_normal: Vec3A,
    /// What the link brings per unit of the kernel, its source's radiance
    /// included: set when made and at each step from the radiance the step
    /// gathers (`refresh_weights`), so that a patch's gather reads the
    /// links alone (reading each source's node there was 54% of a solve).
    pub weight: Rgb,
    pub visibility: f32,
    /// The oracle's bound on A_p F_pq (geometry only).
    pub bound: f32,
}

/// The cluster tree over the patches and, per tree node, what the solve
/// keeps of it. Leaves of the tree are patches (referred to by their
/// element node); only inner nodes are clusters.
pub(super) struct Clusters {
    tree: ClusterTree,
    kind: ClusterKind,
    /// Per tree node, its parent (NONE at the root).
    parent: Vec<u32>,
    /// Per tree node, the componentwise largest reflectance of its patches.
    reflectance: Vec<Rgb>,
    /// Per tree node, the area mean of its patches' sent radiance, and its
    /// componentwise largest (the oracle's).
    sent: Vec<Rgb>,
    brightest: Vec<Rgb>,
    /// Per tree node, the links it gathers over (clusters only).
    links: Vec<Vec<ClusterLink>>,
    /// Per patch (root node), its leaf in the tree.
    leaf: Vec<u32>,
}

/// Bytes per patch the clusters take (tree, state and the patch's copy),
/// links aside: the memory check before building.
pub(super) const BYTES_PER_PATCH: usize = 2 * (48 + 4 + 12 + 12 + 12 + 24) + 48 + 16 + 4 + 4 + 4;

impl Clusters {
    /// The tree over `patches` (the roots, node ids 0..n).
    pub(super) fn build(patches: &[Node], kind: ClusterKind) -> Clusters {
        let triangles: Vec<[Vec3A; 3]> = patches.iter().map(|n| n.element.vertices).collect();
        let tree = ClusterTree::build(&triangles);
        let count = tree.node_count();
        let mut parent = vec![NONE; count];
        let mut leaf = vec![NONE; patches.len()];
        let mut reflectance = vec![Rgb::ZERO; count];
        // Children follow their parent in the tree's order.
        for i in (0..count).rev() {
            let (first, _, children) = tree.range(i);
            reflectance[i] = match children {
                Some(c) => {
                    parent[c] = i as u32;
                    parent[c + 1] = i as u32;
                    reflectance[c].max(reflectance[c + 1])
                }
                None => {
                    let patch = tree.input_index(first) as usize;
                    leaf[patch] = i as u32;
                    patches[patch].element.reflectance
                }
            };
        }
        Clusters {
            tree,
            kind,
            parent,
            reflectance,
            sent: vec![Rgb::ZERO; count],
            brightest: vec![Rgb::ZERO; count],
            links: vec![Vec::new(); count],
            leaf,
        }
    }

    /// The reference of tree node `i`: its patch's node for a leaf.
    fn reference(&self, i: usize) -> u32 {
        match self.tree.range(i) {
            (first, _, None) => self.tree.input_index(first),
            _ => CLUSTER | i as u32,
        }
    }

    /// The root's reference, if the tree has a cluster at all.
    pub(super) fn root(&self) -> Option<u32> {
        (self.tree.node_count() > 1).then(|| self.reference(0))
    }

    /// The patches (root nodes 0..n).
    pub(super) fn patch_count(&self) -> usize {
        self.leaf.len()
    }

    /// Links gathered by clusters.
    pub(super) fn link_count(&self) -> usize {
        self.links.iter().map(Vec::len).sum()
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.tree.triangle_count() * BYTES_PER_PATCH
            + self.link_count() * std::mem::size_of::<ClusterLink>()
    }

    /// Sets every cluster's sent radiance to its patches' area-mean
    /// radiance (`mean`, by node: not what a partly hidden patch sends from
    /// its open part, which counted over all of it made the indirect room
    /// 8% too bright) and its brightest to the most any patch sends (`sent`).
    pub(super) fn pull(&mut self, sent: &[Rgb], mean: &[Rgb]) {
        for i in (0..self.tree.node_count()).rev() {
            let (first, _, children) = self.tree.range(i);
            (self.sent[i], self.brightest[i]) = match children {
                Some(c) => {
                    let (a, b) = (self.tree.sphere(c).2, self.tree.sphere(c + 1).2);
                    let total = a + b;
                    let mean = if total > 0.0 {
                        (a * self.sent[c] + b * self.sent[c + 1]) / total
                    } else {
                        Rgb::ZERO
                    };
                    (mean, self.brightest[c].max(self.brightest[c + 1]))
                }
                None => {
                    let patch = self.tree.input_index(first) as usize;
                    (mean[patch], sent[patch])
                }
            };
        }
    }
}

impl Hierarchy {
    /// Centre, radius and area of a node or cluster.
    fn sphere_of(&self, r: u32) -> (Vec3A, f32, f32) {
        if is_cluster(r) {
            return self.clusters.tree.sphere((r & !CLUSTER) as usize);
        }
        let e = &self.nodes[r as usize].element;
        let c = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
        let radius = e
            .vertices
            .iter()
            .map(|v| (*v - c).length())
            .fold(0.0, f32::max);
        (c, radius, e.area)
    }

    /// The area of a node or cluster projected towards unit direction `d`
    /// (light leaves an element's front only).
    fn projected_of(&self, r: u32, d: Vec3A) -> f32 {
        if is_cluster(r) {
            let kind = self.clusters.kind;
            return self
                .clusters
                .tree
                .projected((r & !CLUSTER) as usize, d, kind);
        }
        let e = &self.nodes[r as usize].element;
        e.area * e.normal.dot(d).max(0.0)
    }

    fn reflectance_of(&self, r: u32) -> Rgb {
        if is_cluster(r) {
            self.clusters.reflectance[(r & !CLUSTER) as usize]
        } else {
            self.nodes[r as usize].element.reflectance
        }
    }

    /// Pulls the patches' radiance up the clusters, `sent` by node.
    pub(super) fn pull_clusters(&mut self, sent: &[Rgb]) {
        let patches = self.clusters.patch_count();
        let mean: Vec<Rgb> = self.nodes[..patches].iter().map(|n| n.radiance).collect();
        self.clusters.pull(sent, &mean);
    }

    /// The radiance the oracle bounds a source's by: a cluster's brightest
    /// patch's, a node's own.
    pub(super) fn oracle_radiance(&self, q: u32) -> Rgb {
        if is_cluster(q) {
            self.clusters.brightest[(q & !CLUSTER) as usize]
        } else {
            self.exitant(q)
        }
    }

    /// The radiance a cluster sends (set by the last pull).
    pub(super) fn cluster_sent(&self, r: u32) -> Rgb {
        self.clusters.sent[(r & !CLUSTER) as usize]
    }

    /// The oracle's bound on A_p F_pq, or None where the spheres overlap.
    fn exchange_bound(&self, p: u32, q: u32) -> Option<f32> {
        if p == q {
            return None;
        }
        let ((cp, rp, ap), (cq, rq, aq)) = (self.sphere_of(p), self.sphere_of(q));
        let between = cq - cp;
        let r = between.length();
        let gap = r - rp - rq;
        if !(gap > 0.0) {
            return None;
        }
        let d = between / r;
        let spread = ((rp + rq) / r).min(1.0);
        let widened =
            |x: u32, d: Vec3A, area: f32| (self.projected_of(x, d) + spread * area).min(area);
        Some(widened(p, d, ap) * widened(q, -d, aq) / (PI * gap * gap))
    }

    /// The oracle's transfer for a pair with exchange bound `bound`,
    /// relative to the emitted power, by the source's brightest patch: a
    /// cluster sends its mean radiance every way, so a lamp and its shade
    /// linked as one leaked the lamp's light through the shade (the
    /// indirect room's masked RMSE 0.0133 against 0.0051 without clusters).
    fn cluster_transfer(&self, p: u32, q: u32, bound: f32) -> f32 {
        let light = luminance(self.reflectance_of(p) * self.oracle_radiance(q));
        (light as f64 * bound as f64 / self.emitted) as f32
    }

    /// The end of a pair to split and its children, or None if neither can
    /// be (or the node budget is spent).
    fn split_pair(&mut self, p: u32, q: u32) -> Option<Vec<(u32, u32)>> {
        if p == q {
            let c = self.children_of(p)?;
            return Some(
                c.iter()
                    .flat_map(|&a| c.iter().map(move |&b| (a, b)))
                    .collect(),
            );
        }
        let (can_p, can_q) = (self.divisible(p), self.divisible(q));
        if !can_p && !can_q {
            return None;
        }
        // A small cluster facing an element is split first: the element's
        // own oracle then decides its subdivision (see [`SMALL_CLUSTER`]).
        let small = |r: u32| {
            is_cluster(r) && self.clusters.tree.range((r & !CLUSTER) as usize).1 <= SMALL_CLUSTER
        };
        let split_p = if is_cluster(p) != is_cluster(q) && (small(p) || small(q)) {
            is_cluster(p)
        } else {
            can_p && (!can_q || self.sphere_of(p).1 >= self.sphere_of(q).1)
        };
        let children = self.children_of(if split_p { p } else { q })?;
        Some(
            children
                .into_iter()
                .map(|c| if split_p { (c, q) } else { (p, c) })
                .collect(),
        )
    }

    /// A cluster's two children or an element's four.
    fn children_of(&mut self, r: u32) -> Option<Vec<u32>> {
        if is_cluster(r) {
            let (_, _, children) = self.clusters.tree.range((r & !CLUSTER) as usize);
            let c = children?;
            return Some(vec![
                self.clusters.reference(c),
                self.clusters.reference(c + 1),
            ]);
        }
        let first = self.subdivide(r)?;
        Some((first..first + 4).collect())
    }

    /// Links pairs with a cluster at one end at least, splitting while the
    /// oracle finds them too coarse, and a link through a shadow boundary
    /// while its transfer is above [`PARTIAL_SHARE`] of ε, as elements' are.
    /// Pairs of elements met on the way go to `elements` (for
    /// [`Hierarchy::link`]).
    pub(super) fn link_clusters(
        &mut self,
        geometry: &Geometry,
        mut wave: Vec<(u32, u32, bool)>,
        elements: &mut Vec<(u32, u32, bool)>,
    ) {
        let epsilon = self.settings.epsilon;
        while !wave.is_empty() {
            let mut accepted = Vec::new();
            while !wave.is_empty() {
                let bounds: Vec<Option<f32>> = wave
                    .par_iter()
                    .map(|&(p, q, forced)| (!forced).then(|| self.exchange_bound(p, q)).flatten())
                    .collect();
                let mut next = Vec::new();
                for (&(p, q, _), bound) in wave.iter().zip(bounds) {
                    if let Some(b) = bound
                        && self.cluster_transfer(p, q, b) <= epsilon
                    {
                        accepted.push((p, q, b));
                        continue;
                    }
                    let Some(pairs) = self.split_pair(p, q) else {
                        // The budget is spent: the coarse link stays.
                        accepted.push((p, q, bound.unwrap_or(f32::INFINITY)));
                        continue;
                    };
                    for (a, b) in pairs {
                        if is_cluster(a) || is_cluster(b) {
                            next.push((a, b, false));
                        } else if a != b
                            && faces(
                                &self.nodes[a as usize].element,
                                &self.nodes[b as usize].element,
                            )
                        {
                            elements.push((a, b, false));
                        }
                    }
                }
                wave = next;
            }
            let exchanges: Vec<(f32, f32, u32)> = accepted
                .par_iter()
                .map(|&(p, q, _)| self.cluster_exchange(geometry, p, q))
                .collect();
            for (&(p, q, bound), (factor, visibility, rays)) in accepted.iter().zip(exchanges) {
                self.rays += u64::from(rays);
                let transfer = self.cluster_transfer(p, q, bound);
                if partly_visible(visibility)
                    && transfer > epsilon * PARTIAL_SHARE
                    && !self.budget_spent
                    && (self.divisible(p) || self.divisible(q))
                {
                    wave.push((p, q, true));
                } else if factor > 0.0 {
                    self.add_link(p, q, bound, factor, visibility);
                }
            }
        }
    }

    fn add_link(&mut self, p: u32, q: u32, bound: f32, factor: f32, visibility: f32) {
        if is_cluster(p) {
            let center = self.sphere_of(q).0;
            let r2 = (center - self.sphere_of(p).0).length_squared();
            let area_normal = if is_cluster(q) {
                Vec3A::ZERO
            } else {
                let e = &self.nodes[q as usize].element;
                e.area * e.normal
            };
            let mut link = ClusterLink {
                source: q,
                center,
                intensity: factor * r2,
                g: factor,
                visibility,
                bound,
                area_normal,
                weight: Rgb::ZERO,
            };
            link.weight = self.link_weight(&link);
            self.clusters.links[(p & !CLUSTER) as usize].push(link);
        } else {
            let area = self.nodes[p as usize].element.area;
            self.nodes[p as usize].links.push(Link {
                source: q,
                f: factor,
                visibility,
                f_max: bound / area,
            });
        }
    }

    /// A link's factor (g for a cluster gatherer, F for an element), the
    /// share of its shadow rays that arrived, and the rays cast.
    fn cluster_exchange(&self, geometry: &Geometry, p: u32, q: u32) -> (f32, f32, u32) {
        let (cp, _, _) = self.sphere_of(p);
        let cq = self.sphere_of(q).0;
        let factor = if is_cluster(p) {
            let between = cq - cp;
            self.projected_of(q, -between.normalize()) / (PI * between.length_squared())
        } else {
            let e = &self.nodes[p as usize].element;
            let points = [cp, e.vertices[0], e.vertices[1], e.vertices[2]];
            points
                .iter()
                .map(|&x| self.point_to_cluster(x + 0.05 * (cp - x), e.normal, q))
                .sum::<f32>()
                / 4.0
        };
        if !(factor > 0.0) {
            return (0.0, 1.0, 0);
        }
        let d = (cq - cp).normalize();
        let key = hash_combine(u64::from(p), u64::from(q));
        let (mut cast, mut arrived) = (0, 0);
        for k in 0..CLUSTER_RAYS {
            let key = hash_combine(key, u64::from(k));
            let (Some(x), Some(y)) = (self.point_facing(p, d, key), self.point_facing(q, -d, !key))
            else {
                continue;
            };
            let ray = ray_between(x.0, x.1, x.2, y.0, y.1, y.2);
            cast += 1;
            arrived += u32::from(!geometry.occluded(&ray));
        }
        let visibility = if cast == 0 {
            1.0
        } else {
            arrived as f32 / cast as f32
        };
        (factor * visibility, visibility, cast)
    }

    /// The unoccluded form factor from the point `x` (normal `n`) to the
    /// node or cluster `q`, as a point source.
    pub(super) fn point_to_cluster(&self, x: Vec3A, n: Vec3A, q: u32) -> f32 {
        let between = self.sphere_of(q).0 - x;
        let r2 = between.length_squared();
        let d = between / r2.sqrt();
        n.dot(d).max(0.0) * self.projected_of(q, -d) / (PI * r2)
    }

    /// A random point of node or cluster `r` on a triangle that faces
    /// direction `d`: the point, its error bound and the triangle's normal.
    fn point_facing(&self, r: u32, d: Vec3A, key: u64) -> Option<(Vec3A, Vec3A, Vec3A)> {
        let unit = |salt: u64| to_unit_float(hash_combine(key, salt));
        let (vertices, normal) = if is_cluster(r) {
            let (first, count, _) = self.clusters.tree.range((r & !CLUSTER) as usize);
            (0..FACING_TRIES as u64)
                .map(|t| {
                    let pick = ((unit(t) * count as f32) as usize).min(count - 1);
                    self.clusters.tree.triangle(first + pick)
                })
                .find(|(_, n)| n.dot(d) > 0.0)?
        } else {
            let e = &self.nodes[r as usize].element;
            (e.vertices, e.normal)
        };
        let b = square_to_uniform_triangle(Vec2::new(unit(100), unit(101)));
        let [a, v1, v2] = vertices;
        let (e1, e2) = (b.x * (v1 - a), b.y * (v2 - a));
        let error = gamma(7) * (a.abs() + e1.abs() + e2.abs());
        Some((a + e1 + e2, error, normal))
    }

    /// The irradiance the point `x` (normal `n`) of patch `root` gathers
    /// over its ancestor clusters' links, from their weights.
    pub(super) fn cluster_irradiance(&self, root: u32, x: Vec3A, n: Vec3A) -> Rgb {
        let mut irradiance = Rgb::ZERO;
        self.for_cluster_links(root, |l| irradiance += self.kernel(l, x, n) * l.weight);
        irradiance
    }

    /// The geometric part of what a link brings to the point `x` (normal
    /// `n`) of a patch of its cluster; times the link's weight, the
    /// irradiance. Oriented, by the point's own distance and cosine to the
    /// source's centre (by the cluster's centre, patches a cluster's radius
    /// from it were lit up to 35% wrong, in blocks the size of clusters),
    /// and an element source's projected area towards the point itself (a
    /// cluster source's costs its triangles, so it is the link's, in the
    /// weight); isotropic, 1: every patch alike.
    #[inline]
    fn kernel(&self, l: &ClusterLink, x: Vec3A, n: Vec3A) -> f32 {
        if self.clusters.kind == ClusterKind::Isotropic {
            return 1.0;
        }
        let between = l.center - x;
        let cos = n.dot(between);
        if cos <= 0.0 {
            return 0.0;
        }
        let r2 = between.length_squared();
        if l.area_normal == Vec3A::ZERO {
            cos / (r2 * r2.sqrt())
        } else {
            cos * (-l.area_normal.dot(between)).max(0.0) / (r2 * r2)
        }
    }

    /// A link's weight per unit of its source's radiance: oriented, V / π
    /// and, for a cluster source, its projected area from the cluster's
    /// centre; isotropic, a quarter of g (Sillion).
    fn unit_weight(&self, l: &ClusterLink) -> f32 {
        match self.clusters.kind {
            ClusterKind::Isotropic => 0.25 * l.g,
            ClusterKind::Oriented if l.area_normal == Vec3A::ZERO => l.intensity,
            ClusterKind::Oriented => l.visibility / PI,
        }
    }

    /// A link's weight from its source's radiance now (see
    /// [`Hierarchy::sent_by`]).
    fn link_weight(&self, l: &ClusterLink) -> Rgb {
        self.unit_weight(l) * self.sent_by(l.source)
    }

    /// Sets every cluster link's weight from the radiance the step gathers.
    pub(super) fn refresh_weights(&mut self) {
        let weights: Vec<Vec<Rgb>> = self
            .clusters
            .links
            .par_iter()
            .map(|links| links.iter().map(|l| self.link_weight(l)).collect())
            .collect();
        for (links, weights) in self.clusters.links.iter_mut().zip(weights) {
            for (l, w) in links.iter_mut().zip(weights) {
                l.weight = w;
            }
        }
    }

    /// The share of the hemisphere the point `x` (normal `n`) of patch
    /// `root` gathers from over its ancestor clusters' links (see
    /// `gathered_share`).
    pub(super) fn cluster_form_factor(&self, root: u32, x: Vec3A, n: Vec3A) -> f32 {
        let mut sum = 0.0;
        self.for_cluster_links(root, |l| sum += self.kernel(l, x, n) * self.unit_weight(l));
        sum
    }

    /// Calls `f` on every link of patch `root`'s ancestor clusters.
    fn for_cluster_links(&self, root: u32, mut f: impl FnMut(&ClusterLink)) {
        let Some(&leaf) = self.clusters.leaf.get(root as usize) else {
            return;
        };
        let mut a = self.clusters.parent[leaf as usize];
        while a != NONE {
            self.clusters.links[a as usize].iter().for_each(&mut f);
            a = self.clusters.parent[a as usize];
        }
    }

    /// Replaces the clusters' links the current radiance makes too coarse:
    /// returns the pairs to refine.
    pub(super) fn coarse_cluster_links(&mut self) -> Vec<(u32, u32, bool)> {
        let epsilon = self.settings.epsilon;
        let mut coarse = Vec::new();
        if self.budget_spent {
            return coarse;
        }
        // Read in parallel, removed in order (as the elements' links).
        let removed: Vec<(usize, Vec<u32>)> = (0..self.clusters.links.len())
            .into_par_iter()
            .filter_map(|i| {
                let p = CLUSTER | i as u32;
                let sources: Vec<u32> = self.clusters.links[i]
                    .iter()
                    .filter(|l| {
                        let transfer = self.cluster_transfer(p, l.source, l.bound);
                        transfer > epsilon
                            || (transfer > epsilon * PARTIAL_SHARE && partly_visible(l.visibility))
                    })
                    .map(|l| l.source)
                    .collect();
                (!sources.is_empty()).then_some((i, sources))
            })
            .collect();
        for (i, sources) in removed {
            coarse.extend(sources.iter().map(|&q| (CLUSTER | i as u32, q, true)));
            self.clusters.links[i].retain(|l| !sources.contains(&l.source));
        }
        coarse
    }
}
