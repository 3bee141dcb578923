//! Discontinuity meshing for polygonal area lights (Heckbert 1992;
//! Lischinski, Tampieri and Greenberg 1992): the lines where the
//! irradiance jumps (D0: where an occluder touches a receiver) or where
//! its derivative jumps (D1: the outer and inner boundaries of penumbrae)
//! are traced onto the receivers, and each receiver triangle is split
//! along them by a constrained Delaunay triangulation (spade), so that no
//! element straddles one.
//!
//! D1 lines come from critical visual events between a light and an
//! occluder: a light vertex with an occluder edge (VE) and a light edge
//! with an occluder vertex (EV), each spanning a plane that touches both
//! the light and the occluder without cutting into either. The rays of
//! that plane that leave the light and graze the occluder form a fan (a
//! wedge); where they first land is the discontinuity. Fans are traced by
//! rays rather than clipped polygon by polygon, which gives the wedges'
//! visibility of Lischinski et al. for free: where a fan is blocked
//! before the occluder, or passes from one receiver to the next, the
//! break is found by bisection on the fan's parameter. Within a receiver
//! triangle the landing points lie on the line where the wedge's plane
//! cuts the triangle's, so a run of rays on one triangle is one segment.
//! EEE events (quadric surfaces, D2) are not traced; receivers narrower
//! than a fan's sampling ([`FAN_RAYS`]) can be missed.

use crate::math::{Ray, Rgb};
use crate::radiosity::Element;
use crate::radiosity::form_factor::{EXPOSURE_POINTS, exposure};
use crate::radiosity::mesh::exposed_backs;
use crate::scene::Scene;
use crate::scene::light::Light;
use glam::Vec3A;
use rayon::prelude::*;
use std::collections::{BTreeMap, HashMap};

mod triangulate;
pub use triangulate::{Base, MIN_ANGLE, split};

/// Rays per fan before bisection.
const FAN_RAYS: u32 = 32;
/// Bisection steps where a fan changes receiver (2^-20 of the fan).
const BISECTIONS: u32 = 20;
/// Most critical wedges traced. Beyond, the scene is too detailed for
/// discontinuity meshing to pay (a tessellated sphere casts thousands of
/// lines a few elements long) and it is skipped with a note.
pub const MAX_WEDGES: usize = 20_000;

/// The visual event a line comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// A light's vertex and an occluder's edge (D1).
    VertexEdge,
    /// A light's edge and an occluder's vertex (D1).
    EdgeVertex,
    /// An occluder's edge resting on the receiver (D0).
    Contact,
}

/// A discontinuity line's piece on one receiver triangle.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    pub ends: [Vec3A; 2],
    pub event: Event,
    /// The penumbra's width at each end, by similar triangles (the light's
    /// extent across the line times the ratio of the end's distance past the
    /// occluder to the light's distance before it); 0 for a contact line.
    pub penumbra: [f32; 2],
}

impl Segment {
    /// The part of this segment where its penumbra is at most `limit` wide
    /// (the width is linear along it), unless that is none of it.
    fn narrower_part(&self, limit: f32) -> Option<Segment> {
        let [wa, wb] = self.penumbra;
        if wa <= limit && wb <= limit {
            return Some(*self);
        }
        if wa > limit && wb > limit {
            return None;
        }
        let t = (limit - wa) / (wb - wa);
        // A part a thousandth of the line long (one that only touches the
        // limit, as a line from a contact does at 0) would be a lone point.
        let kept = if wa <= limit { t } else { 1.0 - t };
        if kept < 1e-3 {
            return None;
        }
        let [a, b] = self.ends;
        let cut = a + t * (b - a);
        Some(if wa <= limit {
            Segment {
                ends: [a, cut],
                penumbra: [wa, limit],
                ..*self
            }
        } else {
            Segment {
                ends: [cut, b],
                penumbra: [limit, wb],
                ..*self
            }
        })
    }
}

/// The discontinuities of a scene's receivers.
#[derive(Clone, Debug, Default)]
pub struct Discontinuities {
    /// Per scene triangle, the segments on it.
    pub segments: Vec<Vec<Segment>>,
    /// Critical wedges traced: VE, EV and contact edges.
    pub wedges: [usize; 3],
    /// Rays traced to find them.
    pub rays: u64,
    /// Why some were not traced.
    pub notes: Vec<String>,
}

