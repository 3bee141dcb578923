//! Shaft culling (Haines and Wallace 1994): which triangles can block the
//! shadow rays between two elements. Every such ray lies in the convex hull
//! of the two triangles, so an occluder that an axis separates from that
//! hull blocks none of them. A link none can block needs no rays at all; one
//! that a few can block tests only those.
//!
//! It applies where the geometry is a static soup (`accel::soup`) whose
//! rays leave surfaces by robust offsets: there the soup's face triangles
//! (a room's walls) cannot block a segment inside its box, and the inner
//! ones are few enough to list. Elsewhere (a BVH, moving or sphere
//! geometry) every ray is traced, as before.

use super::mesh::Element;
use crate::accel::Geometry;
use crate::math::Ray;
use glam::Vec3A;

/// Listed blockers up to this many are tested one by one; more take the
/// whole test (the soup's eight-wide test of a block costs about what
/// three one-by-one tests do: `shortcuts::shadow_voxels`).
const MAX_LISTED: usize = 4;

/// What may block the rays between two elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blockers {
    /// Nothing: every ray arrives.
    None,
    /// Only these triangles (storage order), `len` of them.
    Among { list: [u32; MAX_LISTED], len: u8 },
    /// Not known: the whole test.
    Unknown,
}

impl Blockers {
    /// [`Geometry::occluded`] for a ray between the two elements, by the
    /// same watertight test against the listed triangles only.
    #[inline(always)]
    pub fn occluded(&self, geometry: &Geometry, ray: &Ray) -> bool {
        match self {
            Blockers::None => false,
            Blockers::Among { list, len } if geometry.segment_inside_soup(ray) => {
                geometry.occluded_among(ray, &list[..*len as usize])
            }
            _ => geometry.occluded(ray),
        }
    }
}

/// An inner triangle of the soup (at its index in storage order) and its
/// bounding box.
#[derive(Clone, Copy, Debug)]
struct Occluder {
    index: u32,
    vertices: [Vec3A; 3],
    lo: Vec3A,
    hi: Vec3A,
}

/// The triangles that can block rays inside a static soup's box.
#[derive(Clone, Debug)]
pub struct Shafts {
    occluders: Vec<Occluder>,
    /// Covers the ray ends' offsets off the elements and rounding.
    margin: f32,
}

impl Shafts {
    /// The soup's inner triangles, or None where culling does not apply
    /// (see the module's note).
    pub fn of(geometry: &Geometry) -> Option<Shafts> {
        let (lo, hi, inner) = geometry.static_soup_box()?;
        // A soup holds a few dozen triangles (`accel::SOUP_MAX_TRIANGLES`).
        if !geometry.has_robust_offsets() {
            return None;
        }
        let triangles = geometry.triangles();
        let occluders = (0..inner)
            .map(|i| {
                let v = triangles[i];
                Occluder {
                    index: i as u32,
                    vertices: v,
                    lo: v[0].min(v[1]).min(v[2]),
                    hi: v[0].max(v[1]).max(v[2]),
                }
            })
            .collect();
        Some(Shafts {
            occluders,
            margin: (hi - lo).max_element() * 1e-4,
        })
    }

    /// What may block rays between elements `i` and `j` (neither blocks
    /// them: rays leave one's plane and end before the other's), given what
    /// may block rays between elements that hold them (`within`; Unknown for
    /// none): a shaft lies inside those of its elements' ancestors.
    pub fn between(&self, i: &Element, j: &Element, within: Blockers) -> Blockers {
        let candidates: &[u32] = match &within {
            Blockers::None => return Blockers::None,
            Blockers::Among { list, len } => &list[..*len as usize],
            Blockers::Unknown => &[],
        };
        let shaft = Shaft::new(i, j, self.margin);
        let mut list = [0u32; MAX_LISTED];
        let mut len = 0;
        let mut add = |o: &Occluder| {
            if o.index == i.triangle || o.index == j.triangle || shaft.misses(o, i, j) {
                return true;
            }
            if len == MAX_LISTED {
                return false;
            }
            list[len] = o.index;
            len += 1;
            true
        };
        let listed = if within == Blockers::Unknown {
            self.occluders.iter().all(&mut add)
        } else {
            candidates.iter().all(|&k| add(&self.occluders[k as usize]))
        };
        match (listed, len) {
            (false, _) => Blockers::Unknown,
            (true, 0) => Blockers::None,
            (true, _) => Blockers::Among {
                list,
                len: len as u8,
            },
        }
    }
}

