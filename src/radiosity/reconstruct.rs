//! The smooth display's vertex radiance, reconstructed from a solution that
//! is constant per element. Averaging the elements around a vertex puts the
//! value of a point about a third of an element inside at every wall's
//! edge, so corners and the ground around blocks come out too bright or
//! too dark by the gradient times the element size. Instead each element
//! gets a gradient, a least-squares plane through its neighbours' centroid
//! values (as finite-volume schemes reconstruct cell averages), and a vertex
//! takes the area-weighted mean of its elements' planes there: exact for a
//! linear field, so the error falls as the element size squared, and shared
//! by every element at the vertex, so the image has no cracks (at the
//! T-vertices of an adaptive mesh, [`super::VertexField`] interpolates the
//! coarser element through them). Hierarchies gather their vertices over
//! their links instead ([`super::hierarchy::Hierarchy::smooth`]).

use super::element::Element;
use crate::math::Rgb;
use glam::Vec3A;
use std::collections::HashMap;

/// Per element, the radiance at its three vertices. Elements are neighbours
/// when they share a vertex (the same position, exactly: midpoints are
/// computed alike on both sides of an edge), lie in the same plane (walls
/// meeting at a corner keep their own values) and emit alike (a light's edge
/// is a true discontinuity).
pub fn vertex_radiance<'a>(
    elements: impl Iterator<Item = (&'a Element, Rgb)>,
    lines: &[LineEdge],
) -> Vec<[Rgb; 3]> {
    let elements: Vec<(&Element, Rgb)> = elements.collect();
    let mut at_vertex: VertexMap<Vec<u32>> = VertexMap::default();
    for (k, (e, _)) in elements.iter().enumerate() {
        for v in e.vertices {
            at_vertex
                .entry(vertex_key(v, e))
                .or_default()
                .push(k as u32);
        }
    }
    let centroid = |e: &Element| (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
    let crossing = LinesAtVertices::new(elements.iter().map(|(e, _)| *e), lines);
    let mut neighbours = Vec::new();
    let gradients: Vec<[Vec3A; 3]> = elements
        .iter()
        .enumerate()
        .map(|(k, &(e, l))| {
            neighbours.clear();
            let c = centroid(e);
            for v in e.vertices {
                // Where a discontinuity line passes through the vertex, the
                // fit takes the neighbours on this element's side only, as
                // the radiance's slope jumps across it.
                let side = crossing.side(v, e);
                neighbours.extend(
                    at_vertex[&vertex_key(v, e)]
                        .iter()
                        .copied()
                        .filter(|&n| crossing.side(v, elements[n as usize].0) == side),
                );
            }
            neighbours.sort_unstable();
            neighbours.dedup();
            let samples = neighbours.iter().filter(|&&n| n as usize != k).map(|&n| {
                (
                    centroid(elements[n as usize].0) - c,
                    elements[n as usize].1 - l,
                )
            });
            gradient(e, samples)
        })
        .collect();
    let planes: Vec<[Rgb; 3]> = elements
        .iter()
        .zip(&gradients)
        .map(|((e, l), g)| {
            let c = centroid(e);
            e.vertices.map(|v| {
                let d = v - c;
                *l + Rgb::new(g[0].dot(d), g[1].dot(d), g[2].dot(d))
            })
        })
        .collect();
    shared_mean(elements.iter().map(|(e, _)| *e), &planes)
}

/// An element edge that lies on a discontinuity line, with its receiver's
/// normal.
#[derive(Clone, Copy, Debug)]
pub struct LineEdge {
    pub ends: [Vec3A; 2],
    pub normal: Vec3A,
}

/// Per vertex that discontinuity lines pass through (at an edge's end, or
/// inside it where subdivision put a midpoint), the lines' directions away
/// from it in its plane.
pub(crate) struct LinesAtVertices(VertexMap<Vec<Vec3A>>);

impl LinesAtVertices {
    pub(crate) fn new<'a>(
        elements: impl Iterator<Item = &'a Element>,
        lines: &[LineEdge],
    ) -> LinesAtVertices {
        let mut at = VertexMap::default();
        if lines.is_empty() {
            return LinesAtVertices(at);
        }
        for e in elements {
            for v in e.vertices {
                let key = vertex_key(v, e);
                if at.contains_key(&key) {
                    continue;
                }
                let mut directions: Vec<Vec3A> = Vec::new();
                for line in lines.iter().filter(|l| l.normal.dot(e.normal) > 0.999) {
                    let [a, b] = line.ends;
                    let ab = b - a;
                    let length2 = ab.length_squared();
                    let t = (v - a).dot(ab) / length2;
                    // Relative tolerances: the test does not depend on units.
                    let off = (v - (a + t * ab)).length_squared();
                    if !(-1e-5..=1.0 + 1e-5).contains(&t) || off > 1e-10 * length2 {
                        continue;
                    }
                    let mut add = |d: Vec3A| {
                        let d = (d - e.normal * d.dot(e.normal)).normalize_or_zero();
                        if d != Vec3A::ZERO && directions.iter().all(|x| x.dot(d) < 0.99999) {
                            directions.push(d);
                        }
                    };
                    if t > 1e-5 {
                        add(-ab);
                    }
                    if t < 1.0 - 1e-5 {
                        add(ab);
                    }
                }
                if !directions.is_empty() {
                    at.insert(key, directions);
                }
            }
        }
        LinesAtVertices(at)
    }

    fn directions(&self, key: &VertexKey) -> Option<&[Vec3A]> {
        self.0.get(key).map(Vec::as_slice)
    }

    /// Which side of the lines through its vertex `v` element `e` lies on
    /// (the sector its centroid is in; 0 where no line passes through `v`).
    pub(crate) fn side(&self, v: Vec3A, e: &Element) -> usize {
        match self.directions(&vertex_key(v, e)) {
            Some(directions) => {
                let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
                sector(e.normal, directions, centroid - v)
            }
            None => 0,
        }
    }
}