impl Discontinuities {
    /// These lines with a penumbra's boundary (D1) kept only where the
    /// penumbra is narrower than `limit` (scene units), cut where it
    /// reaches it; contact lines (D0) all kept. A wide penumbra's irradiance
    /// changes slowly, and its lines cost pieces that a coarse mesh needs
    /// elsewhere (docs/validation.md).
    pub fn narrower_than(&self, limit: f32) -> Discontinuities {
        Discontinuities {
            segments: self
                .segments
                .iter()
                .map(|s| s.iter().filter_map(|s| s.narrower_part(limit)).collect())
                .collect(),
            notes: self.notes.clone(),
            ..*self
        }
    }

    /// Line segments, over every receiver.
    pub fn count(&self) -> usize {
        self.segments.iter().map(Vec::len).sum()
    }
}

/// A piece of a receiver triangle after meshing, wound like the triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    pub vertices: [Vec3A; 3],
    /// Per edge (opposite the vertex of that index), whether it lies on a
    /// discontinuity line.
    pub on_line: [bool; 3],
}

/// A planar light's polygon.
struct Polygon {
    corners: Vec<Vec3A>,
    normal: Vec3A,
    two_sided: bool,
}

fn polygons(scene: &Scene) -> Vec<Polygon> {
    scene
        .lights
        .as_slice()
        .iter()
        .filter_map(|light| {
            let (e, corners) = match light {
                Light::Triangle(e) => (e, vec![e.p0, e.p0 + e.e1, e.p0 + e.e2]),
                Light::Parallelogram(e) => {
                    (e, vec![e.p0, e.p0 + e.e1, e.p0 + e.e1 + e.e2, e.p0 + e.e2])
                }
                _ => return None,
            };
            Some(Polygon {
                corners,
                normal: e.normal,
                two_sided: e.two_sided,
            })
        })
        .collect()
}

/// The occluders (every triangle that does not emit) with their vertices
/// welded, so that edges know both their faces.
struct Welded {
    positions: Vec<Vec3A>,
    /// Per edge (vertex pair, smaller first), the third vertex of each face;
    /// ordered, so that lines come in the same order every run and the
    /// triangulation (which merges close points first come, first kept) is
    /// the same.
    edges: BTreeMap<(u32, u32), Vec<u32>>,
    /// Per vertex, the vertices it shares an edge with.
    neighbours: Vec<Vec<u32>>,
}

impl Welded {
    fn new(scene: &Scene, step: f32) -> Welded {
        let geometry = &scene.geometry;
        let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let mut edges: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
        for (i, v) in geometry.triangles().iter().enumerate() {
            if scene.materials[geometry.triangle_material(i) as usize].is_emissive() {
                continue;
            }
            let t = v.map(|p| {
                let key = (p / step).round().as_dvec3().to_array().map(|x| x as i64);
                *ids.entry(key).or_insert_with(|| {
                    positions.push(p);
                    positions.len() as u32 - 1
                })
            });
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                continue;
            }
            for k in 0..3 {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                edges.entry((a.min(b), a.max(b))).or_default().push(c);
            }
        }
        let mut neighbours = vec![Vec::new(); positions.len()];
        for &(a, b) in edges.keys() {
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
        Welded {
            positions,
            edges,
            neighbours,
        }
    }
}

/// Whether `points` all lie on one side of the plane through `origin`
/// with unit normal `m`, within `tolerance`.
fn one_side(
    points: impl IntoIterator<Item = Vec3A>,
    origin: Vec3A,
    m: Vec3A,
    tolerance: f32,
) -> bool {
    let (mut above, mut below) = (false, false);
    for p in points {
        let d = (p - origin).dot(m);
        above |= d > tolerance;
        below |= d < -tolerance;
    }
    !(above && below)
}

