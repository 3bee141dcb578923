//! The smooth display of a hierarchy: radiance gathered at the leaves'
//! vertices over their links and their ancestors'.

use super::{Hierarchy, NONE, VERTEX_RAYS, is_cluster};
use crate::accel::Geometry;
use crate::math::Rgb;
use crate::radiosity::VertexField;
use crate::radiosity::form_factor::{open_at, point_to_polygon, point_visibility};
use crate::radiosity::reconstruct::{VertexMap, vertex_key};
use glam::{Vec2, Vec3A};
use rayon::prelude::*;

impl Hierarchy {
    /// Computes the leaves' vertex radiance for the smooth display: at each
    /// vertex, E + ρ Σ B_q F(x → q) V over the links of the leaf and of its
    /// ancestors, F the point-to-polygon form factor at the vertex and V the
    /// link's share of visible shadow rays. A link's transfer is constant
    /// over its gatherer (the constant basis) but its kernel is not, so a
    /// coarse link that lights a whole wall still shades it smoothly where
    /// pushing its constant down would leave steps the size of the link;
    /// Cornell box, ε 1e-5: masked RMSE 0.00450 with per-leaf gradients.
    pub fn smooth(&mut self, geometry: &Geometry) {
        let mut parent = vec![NONE; self.nodes.len()];
        for (k, n) in self.nodes.iter().enumerate() {
            if n.children != NONE {
                parent[n.children as usize..n.children as usize + 4].fill(k as u32);
            }
        }
        let leaves: Vec<u32> = (0..self.nodes.len() as u32)
            .filter(|&k| self.nodes[k as usize].children == NONE)
            .collect();
        // One gather per vertex, through the most exposed, then smallest,
        // leaf that has it (its links are the finest there); the leaves
        // sharing it read it. A vertex gathered from inside a hidden leaf
        // (the ceiling above the light) darkened its open neighbours.
        self.measure_exposure(geometry);
        let preference = |k: u32| {
            let n = &self.nodes[k as usize];
            (n.exposure, -n.element.area)
        };
        let mut index: VertexMap<usize> = VertexMap::default();
        let mut vertices: Vec<(u32, Vec3A)> = Vec::new();
        for &k in &leaves {
            let e = &self.nodes[k as usize].element;
            for v in e.vertices {
                let slot = *index.entry(vertex_key(v, e)).or_insert_with(|| {
                    vertices.push((k, v));
                    vertices.len() - 1
                });
                if preference(k) > preference(vertices[slot].0) {
                    vertices[slot].0 = k;
                }
            }
        }
        // First every vertex over the sources' constant radiance, then again
        // where a leaf source is near, over the radiance the first pass found
        // at that source's vertices.
        let first: Vec<(Rgb, bool)> = vertices
            .par_iter()
            .map(|&(k, v)| self.vertex_radiance(geometry, &parent, k, v))
            .collect();
        let near = NearField {
            index: &index,
            radiance: first.iter().map(|&(r, _)| r.max(Rgb::ZERO)).collect(),
        };
        let values: Vec<(Rgb, bool)> = vertices
            .par_iter()
            .zip(&first)
            .map(|(&(k, v), &(radiance, was_near))| {
                let radiance = if was_near {
                    (radiance + self.near_correction(geometry, &parent, k, v, &near)).max(Rgb::ZERO)
                } else {
                    radiance.max(Rgb::ZERO)
                };
                let e = &self.nodes[k as usize].element;
                let x = gather_point(e, v);
                let x_error = crate::math::gamma(7) * x.abs();
                let (open, _) = open_at(
                    geometry,
                    &self.two_sided,
                    x,
                    x_error,
                    e.normal,
                    Vec2::splat(0.5),
                );
                (radiance, open)
            })
            .collect();
        let leaf_corners: Vec<[Rgb; 3]> = leaves
            .par_iter()
            .map(|&k| {
                let e = &self.nodes[k as usize].element;
                let corners = e.vertices.map(|v| values[index[&vertex_key(v, e)]]);
                // A leaf partly hidden (the ceiling's edge around the light, the
                // floor's around a block) shows its open part: hidden corners,
                // dark, take the open corners' mean instead of shading it
                // towards black. Cornell box, masked RMSE without -> with: ε 1e-4
                // 0.00236 -> 0.00233, 7e-5 0.00222 -> 0.00217 (large leaves);
                // 1e-5 0.00130 -> 0.00131 (small ones, where it hardly matters).
                let (sum, count) = corners
                    .iter()
                    .filter(|c| c.1)
                    .fold((Rgb::ZERO, 0.0), |(s, n), c| (s + c.0, n + 1.0));
                corners.map(|(value, is_open)| {
                    if is_open || count == 0.0 {
                        value
                    } else {
                        sum / count
                    }
                })
            })
            .collect();
        let mut per_node = vec![[Rgb::ZERO; 3]; self.nodes.len()];
        for (&k, corners) in leaves.iter().zip(leaf_corners) {
            per_node[k as usize] = corners;
        }
        let elements = leaves
            .iter()
            .map(|&k| (k as usize, &self.nodes[k as usize].element));
        self.vertex_radiance = VertexField::new(elements, per_node);
    }