/// Planes bounding the hull of two triangles (with their intervals along
/// the planes' normals): the triangles' own, and those through an edge of
/// one and a vertex of the other, which include the hull's side faces.
/// Edges crossed with the occluder's edges would separate a few more
/// occluders (edge-on ones) but cost three times as much per occluder.
struct Shaft {
    lo: Vec3A,
    hi: Vec3A,
    hull: [Vec3A; 6],
    axes: [(Vec3A, f32, f32); 20],
    margin: f32,
}

impl Shaft {
    fn new(i: &Element, j: &Element, margin: f32) -> Shaft {
        let hull = [
            i.vertices[0],
            i.vertices[1],
            i.vertices[2],
            j.vertices[0],
            j.vertices[1],
            j.vertices[2],
        ];
        let pad = Vec3A::splat(margin);
        let lo = hull.iter().fold(Vec3A::INFINITY, |a, &p| a.min(p)) - pad;
        let hi = hull.iter().fold(Vec3A::NEG_INFINITY, |a, &p| a.max(p)) + pad;
        let mut axes = [(Vec3A::ZERO, 0.0, 0.0); 20];
        let mut add = |k: usize, axis: Vec3A| {
            let (h_lo, h_hi) = interval(&hull, axis);
            let gap = margin * axis.length();
            axes[k] = (axis, h_lo - gap, h_hi + gap);
        };
        add(0, i.normal);
        add(1, j.normal);
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            for m in 0..3 {
                let through_j =
                    (i.vertices[b] - i.vertices[a]).cross(j.vertices[m] - i.vertices[a]);
                let through_i =
                    (j.vertices[b] - j.vertices[a]).cross(i.vertices[m] - j.vertices[a]);
                add(2 + 6 * k + 2 * m, through_j);
                add(3 + 6 * k + 2 * m, through_i);
            }
        }
        Shaft {
            lo,
            hi,
            hull,
            axes,
            margin,
        }
    }

    /// True when an axis separates the occluder from the hull by more than
    /// the margin; false when none of those tried does.
    fn misses(&self, o: &Occluder, i: &Element, j: &Element) -> bool {
        if o.hi.cmplt(self.lo).any() || o.lo.cmpgt(self.hi).any() {
            return true;
        }
        let apart = |axis: Vec3A, h_lo: f32, h_hi: f32| {
            let (o_lo, o_hi) = interval(&o.vertices, axis);
            o_hi < h_lo || h_hi < o_lo
        };
        // An occluder in the plane of one element, the other wholly in front
        // of it: rays leave that plane (robustly) and stay in front of it.
        let in_plane_behind = |a: &Element, b: &Element| {
            let height = |p: Vec3A| a.normal.dot(p - a.vertices[0]);
            o.vertices.iter().all(|&p| height(p).abs() <= self.margin)
                && b.vertices.iter().all(|&p| height(p) > self.margin)
        };
        if in_plane_behind(i, j) || in_plane_behind(j, i) {
            return true;
        }
        let normal = (o.vertices[1] - o.vertices[0]).cross(o.vertices[2] - o.vertices[0]);
        let (h_lo, h_hi) = interval(&self.hull, normal);
        let gap = self.margin * normal.length();
        apart(normal, h_lo - gap, h_hi + gap)
            || self
                .axes
                .iter()
                .any(|&(axis, h_lo, h_hi)| axis != Vec3A::ZERO && apart(axis, h_lo, h_hi))
    }
}