/// Which of the sectors that `directions` (in the plane of `normal`) cut
/// around a vertex holds the direction `d`: the number of them at a
/// smaller angle, counted from the first, which closes the last. One
/// direction (a line reaching the receiver's edge, where the elements lie
/// in a half-plane) splits by side.
fn sector(normal: Vec3A, directions: &[Vec3A], d: Vec3A) -> usize {
    let x = directions[0];
    let y = normal.cross(x);
    if directions.len() == 1 {
        return (d.dot(y) < 0.0) as usize;
    }
    let angle = |d: Vec3A| {
        let a = d.dot(y).atan2(d.dot(x));
        if a < 0.0 {
            a + std::f32::consts::TAU
        } else {
            a
        }
    };
    let phi = angle(d);
    directions[1..].iter().filter(|&&l| angle(l) < phi).count()
}

/// Per element, the area-weighted mean of `values` (one per element
/// vertex) over the elements that share each vertex: one value per vertex,
/// so the interpolated image has no cracks. Negative means (a plane past a
/// sharp shadow edge) are clamped to zero.
fn shared_mean<'a>(
    elements: impl Iterator<Item = &'a Element> + Clone,
    values: &[[Rgb; 3]],
) -> Vec<[Rgb; 3]> {
    let mut sums: VertexMap<(Rgb, f32)> =
        VertexMap::with_capacity_and_hasher(values.len(), Default::default());
    for (e, at) in elements.clone().zip(values) {
        for (v, value) in e.vertices.into_iter().zip(at) {
            let entry = sums.entry(vertex_key(v, e)).or_insert((Rgb::ZERO, 0.0));
            entry.0 += e.area * *value;
            entry.1 += e.area;
        }
    }
    elements
        .map(|e| {
            e.vertices.map(|v| {
                let (sum, area) = sums[&vertex_key(v, e)];
                (sum / area).max(Rgb::ZERO)
            })
        })
        .collect()
}

/// The least-squares gradient in `e`'s plane, per colour channel, from
/// neighbours' (centroid offset, radiance difference); zero when the
/// neighbours lie on a line (too few to fit a plane).
fn gradient(e: &Element, samples: impl Iterator<Item = (Vec3A, Rgb)>) -> [Vec3A; 3] {
    let t = (e.vertices[1] - e.vertices[0]).normalize();
    let b = e.normal.cross(t);
    // Normal equations of Σ w (Δl - g·d)², weighted by 1/|d|² so that near
    // neighbours count more (as in unstructured finite volumes).
    let (mut a11, mut a12, mut a22) = (0.0f32, 0.0f32, 0.0f32);
    let (mut r1, mut r2) = (Rgb::ZERO, Rgb::ZERO);
    for (d, dl) in samples {
        let (x, y) = (d.dot(t), d.dot(b));
        let w = 1.0 / (x * x + y * y);
        if !w.is_finite() {
            continue;
        }
        a11 += w * x * x;
        a12 += w * x * y;
        a22 += w * y * y;
        r1 += w * x * dl;
        r2 += w * y * dl;
    }
    let det = a11 * a22 - a12 * a12;
    // Relative to the trace: scale-free, so units do not matter.
    if !(det > 1e-4 * (a11 + a22) * (a11 + a22)) {
        return [Vec3A::ZERO; 3];
    }
    let gx = (a22 * r1 - a12 * r2) / det;
    let gy = (a11 * r2 - a12 * r1) / det;
    [0, 1, 2].map(|c| gx[c] * t + gy[c] * b)
}

pub(crate) type VertexKey = ([u32; 3], [i32; 3], [u32; 3]);

/// A map keyed by vertex, hashed by FxHash: SipHash's defence against
/// chosen keys buys nothing here, and it was 3% of a clustered solve's
/// profile, all of it serial.
pub(crate) type VertexMap<V> = HashMap<VertexKey, V, rustc_hash::FxBuildHasher>;