/// One fan of rays: for a parameter s in [0, 1], a source on the light and
/// the point the ray grazes (VE: the light's vertex and a point of the
/// occluder's edge; EV: a point of the light's edge and the occluder's
/// vertex), or for contact lines, a point of the occluder's edge and the
/// direction down its face.
#[derive(Clone, Copy)]
enum Fan {
    Wedge {
        from: [Vec3A; 2],
        through: [Vec3A; 2],
        light_normal: Vec3A,
        two_sided: bool,
        /// The light's extent across the occluder's edge (VE) or across its
        /// own edge (EV): the penumbra's width where the occluder is halfway.
        light_size: f32,
    },
    Contact {
        edge: [Vec3A; 2],
        /// Unit: out of the face, and along it towards the edge.
        out: Vec3A,
        down: Vec3A,
    },
}

/// What the fans need of the scene.
struct Tracer<'a> {
    scene: &'a Scene,
    /// Lengths below which points coincide (a millionth of the diagonal)
    /// and rays start off surfaces.
    tolerance: f32,
    offset: f32,
    rays: u64,
}

impl Tracer<'_> {
    /// Whether triangle `t` is a receiver: diffuse and not emitting.
    fn receiver(&self, t: usize) -> bool {
        // Spheres (primitives past the triangles) are not patches.
        if t >= self.scene.geometry.triangles().len() {
            return false;
        }
        let m = self.scene.geometry.triangle_material(t);
        !self.scene.materials[m as usize].is_emissive() && self.scene.diffuse_albedo(m).is_some()
    }

    /// Where the fan's ray at `s` lands: the receiver triangle and point.
    fn land(&mut self, fan: &Fan, s: f32) -> Option<(u32, Vec3A)> {
        let geometry = &self.scene.geometry;
        let lerp = |p: [Vec3A; 2]| p[0] + s * (p[1] - p[0]);
        let (origin, direction) = match *fan {
            Fan::Wedge {
                from,
                through,
                light_normal,
                two_sided,
                ..
            } => {
                let (source, target) = (lerp(from), lerp(through));
                let d = target - source;
                let length = d.length();
                let cos = d.dot(light_normal) / length;
                if !(length > self.offset) || (!two_sided && cos <= 1e-4) || cos.abs() <= 1e-4 {
                    return None;
                }
                let w = d / length;
                // The light must see the occluder's edge or vertex.
                let side = if cos > 0.0 {
                    light_normal
                } else {
                    -light_normal
                };
                let start = source + side * self.offset;
                let to_target = target - start;
                let mut shadow = Ray::new(start, to_target.normalize());
                shadow.t_max = to_target.length() * (1.0 - 1e-3);
                self.rays += 1;
                if geometry.occluded(&shadow) {
                    return None;
                }
                (target + w * self.offset, w)
            }
            Fan::Contact { edge, out, down } => (lerp(edge) + self.offset * (out - down), down),
        };
        self.rays += 1;
        let hit = geometry.intersect(&Ray::new(origin, direction))?;
        if let Fan::Contact { .. } = fan {
            // A contact ray lands within a few offsets, on a surface the face meets.
            if hit.t > 4.0 * self.offset {
                return None;
            }
        }
        if hit.normal.dot(direction).abs() < 1e-3 || !self.receiver(hit.primitive as usize) {
            return None;
        }
        Some((hit.primitive, hit.point))
    }

    /// The fan's runs on receivers: (triangle, start, end), each a straight
    /// segment. Samples [`FAN_RAYS`] rays, then bisects every change.
    fn runs(&mut self, fan: &Fan, out: &mut Vec<(u32, Vec3A, Vec3A)>) {
        let same =
            |a: Option<(u32, Vec3A)>, b: Option<(u32, Vec3A)>| a.map(|x| x.0) == b.map(|x| x.0);
        // The fan's own ends graze the occluder's corners: kept off them.
        let (first, last) = (1e-3, 1.0 - 1e-3);
        let step = (last - first) / FAN_RAYS as f32;
        let (mut s, mut here) = (first, self.land(fan, first));
        let mut start = here;
        let mut next = first + step;
        loop {
            if s >= last {
                if let (Some((t, a)), Some((_, b))) = (start, here) {
                    out.push((t, a, b));
                }
                return;
            }
            let t = next.min(last);
            let there = self.land(fan, t);
            if same(here, there) {
                (s, here) = (t, there);
                next = t + step;
                continue;
            }
            let (mut lo, mut lo_hit, mut hi, mut hi_hit) = (s, here, t, there);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                let h = self.land(fan, mid);
                if same(h, lo_hit) {
                    (lo, lo_hit) = (mid, h);
                } else {
                    (hi, hi_hit) = (mid, h);
                }
            }
            if let (Some((tri, a)), Some((_, b))) = (start, lo_hit) {
                out.push((tri, a, b));
            }
            (s, here, start) = (hi, hi_hit, hi_hit);
            if next <= s {
                next = s + step;
            }
        }
    }
}

