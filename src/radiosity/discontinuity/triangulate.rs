//! Receivers split along their discontinuity lines: spade's constrained
//! Delaunay triangulation and refinement, with points on a triangle's
//! edges placed so that neighbours meshed on their own agree.

use super::{Discontinuities, Piece, Segment, Tracer};
use crate::scene::Scene;
use glam::Vec3A;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// How a matrix solver's receivers are meshed around their lines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Base {
    /// Every receiver, lines or not, by constrained Delaunay refinement with
    /// points at most `max_edge` apart along its edges and lines.
    Delaunay { max_edge: f32 },
    /// The regular elements of the mesh without lines (edges at most
    /// `max_edge`, [`crate::radiosity::Mesh::build`]'s depth), only those a
    /// line crosses triangulated along it; receivers without lines stay
    /// whole for the mesh to subdivide the same way. An element whose
    /// pieces would include one smaller than `min_piece` of its area stays
    /// whole: a sliver costs an element and adds little (docs/validation.md).
    Regular { max_edge: f32, min_piece: f32 },
}

/// Splits receiver triangles along their discontinuities: a constrained
/// Delaunay triangulation of the triangle's corners and its segments, the
/// segments constraints (crossing ones split each other), refined by
/// spade's Delaunay refinement to angles of at least [`MIN_ANGLE`].
///
/// With a `base` (the matrix solvers' elements), receivers are meshed as it
/// says. The two are complementary on the Cornell box (docs/validation.md):
/// Delaunay pieces are fewer for a coarse size, the regular base keeps the
/// walls' regular elements at fine ones. Without (the hierarchy, which
/// subdivides on its own), only triangles with lines are split, and only
/// along them. Per scene triangle, its pieces, or none where it stays whole;
/// and how many regular elements that lines cross were left whole
/// ([`Base::Regular`]'s `min_piece`).
pub fn split(
    scene: &Scene,
    lines: &Discontinuities,
    base: Option<Base>,
) -> (Vec<Vec<Piece>>, usize) {
    let geometry = &scene.geometry;
    let tracer = Tracer {
        scene,
        tolerance: 0.0,
        offset: 0.0,
        rays: 0,
    };
    let mut left_whole = 0;
    let pieces = lines
        .segments
        .iter()
        .enumerate()
        .map(|(t, segments)| {
            let v = geometry.triangles()[t];
            let receiver = || tracer.receiver(t);
            match base {
                None if segments.is_empty() => Vec::new(),
                None => split_triangle(v, segments, None),
                Some(Base::Delaunay { max_edge }) if !segments.is_empty() || receiver() => {
                    split_triangle(v, segments, Some(max_edge))
                }
                Some(Base::Regular {
                    max_edge,
                    min_piece,
                }) if !segments.is_empty() => {
                    let (pieces, whole) = split_regular(v, segments, max_edge, min_piece);
                    left_whole += whole;
                    pieces
                }
                // Left whole: the mesh subdivides it (a receiver without
                // lines on the regular base).
                Some(_) => Vec::new(),
            }
        })
        .collect();
    (pieces, left_whole)
}

/// Triangle `v` cut into the regular elements of the mesh without lines
/// (edges at most `max_edge`), each element that `segments` cross split
/// along the part of them inside it, unless a piece would be smaller than
/// `min_piece` of its area; and how many crossed elements stayed whole.
fn split_regular(
    v: [Vec3A; 3],
    segments: &[Segment],
    max_edge: f32,
    min_piece: f32,
) -> (Vec<Piece>, usize) {
    let lines: Vec<&Segment> = segments.iter().filter(|s| !along_an_edge(s, &v)).collect();
    let longest = crate::radiosity::mesh::longest_edge(&v);
    let depth = crate::radiosity::mesh::depth_for(longest, max_edge);
    let mut elements = vec![v];
    for _ in 0..depth {
        elements = elements
            .into_iter()
            .flat_map(crate::radiosity::mesh::children)
            .collect();
    }
    let mut pieces = Vec::with_capacity(elements.len());
    let mut inside = Vec::new();
    let mut left_whole = 0;
    let area = |v: &[Vec3A; 3]| (v[1] - v[0]).cross(v[2] - v[0]).length();
    for element in elements {
        inside.clear();
        inside.extend(lines.iter().filter_map(|s| clip(s, &element)));
        let split = match inside.is_empty() {
            true => Vec::new(),
            false => split_triangle(element, &inside, None),
        };
        let smallest = split
            .iter()
            .map(|p| area(&p.vertices))
            .fold(f32::MAX, f32::min);
        if split.is_empty() || smallest < min_piece * area(&element) {
            left_whole += usize::from(!split.is_empty());
            pieces.push(Piece {
                vertices: element,
                on_line: [false; 3],
            });
        } else {
            pieces.extend(split);
        }
    }
    (pieces, left_whole)
}