    /// The radiance at vertex `v` of leaf `k` (`parent`: each node's parent):
    /// E + ρ Σ B_q F(x → q) V over the links of the leaf and its ancestors,
    /// and whether a leaf source was near.
    fn vertex_radiance(
        &self,
        geometry: &Geometry,
        parent: &[u32],
        k: u32,
        v: Vec3A,
    ) -> (Rgb, bool) {
        let e = &self.nodes[k as usize].element;
        let x = gather_point(e, v);
        let mut irradiance = Rgb::ZERO;
        let mut was_near = false;
        let (mut a, mut root) = (k, k);
        while a != NONE {
            for link in &self.nodes[a as usize].links {
                if is_cluster(link.source) {
                    let f = self.point_to_cluster(x, e.normal, link.source);
                    irradiance += (link.visibility * f) * self.sent_by(link.source);
                    continue;
                }
                let q = &self.nodes[link.source as usize];
                // One-sided sources send nothing behind their plane.
                if q.element.normal.dot(x - q.element.vertices[0]) <= 0.0 {
                    continue;
                }
                let f = point_to_polygon(x, e.normal, &q.element.vertices);
                was_near |= q.children == NONE && f > NEAR_FORM_FACTOR;
                irradiance += self.vertex_visibility(geometry, a, link, x, e.normal)
                    * f
                    * self.sent_by(link.source);
            }
            root = a;
            a = parent[a as usize];
        }
        irradiance += self.cluster_irradiance(root, x, e.normal);
        (e.emission + e.reflectance * irradiance, was_near)
    }

    /// What [`Self::vertex_radiance`] changes by when each near leaf source
    /// sends the linear field through its vertices' radiance (`near`)
    /// instead of its mean. Only the near links are evaluated again, so the
    /// second pass costs a fraction of the first.
    fn near_correction(
        &self,
        geometry: &Geometry,
        parent: &[u32],
        k: u32,
        v: Vec3A,
        near: &NearField,
    ) -> Rgb {
        let e = &self.nodes[k as usize].element;
        let x = gather_point(e, v);
        let mut change = Rgb::ZERO;
        let mut a = k;
        while a != NONE {
            for link in &self.nodes[a as usize].links {
                if is_cluster(link.source) {
                    continue;
                }
                let q = &self.nodes[link.source as usize];
                if q.children != NONE || q.element.normal.dot(x - q.element.vertices[0]) <= 0.0 {
                    continue;
                }
                if !may_be_near(x, &q.element) {
                    continue;
                }
                let f = point_to_polygon(x, e.normal, &q.element.vertices);
                let Some(corners) = near.at(&q.element).filter(|_| f > NEAR_FORM_FACTOR) else {
                    continue;
                };
                let linear = linear_source(x, e.normal, &q.element.vertices, corners);
                change += self.vertex_visibility(geometry, a, link, x, e.normal)
                    * (linear - f * self.sent_by(link.source));
            }
            a = parent[a as usize];
        }
        e.reflectance * change
    }