/// Finds the D0 and D1 discontinuities the scene's planar lights cast on
/// its diffuse surfaces.
pub fn find(scene: &Scene) -> Discontinuities {
    let geometry = &scene.geometry;
    let bounds = geometry.bounds();
    let diagonal = (bounds.max - bounds.min).length().max(f32::MIN_POSITIVE);
    let tolerance = 1e-6 * diagonal;
    let mut out = Discontinuities {
        segments: vec![Vec::new(); geometry.triangles().len()],
        ..Discontinuities::default()
    };
    let lights = polygons(scene);
    if lights.is_empty() {
        out.notes.push(
            "discontinuity meshing: no polygonal light (spheres, points and the environment cast \
             no lines)"
                .into(),
        );
        return out;
    }
    let welded = Welded::new(scene, tolerance);
    let mut fans = Vec::new();
    for light in &lights {
        let n = light.corners.len();
        let p0 = light.corners[0];
        // The light's extent across a line along `u` (its diameter where `u`
        // is along the light's normal).
        let diameter = light
            .corners
            .iter()
            .flat_map(|a| light.corners.iter().map(move |b| (*a - *b).length()))
            .fold(0.0, f32::max);
        let extent_across = |u: Vec3A| {
            let d = u.cross(light.normal).normalize_or_zero();
            if d == Vec3A::ZERO {
                return diameter;
            }
            let along = light.corners.iter().map(|c| c.dot(d));
            along.clone().fold(f32::MIN, f32::max) - along.fold(f32::MAX, f32::min)
        };
        let in_front = |p: Vec3A| light.two_sided || (p - p0).dot(light.normal) > tolerance;
        // VE: a light corner and an occluder edge.
        for &corner in &light.corners {
            for (&(a, b), thirds) in &welded.edges {
                let (pa, pb) = (welded.positions[a as usize], welded.positions[b as usize]);
                if !(in_front(pa) || in_front(pb)) {
                    continue;
                }
                let m = (pa - corner).cross(pb - corner).normalize_or_zero();
                let thirds = thirds.iter().map(|&c| welded.positions[c as usize]);
                if m != Vec3A::ZERO
                    && one_side(light.corners.iter().copied(), corner, m, tolerance)
                    && one_side(thirds, pa, m, tolerance)
                {
                    out.wedges[0] += 1;
                    fans.push(Fan::Wedge {
                        from: [corner; 2],
                        through: [pa, pb],
                        light_normal: light.normal,
                        two_sided: light.two_sided,
                        light_size: extent_across(pb - pa),
                    });
                }
            }
        }
        // EV: a light edge and an occluder vertex.
        for k in 0..n {
            let (c0, c1) = (light.corners[k], light.corners[(k + 1) % n]);
            for (v, p) in welded.positions.iter().enumerate() {
                if !in_front(*p) || welded.neighbours[v].is_empty() {
                    continue;
                }
                let m = (c1 - c0).cross(*p - c0).normalize_or_zero();
                let around = welded.neighbours[v]
                    .iter()
                    .map(|&u| welded.positions[u as usize]);
                if m != Vec3A::ZERO
                    && one_side(light.corners.iter().copied(), c0, m, tolerance)
                    && one_side(around, *p, m, tolerance)
                {
                    out.wedges[1] += 1;
                    fans.push(Fan::Wedge {
                        from: [c0, c1],
                        through: [*p; 2],
                        light_normal: light.normal,
                        two_sided: light.two_sided,
                        light_size: extent_across(c1 - c0),
                    });
                }
            }
        }
    }
    if fans.len() > MAX_WEDGES {
        out.notes.push(format!(
            "discontinuity meshing skipped: {} critical wedges, more than {MAX_WEDGES} (the \
             scene is too finely tessellated for lines to pay)",
            fans.len()
        ));
        out.wedges = [0; 3];
        return out;
    }
    // D0: an occluder's edge resting on a receiver, found by a ray down
    // each of its faces just past the edge.
    for (&(a, b), thirds) in &welded.edges {
        let (pa, pb) = (welded.positions[a as usize], welded.positions[b as usize]);
        let along = (pb - pa).normalize_or_zero();
        for &c in thirds {
            let pc = welded.positions[c as usize];
            let out_of_face = along.cross(pc - pa).normalize_or_zero();
            let down = ((pa - pc) - along * (pa - pc).dot(along)).normalize_or_zero();
            if out_of_face != Vec3A::ZERO && down != Vec3A::ZERO {
                for out_dir in [out_of_face, -out_of_face] {
                    fans.push(Fan::Contact {
                        edge: [pa, pb],
                        out: out_dir,
                        down,
                    });
                }
            }
        }
    }
    out.wedges[2] = fans.len() - out.wedges[0] - out.wedges[1];
    let mut tracer = Tracer {
        scene,
        tolerance,
        offset: 1e-4 * diagonal,
        rays: 0,
    };
    let mut runs = Vec::new();
    for fan in &fans {
        // Most edges rest on nothing: three rays along a contact fan
        // decide before the whole fan is traced.
        if let Fan::Contact { .. } = fan
            && [0.05, 0.5, 0.95]
                .iter()
                .all(|&s| tracer.land(fan, s).is_none())
        {
            continue;
        }
        runs.clear();
        tracer.runs(fan, &mut runs);
        let plane = match *fan {
            Fan::Wedge { from, through, .. } => {
                let (p, q) = if from[0] == from[1] {
                    (through[0], through[1])
                } else {
                    (from[0], from[1])
                };
                let apex = if from[0] == from[1] {
                    from[0]
                } else {
                    through[0]
                };
                Some((apex, (p - apex).cross(q - apex).normalize_or_zero()))
            }
            Fan::Contact { .. } => None,
        };
        for &(t, a, b) in &runs {
            let v = geometry.triangles()[t as usize];
            let (a, b) = match (*fan, plane) {
                (Fan::Contact { edge, .. }, _) => {
                    // The edge itself, projected onto the receiver.
                    let n = geometry.triangle_normal(t as usize);
                    let onto = |p: Vec3A| {
                        let on_edge = nearest_on_line(edge, p);
                        on_edge - n * (on_edge - v[0]).dot(n)
                    };
                    (onto(a), onto(b))
                }
                (_, Some((apex, m))) => (
                    snap_to_edges(v, a, apex, m, tracer.tolerance),
                    snap_to_edges(v, b, apex, m, tracer.tolerance),
                ),
                _ => (a, b),
            };
            if (b - a).length() > 1e-3 * diagonal {
                out.segments[t as usize].push(Segment {
                    ends: [a, b],
                    event: match fan {
                        Fan::Contact { .. } => Event::Contact,
                        Fan::Wedge { from, .. } if from[0] == from[1] => Event::VertexEdge,
                        Fan::Wedge { .. } => Event::EdgeVertex,
                    },
                    penumbra: [a, b].map(|p| penumbra_width(fan, p)),
                });
            }
        }
    }
    out.rays = tracer.rays;
    out
}