/// Whether segment `s` lies along one of triangle `v`'s edges (within a
/// thousandth of its longest edge): a crease's contact line, which splits
/// nothing.
fn along_an_edge(s: &Segment, v: &[Vec3A; 3]) -> bool {
    let tolerance = 1e-3 * crate::radiosity::mesh::longest_edge(v);
    (0..3).any(|i| {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        let direction = (b - a).normalize_or_zero();
        s.ends.iter().all(|&p| {
            let d = p - a;
            (d - d.dot(direction) * direction).length() < tolerance
        })
    })
}

/// The part of segment `s` inside triangle `v` (both in one plane), unless
/// it is shorter than a thousandth of the triangle's longest edge.
fn clip(s: &Segment, v: &[Vec3A; 3]) -> Option<Segment> {
    let normal = (v[1] - v[0]).cross(v[2] - v[0]);
    let inverse = 1.0 / normal.length_squared();
    // Barycentric i of point p: the sub-triangle opposite vertex i.
    let weight = |p: Vec3A, i: usize| {
        let (a, b) = (v[(i + 1) % 3], v[(i + 2) % 3]);
        (b - a).cross(p - a).dot(normal) * inverse
    };
    let [a, b] = s.ends;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for i in 0..3 {
        let (wa, wb) = (weight(a, i), weight(b, i));
        // w(t) = wa + t (wb - wa) >= 0.
        if wa < 0.0 && wb < 0.0 {
            return None;
        }
        if wa < 0.0 {
            t0 = t0.max(wa / (wa - wb));
        } else if wb < 0.0 {
            t1 = t1.min(wa / (wa - wb));
        }
    }
    let longest = crate::radiosity::mesh::longest_edge(v);
    if (t1 - t0) * (b - a).length() <= 1e-3 * longest {
        return None;
    }
    let [wa, wb] = s.penumbra;
    Some(Segment {
        ends: [a + t0 * (b - a), a + t1 * (b - a)],
        event: s.event,
        penumbra: [wa + t0 * (wb - wa), wa + t1 * (wb - wa)],
    })
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
    // Angles only: the points on the edges and lines already space the
    // pieces by `max_edge`. An area bound of an equilateral piece of that
    // edge (in this frame's units) made the Cornell box's pieces smaller but
    // not its error at equal element count (docs/validation.md).
    let parameters = RefinementParameters::<f64>::new()
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(MIN_ANGLE))
        .with_max_additional_vertices(10 * cdt.num_vertices() + 1000);
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
    use crate::radiosity::discontinuity::Event;

    /// The pieces' signed area, for pieces in the z = 0 plane.
    fn area_in_xy(pieces: &[Piece]) -> f32 {
        pieces
            .iter()
            .map(|p| {
                0.5 * (p.vertices[1] - p.vertices[0])
                    .cross(p.vertices[2] - p.vertices[0])
                    .z
            })
            .sum()
    }

    #[test]
    fn the_regular_base_keeps_the_elements_no_line_crosses() {
        let v = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        // From edge to edge, so that the line's sides are the segment's.
        let line = Segment {
            ends: [Vec3A::new(0.0, 0.55, 0.0), Vec3A::new(0.65, 0.0, 0.0)],
            event: Event::VertexEdge,
            penumbra: [0.0; 2],
        };
        // Longest edge √2 at most 0.3: three levels, 64 elements.
        let (pieces, _) = split_regular(v, &[line], 0.3, 0.0);
        let mut regular = vec![v];
        for _ in 0..3 {
            regular = regular
                .into_iter()
                .flat_map(crate::radiosity::mesh::children)
                .collect();
        }
        let side = |p: Vec3A| {
            let [a, b] = line.ends;
            (b - a).cross(p - a).z
        };
        let crossed = |e: &[Vec3A; 3]| clip(&line, e).is_some();
        let kept = regular.iter().filter(|e| !crossed(e)).count();
        assert!(kept < 64 && kept > 40, "{kept}");
        // Every element the line misses is a piece as it is.
        for e in regular.iter().filter(|e| !crossed(e)) {
            assert!(pieces.iter().any(|p| p.vertices == *e), "{e:?}");
        }
        // The pieces tile the triangle, and none straddles the line.
        let area = area_in_xy(&pieces);
        assert!((area - 0.5).abs() < 1e-5, "{area}");
        for p in &pieces {
            let sides = p.vertices.map(side);
            let (lo, hi) = sides
                .iter()
                .fold((0.0f32, 0.0f32), |(l, h), &x| (l.min(x), h.max(x)));
            assert!(lo > -1e-5 || hi < 1e-5, "{p:?} straddles the line");
        }
    }

    #[test]
    fn an_element_whose_piece_would_be_a_sliver_stays_whole() {
        let v = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let line = |a: f32| Segment {
            ends: [Vec3A::new(a, 0.0, 0.0), Vec3A::new(0.0, a, 0.0)],
            event: Event::VertexEdge,
            penumbra: [0.0; 2],
        };
        // One element (edges under 2); the corner line's piece is 0.25% of it.
        let (pieces, whole) = split_regular(v, &[line(0.05)], 2.0, 0.01);
        assert_eq!((pieces.len(), whole), (1, 1));
        assert_eq!(pieces[0].vertices, v);
        assert_eq!(pieces[0].on_line, [false; 3]);
        let (pieces, whole) = split_regular(v, &[line(0.05)], 2.0, 0.0);
        assert!(pieces.len() > 1 && whole == 0, "{}", pieces.len());
        // A line through the middle leaves no piece under a tenth: split.
        let (pieces, whole) = split_regular(v, &[line(0.5)], 2.0, 0.01);
        assert!(pieces.len() > 1 && whole == 0, "{}", pieces.len());
        assert!(pieces.iter().any(|p| p.on_line != [false; 3]));
    }

    #[test]
    fn a_line_along_the_receivers_edge_leaves_its_regular_elements_whole() {
        // A crease's contact line, traced a thousandth of the edge short
        // of its corners (as on the Cornell box's walls): its ends, inside
        // the corner elements' edges, used to split them for nothing (20
        // pieces for a wall's 16 elements there).
        let v = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let crease = Segment {
            ends: [Vec3A::new(1e-3, 0.0, 0.0), Vec3A::new(0.999, 0.0, 0.0)],
            event: Event::VertexEdge,
            penumbra: [0.0; 2],
        };
        let (pieces, _) = split_regular(v, &[crease], 0.3, 0.0);
        assert_eq!(pieces.len(), 64);
        assert!(pieces.iter().all(|p| p.on_line == [false; 3]));
    }

    #[test]
    fn pieces_do_not_depend_on_the_scenes_units() {
        // A receiver in metres and the same in millimetres, with a line
        // and element size 0.15 m; an area bound in scene units once
        // refined the first and not the second.
        let mesh = |scale: f32| {
            let v = [
                Vec3A::ZERO,
                Vec3A::new(0.55, 0.0, 0.0),
                Vec3A::new(0.0, 0.0, 0.55),
            ]
            .map(|p| scale * p);
            let line = Segment {
                ends: [Vec3A::new(0.1, 0.0, 0.0), Vec3A::new(0.0, 0.0, 0.3)].map(|p| scale * p),
                event: Event::VertexEdge,
                penumbra: [0.0; 2],
            };
            split_triangle(v, &[line], Some(0.15 * scale))
        };
        let (metres, millimetres) = (mesh(1.0), mesh(1000.0));
        assert_eq!(metres.len(), millimetres.len());
        for (a, b) in metres.iter().zip(&millimetres) {
            for (p, q) in a.vertices.iter().zip(&b.vertices) {
                assert!((1000.0 * *p - *q).abs().max_element() < 1e-3, "{p} {q}");
            }
            assert_eq!(a.on_line, b.on_line);
        }
    }

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
            penumbra: [0.0; 2],
        };
        let pieces = split_triangle(
            v,
            &[
                segment([0.2, 0.2], [1.0, 0.5]),
                segment([0.3, 0.6], [0.8, 0.1]),
            ],
            None,
        );
        let area = area_in_xy(&pieces);
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
