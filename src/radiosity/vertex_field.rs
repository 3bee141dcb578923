//! The smooth display's radiance over elements: linear between each
//! element's corners, and through the vertices that finer neighbours put
//! inside its edges (T-vertices). Interpolating the corners alone leaves a
//! step along such an edge wherever the finer side's vertex value differs
//! from the coarser side's line; the display showed it as a crack where a
//! hierarchy's leaves of different levels meet.

use super::element::Element;
use super::reconstruct::{VertexMap, vertex_key};
use crate::math::Rgb;
use glam::Vec3A;
use rayon::prelude::*;

/// Deepest search for vertices inside an edge: the hierarchy's levels
/// below a patch, and a uniform mesh's.
const MAX_HANGING_DEPTH: u32 = 16;

/// Per element, its corners' radiance, and along each edge the vertices
/// that lie inside it.
#[derive(Clone, Debug, Default)]
pub struct VertexField {
    corners: Vec<[Rgb; 3]>,
    /// Per element, where the runs of edges 0, 1 and 2 (corner k to corner
    /// k + 1) start in `hanging`, and where the last ends.
    spans: Vec<[u32; 4]>,
    /// A vertex inside an edge: how far along (0 to 1) and its value less
    /// the edge's linear interpolation there; in order along the edge.
    hanging: Vec<(f32, Rgb)>,
}

impl VertexField {
    /// The field of `corners`, one entry per element index (those not in
    /// `elements`, a hierarchy's inner nodes, are never shown). A vertex
    /// inside an edge is a midpoint, or a midpoint's midpoint, present
    /// among the elements' corners in the same plane: subdivision computes
    /// midpoints alike on both sides of an edge, so positions match exactly.
    pub fn new<'a>(
        elements: impl Iterator<Item = (usize, &'a Element)>,
        corners: Vec<[Rgb; 3]>,
    ) -> VertexField {
        let elements: Vec<(usize, &Element)> = elements.collect();
        let mut value: VertexMap<Rgb> = VertexMap::default();
        for &(k, e) in &elements {
            for (v, c) in e.vertices.into_iter().zip(corners[k]) {
                value.entry(vertex_key(v, e)).or_insert(c);
            }
        }
        // Each element's vertices inside its edges, found in parallel (on
        // one thread the whole field was 7% of a clustered solve's
        // display), then laid end to end in the elements' order.
        let runs: Vec<([u32; 4], Vec<(f32, Rgb)>)> = elements
            .par_iter()
            .map(|&(k, e)| {
                let mut run = Vec::new();
                let mut span = [0u32; 4];
                for edge in 0..3 {
                    let (i, j) = (edge, (edge + 1) % 3);
                    let first = run.len();
                    let ends = (e.vertices[i], e.vertices[j]);
                    inside(e, &value, ends, (0.0, 1.0), MAX_HANGING_DEPTH, &mut run);
                    let (ci, cj) = (corners[k][i], corners[k][j]);
                    for (t, l) in &mut run[first..] {
                        *l -= (1.0 - *t) * ci + *t * cj;
                    }
                    span[edge + 1] = run.len() as u32;
                }
                (span, run)
            })
            .collect();
        let mut spans = vec![[0u32; 4]; corners.len()];
        let mut hanging = Vec::with_capacity(runs.iter().map(|(_, run)| run.len()).sum());
        for (&(k, _), (span, run)) in elements.iter().zip(runs) {
            let start = hanging.len() as u32;
            spans[k] = span.map(|s| start + s);
            hanging.extend(run);
        }
        VertexField {
            corners,
            spans,
            hanging,
        }
    }

    /// The radiance in element `k` at barycentrics `w` (of its vertices 0,
    /// 1, 2); None where the field has no element `k`.
    pub fn at(&self, k: usize, w: [f32; 3]) -> Option<Rgb> {
        let c = self.corners.get(k)?;
        let mut value = w[0] * c[0] + w[1] * c[1] + w[2] * c[2];
        let span = self.spans[k];
        for edge in 0..3 {
            let run = &self.hanging[span[edge] as usize..span[edge + 1] as usize];
            let along = w[edge] + w[(edge + 1) % 3];
            if run.is_empty() || along <= 0.0 {
                continue;
            }
            // The edge's correction at t, piecewise linear through the
            // inside vertices and 0 at the corners, fades towards the
            // opposite corner with the weight of the edge's ends: 0 on the
            // other two edges, so neighbours there see no change.
            let t = w[(edge + 1) % 3] / along;
            let mut before = (0.0f32, Rgb::ZERO);
            let mut correction = Rgb::ZERO;
            for &(tk, dk) in run.iter().chain(std::iter::once(&(1.0, Rgb::ZERO))) {
                if t <= tk {
                    let s = (t - before.0) / (tk - before.0).max(f32::MIN_POSITIVE);
                    correction = before.1 + s * (dk - before.1);
                    break;
                }
                before = (tk, dk);
            }
            value += along * correction;
        }
        Some(value)
    }