    /// A link's visibility at a vertex: through a shadow boundary the link's
    /// mean is not the vertex's (a leaf half behind the light gave the
    /// ceiling a dark ring around it), so uncertain links cast rays there.
    fn vertex_visibility(
        &self,
        geometry: &Geometry,
        a: u32,
        link: &super::Link,
        x: Vec3A,
        normal: Vec3A,
    ) -> f32 {
        if self.uncertain(a, link) {
            let q = &self.nodes[link.source as usize];
            point_visibility(geometry, x, normal, &q.element, VERTEX_RAYS)
        } else {
            link.visibility
        }
    }
}

/// A point form factor above this makes a leaf source near: its radiance
/// varies where the point sees most of it (a wall's strip along a corner,
/// whose mean the coarse links pushed to it overestimate). Cornell box,
/// masked RMSE at ε 3e-5 / 1e-5: 0.05 0.001557 / 0.001211, 0.1 0.001562 /
/// 0.001215, 0.2 0.001574 / 0.001220, none 0.001601 / 0.001228.
const NEAR_FORM_FACTOR: f32 = 0.05;

/// A near source is integrated over 4^NEAR_LEVELS sub-triangles (1:
/// 0.001563 / 0.001212 as above, 3: 0.001558 / 0.001211).
const NEAR_LEVELS: u32 = 2;

/// Whether the form factor from `x` to `q` can exceed [`NEAR_FORM_FACTOR`]:
/// it is at most A / (π d²), d the distance to q's bounding sphere, which
/// skips the exact form factor for all but the adjacent sources.
fn may_be_near(x: Vec3A, q: &crate::radiosity::Element) -> bool {
    let centre = (q.vertices[0] + q.vertices[1] + q.vertices[2]) / 3.0;
    let radius = q
        .vertices
        .iter()
        .map(|&v| v.distance(centre))
        .fold(0.0, f32::max);
    let d = x.distance(centre) - radius;
    d <= 0.0 || q.area > NEAR_FORM_FACTOR * std::f32::consts::PI * d * d
}

/// Where a vertex's radiance is gathered: just inside its leaf, since on a
/// neighbour's edge the integral is singular.
fn gather_point(e: &crate::radiosity::Element, v: Vec3A) -> Vec3A {
    let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
    v + 0.05 * (centroid - v)
}

/// The first pass's vertex radiance, found by vertex key.
struct NearField<'a> {
    index: &'a VertexMap<usize>,
    radiance: Vec<Rgb>,
}

impl NearField<'_> {
    /// The radiance at element `q`'s corners, if all three are vertices of
    /// leaves.
    fn at(&self, q: &crate::radiosity::Element) -> Option<[Rgb; 3]> {
        let [a, b, c] = q
            .vertices
            .map(|v| self.index.get(&vertex_key(v, q)).map(|&i| self.radiance[i]));
        Some([a?, b?, c?])
    }
}