/// The width of the penumbra a wedge's line bounds, at `p` on it. In the
/// wedge's plane, the ray from the light through the occluder's edge or
/// vertex to `p` is cut by a line through the occluder (the edge, or the
/// parallel to the light's edge through the vertex) in the ratio of the
/// two points' distances to it.
fn penumbra_width(fan: &Fan, p: Vec3A) -> f32 {
    let Fan::Wedge {
        from,
        through,
        light_size,
        ..
    } = *fan
    else {
        return 0.0;
    };
    let (line, source) = if from[0] == from[1] {
        (through, from[0])
    } else {
        ([through[0], through[0] + (from[1] - from[0])], from[0])
    };
    let distance = |q: Vec3A| (q - nearest_on_line(line, q)).length();
    light_size * distance(p) / distance(source).max(f32::MIN_POSITIVE)
}

/// The point of the line through `edge` nearest `p`.
fn nearest_on_line(edge: [Vec3A; 2], p: Vec3A) -> Vec3A {
    let d = edge[1] - edge[0];
    edge[0] + d * ((p - edge[0]).dot(d) / d.length_squared())
}

/// `p` (on triangle `v`, in the plane through `apex` with normal `m`), or,
/// where it lies on an edge of `v`, the plane's crossing with that edge,
/// computed from the edge's ends in a fixed order, so that the triangle
/// across the edge, meshed on its own, gets the same point to the bit.
fn snap_to_edges(v: [Vec3A; 3], p: Vec3A, apex: Vec3A, m: Vec3A, tolerance: f32) -> Vec3A {
    for k in 0..3 {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        let d = nearest_on_line([a, b], p);
        if (d - p).length() > 100.0 * tolerance {
            continue;
        }
        let key = |x: Vec3A| x.to_array().map(f32::to_bits);
        let (x, y) = if key(a) < key(b) { (a, b) } else { (b, a) };
        let along = (y - x).dot(m);
        if along.abs() < 1e-12 {
            continue;
        }
        let t = ((apex - x).dot(m) / along).clamp(0.0, 1.0);
        return x + t * (y - x);
    }
    p
}