    /// Element `k`'s corner values.
    pub fn corners(&self, k: usize) -> Option<[Rgb; 3]> {
        self.corners.get(k).copied()
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.corners.len() * std::mem::size_of::<[Rgb; 3]>()
            + self.spans.len() * std::mem::size_of::<[u32; 4]>()
            + self.hanging.len() * std::mem::size_of::<(f32, Rgb)>()
    }
}

/// Appends, in order, the vertices strictly inside the segment (a, b) of
/// e's edge (parameters t0 to t1 along it) found among `value`'s keys, with
/// their values.
fn inside(
    e: &Element,
    value: &VertexMap<Rgb>,
    (a, b): (Vec3A, Vec3A),
    (t0, t1): (f32, f32),
    depth: u32,
    out: &mut Vec<(f32, Rgb)>,
) {
    if depth == 0 {
        return;
    }
    // As `mesh::children` computes it, so that the bits match.
    let m = 0.5 * (a + b);
    let Some(&lm) = value.get(&vertex_key(m, e)) else {
        return;
    };
    let tm = 0.5 * (t0 + t1);
    inside(e, value, (a, m), (t0, tm), depth - 1, out);
    out.push((tm, lm));
    inside(e, value, (m, b), (tm, t1), depth - 1, out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::mesh::children;

    fn element(vertices: [Vec3A; 3]) -> Element {
        Element::new(0, vertices, Rgb::splat(0.5), Rgb::ZERO)
    }

    /// Barycentrics of `p` in the triangle `v` of the plane z = 0.
    fn weights(p: Vec3A, v: [Vec3A; 3]) -> [f32; 3] {
        let area = |a: Vec3A, b: Vec3A, c: Vec3A| (b - a).cross(c - a).z;
        let whole = area(v[0], v[1], v[2]);
        [
            area(p, v[1], v[2]) / whole,
            area(v[0], p, v[2]) / whole,
            area(v[0], v[1], p) / whole,
        ]
    }

    #[test]
    fn a_coarse_element_meets_finer_neighbours_without_a_step() {
        // The unit square as two triangles sharing the diagonal; the second
        // split twice, so 3 vertices of its leaves lie inside the first's
        // diagonal. Vertex values from a curved field: a linear one would
        // hide the step.
        let field = |p: Vec3A| Rgb::new(p.x * p.x + 3.0 * p.y, p.y * p.y, 1.0);
        let (o, x, xy, y) = (Vec3A::ZERO, Vec3A::X, Vec3A::new(1.0, 1.0, 0.0), Vec3A::Y);
        let mut elements = vec![element([o, x, xy])];
        for child in children([o, xy, y]) {
            elements.extend(children(child).map(element));
        }
        let corners: Vec<[Rgb; 3]> = elements.iter().map(|e| e.vertices.map(field)).collect();
        let vertex_field = VertexField::new(elements.iter().enumerate(), corners);
        let at = |k: usize, p: Vec3A| {
            vertex_field
                .at(k, weights(p, elements[k].vertices))
                .unwrap()
        };
        let containing = |p: Vec3A| {
            (1..elements.len())
                .find(|&k| weights(p, elements[k].vertices).iter().all(|&w| w >= -1e-6))
                .unwrap()
        };
        for step in 0..=64 {
            let t = step as f32 / 64.0;
            let p = Vec3A::new(t, t, 0.0);
            let (coarse, fine) = (at(0, p), at(containing(p), p));
            assert!(
                (coarse - fine).abs().max_element() < 1e-5,
                "at {t}: {coarse} against {fine}"
            );
        }
        // Without the inside vertices the coarse side is off by a quarter
        // in the middle (the field's curvature along the diagonal).
        let plain = |p: Vec3A| {
            let w = weights(p, elements[0].vertices);
            w[0] * field(o) + w[1] * field(x) + w[2] * field(xy)
        };
        let middle = Vec3A::new(0.5, 0.5, 0.0);
        assert!((plain(middle) - at(containing(middle), middle)).x.abs() > 0.1);
        // The coarse element's other edges and corners keep their values.
        for p in [
            o,
            x,
            xy,
            Vec3A::new(0.5, 0.0, 0.0),
            Vec3A::new(1.0, 0.5, 0.0),
        ] {
            assert!((at(0, p) - plain(p)).abs().max_element() < 1e-6, "{p}");
        }
        // A leaf with no finer neighbour interpolates its corners alone.
        let inner = 5;
        let c = elements[inner].vertices;
        let p = (c[0] + c[1] + c[2]) / 3.0;
        let linear = (field(c[0]) + field(c[1]) + field(c[2])) / 3.0;
        assert!((at(inner, p) - linear).abs().max_element() < 1e-5);
    }
}