/// ∫ F(x → y) B(y) over triangle `v` (point `x`, normal `n`), B linear
/// through the values `corners` at its vertices: over 4^NEAR_LEVELS
/// sub-triangles, each at its centroid's value.
fn linear_source(x: Vec3A, n: Vec3A, v: &[Vec3A; 3], corners: [Rgb; 3]) -> Rgb {
    let k = 1u32 << NEAR_LEVELS;
    let step = 1.0 / k as f32;
    let at = |b1: f32, b2: f32| v[0] + (v[1] - v[0]) * b1 + (v[2] - v[0]) * b2;
    let value = |b1: f32, b2: f32| corners[0] * (1.0 - b1 - b2) + corners[1] * b1 + corners[2] * b2;
    let mut sum = Rgb::ZERO;
    for i in 0..k {
        for j in 0..k - i {
            let (b1, b2) = (i as f32 * step, j as f32 * step);
            let up = [at(b1, b2), at(b1 + step, b2), at(b1, b2 + step)];
            sum += point_to_polygon(x, n, &up) * value(b1 + step / 3.0, b2 + step / 3.0);
            if i + j + 1 < k {
                let down = [
                    at(b1 + step, b2),
                    at(b1 + step, b2 + step),
                    at(b1, b2 + step),
                ];
                sum += point_to_polygon(x, n, &down)
                    * value(b1 + 2.0 * step / 3.0, b2 + 2.0 * step / 3.0);
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ F(x → y) B(y) over `v` by 4^levels sub-triangles of its own: the
    /// reference, at a depth where the centroid rule's error is far below
    /// the tolerances.
    fn fine(x: Vec3A, n: Vec3A, v: [Vec3A; 3], b: [Rgb; 3], levels: u32) -> Rgb {
        if levels == 0 {
            return point_to_polygon(x, n, &v) * ((b[0] + b[1] + b[2]) / 3.0);
        }
        let m = [
            (v[0] + v[1]) / 2.0,
            (v[1] + v[2]) / 2.0,
            (v[2] + v[0]) / 2.0,
        ];
        let bm = [
            (b[0] + b[1]) / 2.0,
            (b[1] + b[2]) / 2.0,
            (b[2] + b[0]) / 2.0,
        ];
        fine(x, n, [v[0], m[0], m[2]], [b[0], bm[0], bm[2]], levels - 1)
            + fine(x, n, [m[0], v[1], m[1]], [bm[0], b[1], bm[1]], levels - 1)
            + fine(x, n, [m[2], m[1], v[2]], [bm[2], bm[1], b[2]], levels - 1)
            + fine(x, n, [m[0], m[1], m[2]], [bm[0], bm[1], bm[2]], levels - 1)
    }

    /// A wall beside a floor point at its corner, as on the Cornell box.
    fn corner() -> (Vec3A, Vec3A, [Vec3A; 3]) {
        let x = Vec3A::new(0.05, 0.0, 0.3);
        let up = Vec3A::Y;
        // The wall x = 0, facing +x, from the floor up.
        let wall = [
            Vec3A::new(0.0, 0.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.0),
            Vec3A::new(0.0, 0.0, 1.0),
        ];
        (x, up, wall)
    }

    #[test]
    fn a_constant_source_gives_its_form_factor_times_its_radiance() {
        let (x, n, wall) = corner();
        let b = Rgb::new(0.2, 0.5, 0.9);
        let got = linear_source(x, n, &wall, [b; 3]);
        let want = point_to_polygon(x, n, &wall) * b;
        // The sub-triangles partition the source, so only rounding differs.
        assert!(
            (got - want).abs().max_element() < 1e-5 * want.max_element(),
            "{got} {want}"
        );
    }

    #[test]
    fn a_linear_source_is_integrated_with_its_variation() {
        let (x, n, wall) = corner();
        // Dark along the floor, bright at the top: the point near the floor
        // sees mostly the dark part.
        let b = [Rgb::splat(0.0), Rgb::splat(1.0), Rgb::splat(0.0)];
        let got = linear_source(x, n, &wall, b).x;
        let want = fine(x, n, wall, b, 7).x;
        let constant = point_to_polygon(x, n, &wall) / 3.0;
        // The point lies a twentieth of the wall's size from it, so even 16
        // sub-triangles see the variation coarsely: measured +20% (0.0595
        // against 0.0495; 16 384 and 262 144 sub-triangles agree to 1e-5),
        // while the source's mean radiance gives +197% (0.147).
        assert!((got - want).abs() < 0.25 * want, "{got} {want}");
        assert!((constant - want).abs() > 1.5 * want, "{constant} {want}");
    }
}