/// Per triangle of `meshed` (the scene split into pieces, each of scene
/// triangle `from`), whether it lies inside a contact polygon: a piece of a
/// receiver with contact lines from none of whose points light can leave
/// (every ray meets the inside of what stands there, [`exposure`]). The
/// lines bound such pieces, so none is partly open. Such pieces are not
/// patches (Baum et al. 1991 remove the hidden parts of surfaces that touch):
/// they would cost elements and receive nothing.
pub fn enclosed(meshed: &Scene, from: &[u32], lines: &Discontinuities) -> Vec<bool> {
    let has_contact: Vec<bool> = lines
        .segments
        .iter()
        .map(|s| s.iter().any(|s| s.event == Event::Contact))
        .collect();
    let geometry = &meshed.geometry;
    let two_sided = exposed_backs(meshed);
    geometry
        .triangles()
        .par_iter()
        .enumerate()
        .map(|(i, v)| {
            if !has_contact.get(from[i] as usize).copied().unwrap_or(false) {
                return false;
            }
            let piece = Element::new(i as u32, *v, Rgb::ZERO, Rgb::ZERO);
            piece.area > 0.0 && exposure(geometry, &two_sided, &piece, EXPOSURE_POINTS).0 == 0.0
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_cut_where_its_penumbra_reaches_the_limit() {
        // From a contact (width 0) to a 2 m wide penumbra: a limit of 1 m
        // keeps the first half, 3 m all of it, and a line starting wider
        // than the limit is dropped.
        let line = Segment {
            ends: [Vec3A::ZERO, Vec3A::new(4.0, 0.0, 0.0)],
            event: Event::VertexEdge,
            penumbra: [0.0, 2.0],
        };
        let half = line.narrower_part(1.0).unwrap();
        assert!((half.ends[1] - Vec3A::new(2.0, 0.0, 0.0)).length() < 1e-6);
        assert_eq!(half.ends[0], Vec3A::ZERO);
        assert_eq!(half.penumbra, [0.0, 1.0]);
        let reversed = Segment {
            ends: [line.ends[1], line.ends[0]],
            penumbra: [2.0, 0.0],
            ..line
        };
        let tail = reversed.narrower_part(1.0).unwrap();
        assert!((tail.ends[0] - Vec3A::new(2.0, 0.0, 0.0)).length() < 1e-6);
        assert_eq!(line.narrower_part(3.0).unwrap().ends, line.ends);
        let wide = Segment {
            penumbra: [1.5, 2.0],
            ..line
        };
        assert!(wide.narrower_part(1.0).is_none());
        // Only touching the limit, as a line from a contact at limit 0.
        assert!(line.narrower_part(0.0).is_none());
    }
}
