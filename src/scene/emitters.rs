//! Emissive triangles grouped into lights. Meshes store quads as two
//! triangles; when the two share a diagonal and make an exact parallelogram,
//! they become one parallelogram light, sampled with one 2D point over the
//! whole quad instead of a light choice between its halves.

use glam::Vec3A;
use std::collections::HashMap;

/// The shape of one light made of emissive triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmitterShape {
    Triangle(usize),
    /// `p0 + s e1 + t e2`, s, t in [0, 1], wound as `triangles[0]`.
    Parallelogram {
        triangles: [usize; 2],
        p0: Vec3A,
        e1: Vec3A,
        e2: Vec3A,
    },
}

/// Groups the `emissive` triangles (indices into `triangles`) into lights,
/// in the order of their first triangle. Two triangles pair when they have
/// the same material, share an edge, their other vertices a and d satisfy
/// a + d = b + c exactly for the shared edge (b, c), and they face the same
/// way. Anything else stays a triangle.
pub fn group_emitters(
    triangles: &[[Vec3A; 3]],
    emissive: &[usize],
    material: impl Fn(usize) -> u32,
) -> Vec<EmitterShape> {
    // Edge (endpoints' bits, sorted) -> (triangle, index of its opposite vertex).
    let mut edges: HashMap<[[u32; 3]; 2], Vec<(usize, usize)>> = HashMap::new();
    for &i in emissive {
        for k in 0..3 {
            edges
                .entry(edge_key(&triangles[i], k))
                .or_default()
                .push((i, k));
        }
    }
    let mut partner: HashMap<usize, (usize, usize)> = HashMap::new();
    let mut shapes = Vec::with_capacity(emissive.len());
    for &i in emissive {
        if partner.contains_key(&i) {
            continue;
        }
        let found = (0..3).find_map(|k| {
            edges[&edge_key(&triangles[i], k)]
                .iter()
                .find(|&&(j, _)| {
                    j != i
                        && !partner.contains_key(&j)
                        && material(j) == material(i)
                        && forms_parallelogram(&triangles[i], k, &triangles[j])
                })
                .map(|&(j, _)| (j, k))
        });
        match found {
            Some((j, k)) => {
                partner.insert(j, (i, k));
                let v = triangles[i];
                let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                shapes.push(EmitterShape::Parallelogram {
                    triangles: [i, j],
                    p0: a,
                    e1: b - a,
                    e2: c - a,
                });
            }
            None => shapes.push(EmitterShape::Triangle(i)),
        }
    }
    shapes
}

/// The edge opposite vertex `k`, as a key independent of its direction.
fn edge_key(v: &[Vec3A; 3], k: usize) -> [[u32; 3]; 2] {
    let bits = |p: Vec3A| p.to_array().map(f32::to_bits);
    let (b, c) = (bits(v[(k + 1) % 3]), bits(v[(k + 2) % 3]));
    if b <= c { [b, c] } else { [c, b] }
}

/// True when `other` is the rest of the parallelogram whose diagonal is the
/// edge of `v` opposite vertex k: its third vertex is b + c - a exactly and
/// its winding matches.
fn forms_parallelogram(v: &[Vec3A; 3], k: usize, other: &[Vec3A; 3]) -> bool {
    let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
    let Some(d) = other.iter().copied().find(|&p| p != b && p != c) else {
        return false;
    };
    let faces = |t: &[Vec3A; 3]| (t[1] - t[0]).cross(t[2] - t[0]);
    a + d == b + c && faces(v).dot(faces(other)) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Vec<[Vec3A; 3]> {
        // The Cornell box's light, as its OBJ triangulates it.
        let p = [
            Vec3A::new(343.0, 548.7, 227.0),
            Vec3A::new(343.0, 548.7, 332.0),
            Vec3A::new(213.0, 548.7, 332.0),
            Vec3A::new(213.0, 548.7, 227.0),
        ];
        vec![[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    }

    #[test]
    fn the_two_halves_of_a_quad_become_one_parallelogram() {
        let t = quad();
        let shapes = group_emitters(&t, &[0, 1], |_| 0);
        let [
            EmitterShape::Parallelogram {
                triangles,
                p0,
                e1,
                e2,
            },
        ] = shapes[..]
        else {
            panic!("{shapes:?}");
        };
        assert_eq!(triangles, [0, 1]);
        // Its four corners are the quad's, and it faces as triangle 0 does.
        let corners = [p0, p0 + e1, p0 + e2, p0 + e1 + e2];
        for v in t.iter().flatten() {
            assert!(corners.contains(v), "{v} not in {corners:?}");
        }
        let n0 = (t[0][1] - t[0][0]).cross(t[0][2] - t[0][0]);
        assert!(e1.cross(e2).dot(n0) > 0.0);
    }

    #[test]
    fn other_pairs_stay_triangles() {
        let t = quad();
        // Different materials.
        let shapes = group_emitters(&t, &[0, 1], |i| i as u32);
        assert_eq!(
            shapes,
            [EmitterShape::Triangle(0), EmitterShape::Triangle(1)]
        );
        // A kite, not a parallelogram.
        let mut kite = t.clone();
        kite[1][2] += Vec3A::new(0.0, 0.0, 1.0);
        let shapes = group_emitters(&kite, &[0, 1], |_| 0);
        assert_eq!(shapes.len(), 2);
        // Folded back on itself (opposite winding).
        let mut folded = t.clone();
        folded[1].swap(1, 2);
        let shapes = group_emitters(&folded, &[0, 1], |_| 0);
        assert_eq!(shapes.len(), 2);
        // Only emissive triangles are grouped.
        assert_eq!(group_emitters(&t, &[1], |_| 0), [EmitterShape::Triangle(1)]);
    }
}
