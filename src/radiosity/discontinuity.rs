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

use crate::math::Ray;
use crate::scene::Scene;
use crate::scene::light::Light;
use glam::Vec3A;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::{BTreeMap, HashMap};

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
                });
            }
        }
    }
    out.rays = tracer.rays;
    out
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

/// Splits receiver triangles along their discontinuities: a constrained
/// Delaunay triangulation of the triangle's corners and its segments, the
/// segments constraints (crossing ones split each other), refined by
/// spade's Delaunay refinement to angles of at least [`MIN_ANGLE`].
///
/// With `max_edge` (scene units; the matrix solvers' element size), every
/// receiver is meshed so, lines or not, into pieces of about that size:
/// the triangle's edges are cut at points that depend only on the edge,
/// so the triangle across it, meshed on its own, has the same ones and
/// the mesh has no T-vertices. Without (the hierarchy, which subdivides
/// on its own), only triangles with lines are split, and only along them.
/// Per scene triangle, its pieces, or none where it stays whole.
pub fn split(scene: &Scene, lines: &Discontinuities, max_edge: Option<f32>) -> Vec<Vec<Piece>> {
    let geometry = &scene.geometry;
    let tracer = Tracer {
        scene,
        tolerance: 0.0,
        offset: 0.0,
        rays: 0,
    };
    lines
        .segments
        .iter()
        .enumerate()
        .map(|(t, segments)| {
            if segments.is_empty() && !(max_edge.is_some() && tracer.receiver(t)) {
                Vec::new()
            } else {
                split_triangle(geometry.triangles()[t], segments, max_edge)
            }
        })
        .collect()
}

/// Smallest angle of a piece that refinement aims for (spade terminates
/// reliably up to about 30° with its constraints kept).
pub const MIN_ANGLE: f64 = 20.0;