/// A vertex's position (exact bits), its element's plane orientation and
/// emission, as a hash key.
pub(crate) fn vertex_key(v: Vec3A, e: &Element) -> VertexKey {
    let q = |x: f32| (x * 1024.0).round() as i32;
    let n = e.normal;
    (
        v.to_array().map(f32::to_bits),
        [q(n.x), q(n.y), q(n.z)],
        e.emission.to_array().map(f32::to_bits),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::mesh::children;

    /// A unit square in the plane z = 0 split into 2 · 4^depth triangles.
    fn square(depth: u32) -> Vec<Element> {
        let element = |vertices: [Vec3A; 3]| Element::new(0, vertices, Rgb::splat(0.5), Rgb::ZERO);
        let mut triangles = vec![
            [Vec3A::ZERO, Vec3A::X, Vec3A::new(1.0, 1.0, 0.0)],
            [Vec3A::ZERO, Vec3A::new(1.0, 1.0, 0.0), Vec3A::Y],
        ];
        for _ in 0..depth {
            triangles = triangles.into_iter().flat_map(children).collect();
        }
        triangles.into_iter().map(element).collect()
    }

    /// The largest difference between the vertex values and `field` there.
    fn worst_error(
        elements: &[Element],
        vertices: &[[Rgb; 3]],
        field: impl Fn(Vec3A) -> f32,
    ) -> f32 {
        elements
            .iter()
            .zip(vertices)
            .flat_map(|(e, v)| {
                e.vertices
                    .iter()
                    .zip(v)
                    .map(|(p, l)| (l.x - field(*p)).abs())
            })
            .fold(0.0f32, f32::max)
    }

    #[test]
    fn a_linear_field_is_reconstructed_exactly_up_to_the_edges() {
        // Radiance 0.2 + 0.5 x + 0.3 y: the element averages are its values
        // at the centroids, so every vertex, corners included, must get the
        // field's value there (averaging gave the corner (0, 0) 0.2 + 0.8 h/3).
        let field = |p: Vec3A| 0.2 + 0.5 * p.x + 0.3 * p.y;
        let elements = square(3);
        let values: Vec<Rgb> = elements
            .iter()
            .map(|e| Rgb::splat(field((e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0)))
            .collect();
        let vertices = vertex_radiance(elements.iter().zip(values.iter().copied()), &[]);
        for (e, v) in elements.iter().zip(&vertices) {
            for (p, l) in e.vertices.iter().zip(v) {
                assert!((l.x - field(*p)).abs() < 1e-5, "{p} {l} {}", field(*p));
            }
        }
    }

    #[test]
    fn a_kinked_field_is_exact_on_both_sides_of_its_line() {
        // Radiance 0.2 + 0.3 y + max(0, x - 1/2): its slope jumps along
        // x = 1/2, an edge line of the mesh (a penumbra's boundary). Fits
        // across it put an error of about the jump times the element size
        // at the vertices near it; one-sided fits are exact again.
        let field = |p: Vec3A| 0.2 + 0.3 * p.y + (p.x - 0.5).max(0.0);
        let elements = square(3);
        let values: Vec<Rgb> = elements
            .iter()
            .map(|e| Rgb::splat(field((e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0)))
            .collect();
        let line = LineEdge {
            ends: [Vec3A::new(0.5, 0.0, 0.0), Vec3A::new(0.5, 1.0, 0.0)],
            normal: Vec3A::Z,
        };
        let worst = |lines: &[LineEdge]| {
            let vertices = vertex_radiance(elements.iter().zip(values.iter().copied()), lines);
            worst_error(&elements, &vertices, field)
        };
        assert!(worst(&[line]) < 1e-5, "{}", worst(&[line]));
        assert!(worst(&[]) > 1e-2, "{}", worst(&[]));
    }

    #[test]
    fn a_quadratic_field_converges_as_the_element_size_squared() {
        // Largest vertex error on a curved field, at element sizes h and h/2:
        // second order means the ratio is near 4 (the average gives 2).
        let field = |p: Vec3A| 1.0 + p.x * p.x + 0.5 * p.y * p.y;
        let error = |depth| {
            let elements = square(depth);
            let values: Vec<Rgb> = elements
                .iter()
                .map(|e| {
                    // The element's mean of the field (exact for a quadratic:
                    // the edge midpoints' average).
                    let [a, b, c] = e.vertices;
                    let m =
                        (field(0.5 * (a + b)) + field(0.5 * (b + c)) + field(0.5 * (c + a))) / 3.0;
                    Rgb::splat(m)
                })
                .collect();
            let vertices = vertex_radiance(elements.iter().zip(values.iter().copied()), &[]);
            worst_error(&elements, &vertices, field)
        };
        let (coarse, fine) = (error(2), error(3));
        assert!(coarse / fine > 3.0, "{coarse} {fine}");
    }
}