/// The projections of `points` onto `axis`: (min, max).
#[inline]
fn interval(points: &[Vec3A], axis: Vec3A) -> (f32, f32) {
    points
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            let d = p.dot(axis);
            (lo.min(d), hi.max(d))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::TriangleInput;
    use crate::math::{gamma, ray_between};
    use crate::sampling::hash::{hash_combine, to_unit_float};
    use crate::sampling::warp::square_to_uniform_triangle;
    use glam::Vec2;

    fn element(vertices: [Vec3A; 3], triangle: u32) -> Element {
        let n = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
        Element {
            triangle,
            vertices,
            normal: n.normalize(),
            area: 0.5 * n.length(),
            reflectance: crate::math::Rgb::ZERO,
            emission: crate::math::Rgb::ZERO,
        }
    }

    /// A room with a box and a slanted panel in it: rays between random
    /// pairs of small elements on the walls and the box are blocked only by
    /// triangles their shaft lists, some shafts are clear and some list a
    /// few (the test is not vacuous).
    #[test]
    fn rays_are_blocked_only_by_listed_triangles() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let s = 4.0;
        let mut triangles = Vec::new();
        // The room's six walls, normals inwards.
        let room = [
            (Vec3A::ZERO, Vec3A::Z, Vec3A::X),
            (Vec3A::new(0.0, s, 0.0), Vec3A::X, Vec3A::Z),
            (Vec3A::ZERO, Vec3A::Y, Vec3A::Z),
            (Vec3A::new(s, 0.0, 0.0), Vec3A::Z, Vec3A::Y),
            (Vec3A::ZERO, Vec3A::X, Vec3A::Y),
            (Vec3A::new(0.0, 0.0, s), Vec3A::Y, Vec3A::X),
        ];
        for (corner, a, b) in room {
            triangles.extend(TriangleInput::quad(corner, s * a, s * b, 0));
        }
        // A box [1, 2] x [0, 1.5] x [1, 2], normals outwards.
        let (lo, hi) = (Vec3A::new(1.0, 0.0, 1.0), Vec3A::new(2.0, 1.5, 2.0));
        let size = hi - lo;
        let box_faces = [
            (lo, Vec3A::X * size.x, Vec3A::Y * size.y),
            (lo, Vec3A::Y * size.y, Vec3A::Z * size.z),
            (
                Vec3A::new(lo.x, hi.y, lo.z),
                Vec3A::Z * size.z,
                Vec3A::X * size.x,
            ),
            (hi, -Vec3A::Y * size.y, -Vec3A::X * size.x),
            (hi, -Vec3A::Z * size.z, -Vec3A::Y * size.y),
        ];
        for (corner, a, b) in box_faces {
            triangles.extend(TriangleInput::quad(corner, a, b, 0));
        }
        triangles.push(TriangleInput {
            vertices: [
                Vec3A::new(3.0, 2.0, 0.5),
                Vec3A::new(3.5, 3.0, 0.5),
                Vec3A::new(3.2, 2.5, 1.5),
            ],
            material: 0,
        });
        let geometry = Geometry::build(&triangles, vec![]);
        let shafts = Shafts::of(&geometry).expect("a static soup");
        let stored = geometry.triangles();
        let small = |t: usize, k: u64| {
            // A small triangle inside stored triangle t.
            let v = stored[t];
            let at = |a: f32, b: f32| v[0] + a * (v[1] - v[0]) + b * (v[2] - v[0]);
            let (a, b) = (0.8 * u(k, 1), 0.8 * u(k, 2));
            let (a, b) = if a + b > 0.8 {
                (0.8 - a, 0.8 - b)
            } else {
                (a, b)
            };
            element([at(a, b), at(a + 0.2, b), at(a, b + 0.2)], t as u32)
        };
        let (mut clear, mut listed) = (0, 0);
        for pair in 0..4000u64 {
            let (ti, tj) = (
                (u(pair, 3) * stored.len() as f32) as usize,
                (u(pair, 4) * stored.len() as f32) as usize,
            );
            let (i, j) = (small(ti, pair * 2), small(tj, pair * 2 + 1));
            if !crate::radiosity::form_factor::faces(&i, &j) {
                continue;
            }
            let blockers = shafts.between(&i, &j, Blockers::Unknown);
            match blockers {
                Blockers::None => clear += 1,
                Blockers::Among { .. } => listed += 1,
                Blockers::Unknown => continue,
            }
            for r in 0..16 {
                let point = |e: &Element, k: u64| {
                    let b = square_to_uniform_triangle(Vec2::new(u(k, r), u(k + 7, r)));
                    let [a, v1, v2] = e.vertices;
                    let p = a + b.x * (v1 - a) + b.y * (v2 - a);
                    (p, gamma(7) * (a.abs() + v1.abs() + v2.abs()))
                };
                let ((x, xe), (y, ye)) = (point(&i, pair * 5), point(&j, pair * 5 + 3));
                if i.normal.dot(y - x) <= 0.0 || j.normal.dot(x - y) <= 0.0 {
                    continue;
                }
                let ray = ray_between(x, xe, i.normal, y, ye, j.normal);
                assert_eq!(
                    blockers.occluded(&geometry, &ray),
                    geometry.occluded(&ray),
                    "pair {pair}: {blockers:?} between triangles {ti} and {tj}"
                );
            }
        }
        assert!(
            clear > 500 && listed > 100,
            "{clear} clear, {listed} listed"
        );
    }
}