fn split_triangle(v: [Vec3A; 3], segments: &[Segment], max_edge: Option<f32>) -> Vec<Piece> {
    use spade::handles::FixedVertexHandle;
    use spade::{AngleLimit, RefinementParameters};
    type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;
    let e1 = v[1] - v[0];
    let n = e1.cross(v[2] - v[0]).normalize_or_zero();
    if n == Vec3A::ZERO {
        return Vec::new();
    }
    let u = e1.normalize();
    let w = n.cross(u);
    let longest = (v[1] - v[0])
        .length()
        .max((v[2] - v[1]).length())
        .max((v[0] - v[2]).length()) as f64;
    // Points closer than this are one (a thousandth of the triangle).
    let merge = 1e-3 * longest;
    // The plane's 2D frame, scaled to the longest edge, with corners on a
    // grid of 2^-24 and points on an edge placed at a grid fraction along
    // it: such points are exactly on the edge's line in f64, which spade's
    // exact predicates need (points a rounding off it made its refinement
    // fail to locate circumcentres).
    let grid = |x: f64| (x * 16_777_216.0).round() / 16_777_216.0;
    let corners_2d = {
        let frame = |p: Vec3A| {
            let d = p - v[0];
            Point2::new(
                grid(d.dot(u) as f64 / longest),
                grid(d.dot(w) as f64 / longest),
            )
        };
        v.map(frame)
    };
    let normal = (v[1] - v[0]).cross(v[2] - v[0]);
    let inverse = 1.0 / normal.length_squared();
    // Barycentrics of a 3D point, clamped into the triangle, with those
    // below a thousandth set to 0 (the point is on an edge or a corner).
    let barycentrics = |p: Vec3A| {
        let b1 = ((p - v[0]).cross(v[2] - v[0]).dot(normal) * inverse).max(0.0) as f64;
        let b2 = ((v[1] - v[0]).cross(p - v[0]).dot(normal) * inverse).max(0.0) as f64;
        let b0 = (1.0 - b1 - b2).max(0.0);
        let mut b = [b0, b1, b2].map(|x| if x < 1e-3 { 0.0 } else { x });
        let sum: f64 = b.iter().sum();
        b.iter_mut().for_each(|x| *x /= sum);
        b
    };
    // The 2D point at barycentrics b: on edge i (corner i to i + 1, the
    // others' weight 0) as corner i plus a grid fraction of the edge.
    let place = |b: [f64; 3]| {
        for i in 0..3 {
            if b[(i + 2) % 3] == 0.0 {
                let (a, c) = (corners_2d[i], corners_2d[(i + 1) % 3]);
                let t = grid(b[(i + 1) % 3]);
                return Point2::new(a.x + t * (c.x - a.x), a.y + t * (c.y - a.y));
            }
        }
        let [a, c, d] = corners_2d;
        Point2::new(
            a.x + b[1] * (c.x - a.x) + b[2] * (d.x - a.x),
            a.y + b[1] * (c.y - a.y) + b[2] * (d.y - a.y),
        )
    };
    let merge = merge / longest;
    let to_2d = |p: Vec3A| place(barycentrics(p));
    // Back to 3D by the 2D point's barycentrics.
    let from_2d = |p: Point2<f64>| {
        let [a, c, d] = corners_2d;
        let det = (c.x - a.x) * (d.y - a.y) - (d.x - a.x) * (c.y - a.y);
        let b1 = ((p.x - a.x) * (d.y - a.y) - (d.x - a.x) * (p.y - a.y)) / det;
        let b2 = ((c.x - a.x) * (p.y - a.y) - (p.x - a.x) * (c.y - a.y)) / det;
        v[0] + (b1 as f32) * (v[1] - v[0]) + (b2 as f32) * (v[2] - v[0])
    };
    // Distance from the edge from corner i to corner i + 1, and how far
    // along it (0 to 1), in 2D.
    let edge_coordinates = |p: Point2<f64>, i: usize| {
        let (a, b) = (corners_2d[i], corners_2d[(i + 1) % 3]);
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let length2 = dx * dx + dy * dy;
        let off = ((p.x - a.x) * dy - (p.y - a.y) * dx).abs() / length2.sqrt();
        (off, ((p.x - a.x) * dx + (p.y - a.y) * dy) / length2)
    };
    let mut cdt = Cdt::new();
    // The 3D point of each vertex the triangulation was given, by its
    // index: corners, edge points and segment ends keep theirs to the bit
    // (the neighbour across an edge has the same); points that refinement
    // or crossing constraints add get theirs from the plane.
    let mut exact: Vec<Option<Vec3A>> = Vec::new();
    let mut given: Vec<(Point2<f64>, FixedVertexHandle)> = Vec::new();
    let mut insert = |cdt: &mut Cdt, p3: Vec3A| {
        let p = to_2d(p3);
        if let Some(&(q, h)) = given
            .iter()
            .find(|(q, _)| (q.x - p.x).hypot(q.y - p.y) < merge)
        {
            return Some((h, q));
        }
        let handle = cdt.insert(p).ok()?;
        if exact.len() <= handle.index() {
            exact.resize(handle.index() + 1, None);
        }
        exact[handle.index()] = Some(p3);
        given.push((p, handle));
        Some((handle, p))
    };
    // Per edge of the triangle, the vertices on it with how far along.
    let mut on_edges: [Vec<(f64, FixedVertexHandle)>; 3] = Default::default();
    for (i, corner) in v.into_iter().enumerate() {
        if let Some((h, _)) = insert(&mut cdt, corner) {
            on_edges[i].push((0.0, h));
            on_edges[(i + 2) % 3].push((1.0, h));
        }
    }
    let note_on_edges = |h: FixedVertexHandle, p: Point2<f64>, on_edges: &mut [Vec<_>; 3]| {
        for (i, list) in on_edges.iter_mut().enumerate() {
            let (off, t) = edge_coordinates(p, i);
            if off < merge && t > 0.0 && t < 1.0 && !list.iter().any(|&(_, g)| g == h) {
                list.push((t, h));
            }
        }
    };
    if let Some(max_edge) = max_edge {
        for i in 0..3 {
            let (a, b) = (v[i], v[(i + 1) % 3]);
            let key = |x: Vec3A| x.to_array().map(f32::to_bits);
            let (x, y) = if key(a) < key(b) { (a, b) } else { (b, a) };
            let cuts = ((y - x).length() / max_edge).ceil() as u32;
            for k in 1..cuts {
                let p3 = x + (k as f32 / cuts as f32) * (y - x);
                if let Some((h, p)) = insert(&mut cdt, p3) {
                    note_on_edges(h, p, &mut on_edges);
                }
            }
        }
    }
    // The lines, each a chain of constraints through points at most
    // `max_edge` apart.
    let mut lines_2d = Vec::with_capacity(segments.len());
    let mut chains = Vec::with_capacity(segments.len());
    for s in segments {
        let [a, b] = s.ends;
        let parts = max_edge.map_or(1, |m| ((b - a).length() / m).ceil().max(1.0) as u32);
        let mut chain = Vec::with_capacity(parts as usize + 1);
        for k in 0..=parts {
            let p3 = a + (k as f32 / parts as f32) * (b - a);
            if let Some((h, p)) = insert(&mut cdt, p3) {
                note_on_edges(h, p, &mut on_edges);
                if chain.last() != Some(&h) {
                    chain.push(h);
                }
            }
        }
        let (pa, pb) = (to_2d(a), to_2d(b));
        // A line along the triangle's own edge (a crease the contact test
        // meets) splits nothing.
        let along_edge =
            (0..3).any(|i| edge_coordinates(pa, i).0 < merge && edge_coordinates(pb, i).0 < merge);
        if chain.len() > 1 && !along_edge {
            lines_2d.push((pa, pb));
            chains.push(chain);
        }
    }
    // The triangle's edges first, as constraints through every point on
    // them, so that neither the lines nor refinement cut them elsewhere.
    for list in &mut on_edges {
        list.sort_by(|a, b| a.0.total_cmp(&b.0));
        for pair in list.windows(2) {
            if pair[0].1 != pair[1].1 {
                cdt.add_constraint_and_split(pair[0].1, pair[1].1, |p| p);
            }
        }
    }
    for chain in &chains {
        for pair in chain.windows(2) {
            cdt.add_constraint_and_split(pair[0], pair[1], |p| p);
        }
    }
    let mut parameters = RefinementParameters::<f64>::new()
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(MIN_ANGLE))
        .with_max_additional_vertices(10 * cdt.num_vertices() + 1000);
    if let Some(max_edge) = max_edge {
        // An equilateral triangle's area at that edge length.
        let m = max_edge as f64;
        parameters = parameters.with_max_allowed_area(0.433 * m * m);
    }
    cdt.refine(parameters);
    // Whether the edge from p to q lies on one of the lines.
    let on_a_line = |p: Point2<f64>, q: Point2<f64>| {
        let mid = Point2::new(0.5 * (p.x + q.x), 0.5 * (p.y + q.y));
        lines_2d.iter().any(|&(a, b): &(Point2<f64>, Point2<f64>)| {
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let length2 = dx * dx + dy * dy;
            let t = ((mid.x - a.x) * dx + (mid.y - a.y) * dy) / length2;
            let off = ((mid.x - a.x) * dy - (mid.y - a.y) * dx).abs() / length2.sqrt();
            (-1e-6..=1.0 + 1e-6).contains(&t) && off < 0.1 * merge
        })
    };
    cdt.inner_faces()
        .filter_map(|face| {
            let vertices = face.vertices();
            let p = vertices.map(|h| {
                exact
                    .get(h.fix().index())
                    .copied()
                    .flatten()
                    .unwrap_or_else(|| from_2d(h.position()))
            });
            // Slivers where lines nearly meet can come out flat or wound
            // the other way in f32: a millionth of the triangle is nothing.
            if (p[1] - p[0]).cross(p[2] - p[0]).dot(normal) <= 1e-6 * normal.length_squared() {
                return None;
            }
            // Edge i runs from vertex i to i + 1: opposite vertex i + 2.
            let mut on_line = [false; 3];
            for (i, e) in face.adjacent_edges().iter().enumerate() {
                on_line[(i + 2) % 3] = e.as_undirected().data().is_constraint_edge()
                    && on_a_line(e.from().position(), e.to().position());
            }
            Some(Piece {
                vertices: p,
                on_line,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crossing_pair_splits_a_triangle_into_pieces_that_tile_it() {
        let v = [
            Vec3A::ZERO,
            Vec3A::new(2.0, 0.0, 0.0),
            Vec3A::new(0.0, 2.0, 0.0),
        ];
        let segment = |a: [f32; 2], b: [f32; 2]| Segment {
            ends: [Vec3A::new(a[0], a[1], 0.0), Vec3A::new(b[0], b[1], 0.0)],
            event: Event::VertexEdge,
        };
        let pieces = split_triangle(
            v,
            &[
                segment([0.2, 0.2], [1.0, 0.5]),
                segment([0.3, 0.6], [0.8, 0.1]),
            ],
            None,
        );
        let area: f32 = pieces
            .iter()
            .map(|p| {
                0.5 * (p.vertices[1] - p.vertices[0])
                    .cross(p.vertices[2] - p.vertices[0])
                    .z
            })
            .sum();
        // Every piece wound like the triangle (positive z), covering it.
        assert!(pieces.iter().all(|p| {
            (p.vertices[1] - p.vertices[0])
                .cross(p.vertices[2] - p.vertices[0])
                .z
                > 0.0
        }));
        assert!((area - 2.0).abs() < 1e-5, "{area}");
        // Every piece at least MIN_ANGLE (a little less where a line's end
        // leaves no room), and the lines' edges each shared by two pieces.
        let lines: usize = pieces
            .iter()
            .map(|p| p.on_line.iter().filter(|&&b| b).count())
            .sum();
        assert!(lines >= 8 && lines % 2 == 0, "{lines}");
    }
}
