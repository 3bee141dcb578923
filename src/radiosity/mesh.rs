//! Meshing for radiosity: every diffuse triangle of the scene is a patch,
//! split into elements by midpoint subdivision (4 children per level) until
//! its longest edge is at most the target size. Sizes are fractions of the
//! scene's bounding-box diagonal, so the mesh does not depend on units.
//! Adaptive subdivision ([`Mesh::refine`]) splits elements further where
//! the solution changes fast between neighbours, so each patch keeps a
//! quadtree of its elements.

use super::VertexField;
pub use super::element::Element;
use super::reconstruct::vertex_key;
use crate::accel::Geometry;
use crate::math::Rgb;
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::Vec3A;
use rayon::prelude::*;

/// The elements of a scene and where each scene triangle's elements are.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub elements: Vec<Element>,
    /// Per element, its subdivision level (0: the scene triangle itself).
    pub levels: Vec<u8>,
    /// Per scene triangle, its root cell (`NONE` where it is not a patch),
    /// and that of its back ([`exposed_backs`]; empty if no triangle has one).
    roots: Vec<u32>,
    back_roots: Vec<u32>,
    cells: Vec<Cell>,
    /// Per scene triangle, whether its back is a patch of its own.
    pub two_sided: Vec<bool>,
    /// Triangles left out and why (mirrors and glass are traced through).
    pub notes: Vec<String>,
}

/// A node of a patch's quadtree.
#[derive(Clone, Copy, Debug)]
enum Cell {
    /// An element (its index).
    Leaf(u32),
    /// The first of four consecutive child cells, numbered as [`subdivide`] does.
    Inner(u32),
}

const NONE: u32 = u32::MAX;

/// Deepest subdivision of one triangle (4^8 = 65 536 elements).
const MAX_DEPTH: u8 = 8;

impl Mesh {
    /// Meshes `scene` into elements of at most `size` (fraction of the
    /// bounding-box diagonal) along their longest edge; refuses meshes of
    /// more than `max_elements`, with the count. Triangles marked in
    /// `hidden` (empty: none) have no front patch: discontinuity meshing's
    /// pieces that contact lines enclose, which no light reaches or leaves.
    pub fn build(
        scene: &Scene,
        size: f32,
        max_elements: usize,
        hidden: &[bool],
    ) -> Result<Mesh, String> {
        if !(size > 0.0 && size.is_finite()) {
            return Err(format!(
                "patch size {size} is not a positive fraction of the scene's size"
            ));
        }
        let geometry = &scene.geometry;
        let bounds = geometry.bounds();
        let target = size * (bounds.max - bounds.min).length();
        let triangles = geometry.triangles();
        let two_sided = exposed_backs(scene);
        let mut depths = Vec::with_capacity(triangles.len());
        let (mut glossy, mut specular) = (0usize, 0usize);
        let mut total = 0usize;
        for (i, v) in triangles.iter().enumerate() {
            let diffuse = match scene.diffuse_albedo(geometry.triangle_material(i)) {
                Some((_, approximated)) => {
                    glossy += usize::from(approximated);
                    true
                }
                None => {
                    specular += 1;
                    false
                }
            };
            let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            if !diffuse || !(area > 0.0) {
                depths.push(None);
                continue;
            }
            let depth = depth_for(longest_edge(v), target);
            let front = !hidden.get(i).copied().unwrap_or(false);
            total += (1usize << (2 * depth)) * (usize::from(front) + usize::from(two_sided[i]));
            depths.push(Some(depth));
        }
        if total == 0 {
            return Err("radiosity needs diffuse surfaces: the scene has none".into());
        }
        if total > max_elements {
            // Refused before allocating: n² form factors of 4 bytes.
            let bytes = (total as f64).powi(2) * 4.0;
            return Err(format!(
                "patch size {size} gives {total} elements, whose form factor matrix would take \
                 {:.1} GB, more than the {max_elements} elements ({:.1} GB) allowed: choose a \
                 larger --patch-size",
                bytes * 1e-9,
                (max_elements as f64).powi(2) * 4e-9
            ));
        }
        let mut mesh = Mesh {
            elements: Vec::with_capacity(total),
            levels: Vec::with_capacity(total),
            roots: Vec::with_capacity(triangles.len()),
            back_roots: Vec::new(),
            cells: Vec::new(),
            two_sided,
            notes: Vec::new(),
        };
        if mesh.two_sided.contains(&true) {
            mesh.back_roots = vec![NONE; triangles.len()];
        }
        for (i, (v, depth)) in triangles.iter().zip(depths).enumerate() {
            let Some(depth) = depth else {
                mesh.roots.push(NONE);
                continue;
            };
            let reflectance = scene
                .diffuse_albedo(geometry.triangle_material(i))
                .map_or(Rgb::ZERO, |(a, _)| a);
            let root = Element {
                triangle: i as u32,
                vertices: *v,
                normal: Vec3A::ZERO,
                area: 0.0,
                reflectance,
                emission: scene.triangle_emission(i),
            };
            if hidden.get(i).copied().unwrap_or(false) {
                mesh.roots.push(NONE);
            } else {
                mesh.roots.push(mesh.cells.len() as u32);
                mesh.cells.push(Cell::Leaf(NONE));
                mesh.grow(mesh.roots[i], root, 0, depth);
            }
            if mesh.two_sided[i] {
                mesh.back_roots[i] = mesh.cells.len() as u32;
                mesh.cells.push(Cell::Leaf(NONE));
                mesh.grow(
                    mesh.back_roots[i],
                    back_of(&root, triangles.len()),
                    0,
                    depth,
                );
            }
        }
        let backs = mesh.back_roots.iter().filter(|&&r| r != NONE).count();
        if backs > 0 {
            mesh.notes.push(format!(
                "{backs} thin triangles lit from behind are patches on both sides"
            ));
        }
        if glossy > 0 {
            mesh.notes.push(format!(
                "{glossy} glossy, rough diffuse, plastic, textured or blended triangles are treated as \
                 diffuse with their (mean, blended) diffuse reflectance"
            ));
        }
        if specular > 0 {
            mesh.notes.push(format!(
                "{specular} mirror, conductor and glass triangles are not patches: they block light between \
                 patches, and camera rays are traced through them (caustics are missing)"
            ));
        }
        mesh.notes.extend(light_notes(scene));
        if !mesh.elements.iter().any(|e| e.emission.max_element() > 0.0) {
            return Err(
                "radiosity needs an emissive diffuse surface: the scene has none \
                        (point lights and spheres are not patches)"
                    .into(),
            );
        }
        Ok(mesh)
    }

    /// Fills `cell` with `element` split `depth` more levels below `level`.
    fn grow(&mut self, cell: u32, element: Element, level: u8, depth: u8) {
        if depth == 0 {
            self.cells[cell as usize] = Cell::Leaf(self.elements.len() as u32);
            self.elements.push(Element::new(
                element.triangle,
                element.vertices,
                element.reflectance,
                element.emission,
            ));
            self.levels.push(level);
            return;
        }
        let first = self.cells.len() as u32;
        self.cells[cell as usize] = Cell::Inner(first);
        self.cells.extend([Cell::Leaf(NONE); 4]);
        for (k, vertices) in children(element.vertices).into_iter().enumerate() {
            let child = Element {
                vertices,
                ..element
            };
            self.grow(first + k as u32, child, level + 1, depth - 1);
        }
    }

    /// A copy with each element for which `split` holds divided in four
    /// (elements at the deepest level stay), and per new element the index
    /// of the element it comes from.
    pub fn refine(&self, split: &[bool]) -> (Mesh, Vec<u32>) {
        let mut mesh = Mesh {
            elements: Vec::with_capacity(self.elements.len()),
            levels: Vec::with_capacity(self.elements.len()),
            roots: Vec::with_capacity(self.roots.len()),
            back_roots: Vec::with_capacity(self.back_roots.len()),
            cells: Vec::with_capacity(self.cells.len()),
            two_sided: self.two_sided.clone(),
            notes: self.notes.clone(),
        };
        let mut origin = Vec::with_capacity(self.elements.len());
        for (roots, back) in [(&self.roots, false), (&self.back_roots, true)] {
            for &root in roots {
                let copy = if root == NONE {
                    NONE
                } else {
                    let copy = mesh.cells.len() as u32;
                    mesh.cells.push(Cell::Leaf(NONE));
                    self.copy_cell(root, copy, &mut mesh, split, &mut origin);
                    copy
                };
                if back {
                    mesh.back_roots.push(copy);
                } else {
                    mesh.roots.push(copy);
                }
            }
        }
        (mesh, origin)
    }

    fn copy_cell(
        &self,
        from: u32,
        to: u32,
        mesh: &mut Mesh,
        split: &[bool],
        origin: &mut Vec<u32>,
    ) {
        match self.cells[from as usize] {
            Cell::Leaf(e) => {
                let level = self.levels[e as usize];
                let depth = u8::from(split[e as usize] && level < MAX_DEPTH);
                let before = mesh.elements.len();
                mesh.grow(to, self.elements[e as usize], level, depth);
                origin.extend(std::iter::repeat_n(e, mesh.elements.len() - before));
            }
            Cell::Inner(first) => {
                let first_new = mesh.cells.len() as u32;
                mesh.cells[to as usize] = Cell::Inner(first_new);
                mesh.cells.extend([Cell::Leaf(NONE); 4]);
                for k in 0..4 {
                    self.copy_cell(first + k, first_new + k, mesh, split, origin);
                }
            }
        }
    }

    /// Adaptive subdivision's test: per element, whether its reflected
    /// radiance L - E differs from a neighbour's by more than `tolerance`
    /// times the area-weighted mean over the mesh, in any colour channel
    /// (the red and green walls' gradients hardly show in luminance).
    /// Neighbours are the smooth display's ([`super::reconstruct`]): they
    /// share a vertex, lie in the same plane (walls meeting at a corner may
    /// differ) and emit alike; across a T-vertex only the elements that have
    /// it count; where discontinuity `lines` pass through a vertex, only
    /// the elements on the same side (the mesh already holds that jump, and
    /// splitting along it spends elements for nothing). Elements with an
    /// angle under `min_angle` degrees are never steep: midpoint
    /// subdivision would make four as thin.
    pub fn steep(
        &self,
        radiance: &[Rgb],
        tolerance: f32,
        min_angle: f32,
        lines: &[super::reconstruct::LineEdge],
    ) -> Vec<bool> {
        use std::collections::HashMap;
        let reflected: Vec<Rgb> = self
            .elements
            .iter()
            .zip(radiance)
            .map(|(e, l)| *l - e.emission)
            .collect();
        let area: f32 = self.elements.iter().map(|e| e.area).sum();
        let mean = self
            .elements
            .iter()
            .zip(&reflected)
            .map(|(e, l)| e.area * *l)
            .sum::<Rgb>()
            / area;
        let crossing = super::reconstruct::LinesAtVertices::new(self.elements.iter(), lines);
        let mut range: HashMap<_, (Rgb, Rgb)> = HashMap::new();
        for (e, &l) in self.elements.iter().zip(&reflected) {
            for v in e.vertices {
                let r = range
                    .entry((vertex_key(v, e), crossing.side(v, e)))
                    .or_insert((l, l));
                *r = (r.0.min(l), r.1.max(l));
            }
        }
        // One threshold for every channel, as the image error weighs them.
        let limit = Rgb::splat(tolerance * (mean.x + mean.y + mean.z) / 3.0);
        self.elements
            .iter()
            .map(|e| {
                smallest_angle(&e.vertices) >= min_angle
                    && e.vertices.iter().any(|&v| {
                        let (low, high) = range[&(vertex_key(v, e), crossing.side(v, e))];
                        (high - low).cmpgt(limit).any()
                    })
            })
            .collect()
    }

    /// The smooth display's radiance: per element, its three vertices'
    /// ([`super::reconstruct::vertex_radiance`]), and the T-vertices of an
    /// adaptive mesh ([`VertexField`]). Elements no light leaves
    /// (`exposure` 0: the floor under a block) are left out of their
    /// neighbours' fits and vertices, and shown flat: at a block's foot
    /// they would pull the lit floor's vertices towards their darkness
    /// (the jump a discontinuity mesh's contact lines are there to keep).
    pub fn vertex_radiance(
        &self,
        radiance: &[Rgb],
        exposure: &[f32],
        lines: &[super::reconstruct::LineEdge],
    ) -> VertexField {
        let visible: Vec<usize> = (0..self.elements.len())
            .filter(|&k| exposure.get(k).is_none_or(|&x| x > 0.0))
            .collect();
        let fitted = super::reconstruct::vertex_radiance(
            visible.iter().map(|&k| (&self.elements[k], radiance[k])),
            lines,
        );
        let mut corners: Vec<[Rgb; 3]> = radiance.iter().map(|&l| [l; 3]).collect();
        for (&k, c) in visible.iter().zip(fitted) {
            corners[k] = c;
        }
        VertexField::new(visible.iter().map(|&k| (k, &self.elements[k])), corners)
    }

    /// The element of scene triangle `triangle`, or of its back, that
    /// contains the point at barycentrics (b1, b2) of the triangle, if that
    /// side is a patch.
    pub fn element_at(&self, triangle: usize, back: bool, b1: f32, b2: f32) -> Option<usize> {
        let roots = if back { &self.back_roots } else { &self.roots };
        let mut cell = *roots.get(triangle)?;
        if cell == NONE {
            return None;
        }
        // A back's root lists the triangle's corners 0, 2, 1.
        let mut b = if back {
            [1.0 - b1 - b2, b2, b1]
        } else {
            [1.0 - b1 - b2, b1, b2]
        };
        loop {
            match self.cells[cell as usize] {
                Cell::Leaf(e) => return Some(e as usize),
                Cell::Inner(first) => {
                    let child = child_at(&mut b);
                    cell = first + child as u32;
                }
            }
        }
    }
}

/// The smallest angle of triangle `v`, in degrees.
pub fn smallest_angle(v: &[Vec3A; 3]) -> f32 {
    let angle = |i: usize| (v[(i + 1) % 3] - v[i]).angle_between(v[(i + 2) % 3] - v[i]);
    angle(0).min(angle(1)).min(angle(2)).to_degrees()
}

/// The longest edge of triangle `v`.
pub fn longest_edge(v: &[Vec3A; 3]) -> f32 {
    (v[1] - v[0])
        .length()
        .max((v[2] - v[1]).length())
        .max((v[0] - v[2]).length())
}

/// How many times a triangle whose longest edge is `longest` is split in
/// four for elements of at most `target` along their longest edge.
pub fn depth_for(longest: f32, target: f32) -> u8 {
    let mut depth = 0u8;
    while depth < MAX_DEPTH && longest / (1u32 << depth) as f32 > target {
        depth += 1;
    }
    depth
}

/// The four children of triangle `v` by midpoint subdivision: corner
/// children 0, 1, 2 (at the vertex of that index), then the middle one;
/// points in space or barycentric coordinates in the plane.
pub fn children<T>(v: [T; 3]) -> [[T; 3]; 4]
where
    T: Copy + std::ops::Add<Output = T>,
    f32: std::ops::Mul<T, Output = T>,
{
    // m[k] is the midpoint of the edge opposite vertex k.
    let m = [
        0.5 * (v[1] + v[2]),
        0.5 * (v[2] + v[0]),
        0.5 * (v[0] + v[1]),
    ];
    // The middle child: its vertex k is m[k], so its barycentric k is
    // 1 - 2 b_k of the parent's.
    [
        [v[0], m[2], m[1]],
        [m[2], v[1], m[0]],
        [m[1], m[0], v[2]],
        [m[0], m[1], m[2]],
    ]
}

/// The child of [`children`] that holds the point at barycentrics `b`, and
/// `b` updated to the child's barycentrics.
pub fn child_at(b: &mut [f32; 3]) -> usize {
    // The child whose corner weight is at least 1/2, or the middle one.
    let child = (0..3).find(|&k| b[k] >= 0.5).unwrap_or(3);
    *b = match child {
        3 => [1.0 - 2.0 * b[0], 1.0 - 2.0 * b[1], 1.0 - 2.0 * b[2]],
        k => {
            let mut c = [2.0 * b[0], 2.0 * b[1], 2.0 * b[2]];
            c[k] -= 1.0;
            c
        }
    };
    child
}

/// Notes on the lights radiosity cannot see as they are (only emissive
/// patches emit in it, each uniformly).
pub(crate) fn light_notes(scene: &Scene) -> Vec<String> {
    let mut notes = Vec::new();
    if scene.features.point_lights || scene.lights.environment().is_some() {
        notes.push(
            "point, spot and directional lights and the environment are not patches: \
             radiosity ignores them"
                .to_string(),
        );
    }
    let textured = (0..scene.geometry.triangle_count())
        .filter(|&i| {
            let m = &scene.materials[scene.geometry.triangle_material(i) as usize];
            m.is_emissive() && m.emission_texture.is_some()
        })
        .count();
    if textured > 0 {
        notes.push(format!(
            "{textured} triangles with textured emission emit their texture's mean over each \
             triangle, uniformly"
        ));
    }
    notes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two halves of a square, bright and dark, meet along a line: without
    /// the line every element is steep; with it each side is uniform and
    /// none is (the mesh already holds the jump).
    #[test]
    fn adaptive_subdivision_does_not_split_across_a_discontinuity_line() {
        let p = |x: f32, y: f32| Vec3A::new(x, y, 0.0);
        let element = |v| Element::new(0, v, Rgb::splat(0.5), Rgb::ZERO);
        let mesh = Mesh {
            elements: vec![
                element([p(-1.0, 0.0), p(0.0, 0.0), p(0.0, 1.0)]),
                element([p(-1.0, 0.0), p(0.0, 1.0), p(-1.0, 1.0)]),
                element([p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)]),
                element([p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]),
            ],
            ..Mesh::default()
        };
        let radiance = [1.0, 1.0, 0.2, 0.2].map(Rgb::splat);
        let line = super::super::reconstruct::LineEdge {
            ends: [p(0.0, 0.0), p(0.0, 1.0)],
            normal: Vec3A::Z,
        };
        assert_eq!(mesh.steep(&radiance, 0.5, 0.0, &[]), [true; 4]);
        assert_eq!(mesh.steep(&radiance, 0.5, 0.0, &[line]), [false; 4]);
    }

    /// With a smallest angle to split, a sliver beside a steep change stays
    /// whole (its four children would be as thin); its well-shaped
    /// neighbour across the same change splits.
    #[test]
    fn adaptive_subdivision_leaves_slivers_whole() {
        let p = |x: f32, y: f32| Vec3A::new(x, y, 0.0);
        let element = |v| Element::new(0, v, Rgb::splat(0.5), Rgb::ZERO);
        let sliver = [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.2)];
        // atan(0.2) at the shared corner.
        assert!((smallest_angle(&sliver) - 11.31).abs() < 0.01);
        let mesh = Mesh {
            elements: vec![
                element([p(-1.0, 0.0), p(0.0, 0.0), p(0.0, 1.0)]),
                element(sliver),
            ],
            ..Mesh::default()
        };
        let radiance = [1.0, 0.2].map(Rgb::splat);
        assert_eq!(mesh.steep(&radiance, 0.5, 0.0, &[]), [true, true]);
        assert_eq!(mesh.steep(&radiance, 0.5, 20.0, &[]), [true, false]);
    }

    #[test]
    fn element_lookup_finds_the_element_containing_the_point() {
        let v = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let root = Element {
            triangle: 0,
            vertices: v,
            normal: Vec3A::Z,
            area: 0.5,
            reflectance: Rgb::ZERO,
            emission: Rgb::ZERO,
        };
        let mut uniform = Mesh {
            roots: vec![0],
            cells: vec![Cell::Leaf(NONE)],
            ..Mesh::default()
        };
        uniform.grow(0, root, 0, 2);
        // One more level on every other element: an adaptive mesh.
        let split: Vec<bool> = (0..uniform.elements.len()).map(|k| k % 2 == 0).collect();
        let (mesh, origin) = uniform.refine(&split);
        assert_eq!(mesh.elements.len(), 8 * 4 + 8);
        let area: f32 = mesh.elements.iter().map(|e| e.area).sum();
        assert!((area - 0.5).abs() < 1e-6, "{area}");
        for i in 0..40 {
            for j in 0..40 - i {
                let (b1, b2) = ((i as f32 + 0.3) / 41.0, (j as f32 + 0.3) / 41.0);
                let p = v[0] + b1 * v[1] + b2 * v[2];
                let k = mesh.element_at(0, false, b1, b2).unwrap();
                // p inside the element and its origin: all edge functions agree in sign.
                let inside = |[a, b, c]: [Vec3A; 3]| {
                    let side = |x: Vec3A, y: Vec3A| (y - x).cross(p - x).z;
                    let s = [side(a, b), side(b, c), side(c, a)];
                    s.iter().all(|&x| x >= -1e-6) || s.iter().all(|&x| x <= 1e-6)
                };
                assert!(inside(mesh.elements[k].vertices), "{b1} {b2}");
                assert!(inside(uniform.elements[origin[k] as usize].vertices));
            }
        }
    }
}

/// Per scene triangle, its back twin: the triangle with the same corners
/// facing the other way (a table top made of two quads, one per side), or
/// `u32::MAX`. A camera ray may meet either of two coincident triangles;
/// met from behind, one shows its twin's solution. Corners match to a
/// millionth of the scene's diagonal, so units do not matter.
pub fn back_twins(geometry: &Geometry) -> Vec<u32> {
    let bounds = geometry.bounds();
    let step = 1e-6 * (bounds.max - bounds.min).length().max(f32::MIN_POSITIVE);
    let key = |v: [Vec3A; 3]| {
        let mut corners = v.map(|p| (p / step).round().as_ivec3().to_array());
        corners.sort_unstable();
        corners
    };
    let triangles = geometry.triangles();
    let mut by_corners =
        rustc_hash::FxHashMap::with_capacity_and_hasher(triangles.len(), Default::default());
    for (t, v) in triangles.iter().enumerate() {
        by_corners
            .entry(key(*v))
            .or_insert_with(Vec::new)
            .push(t as u32);
    }
    let normal = |v: &[Vec3A; 3]| (v[1] - v[0]).cross(v[2] - v[0]);
    triangles
        .iter()
        .map(|v| {
            let n = normal(v);
            by_corners[&key(*v)]
                .iter()
                .copied()
                .find(|&o| normal(&triangles[o as usize]).dot(n) < 0.0)
                .unwrap_or(u32::MAX)
        })
        .collect()
}

/// The back of patch `front` (of scene triangle `front.triangle` among
/// `triangles`): its corners 0, 2, 1, facing the other way, reflecting
/// alike and emitting nothing (emitters are one-sided). Its patch number is
/// the triangle's plus the triangle count, so that shooting keeps the two
/// sides apart.
pub fn back_of(front: &Element, triangles: usize) -> Element {
    let [a, b, c] = front.vertices;
    Element {
        triangle: front.triangle + triangles as u32,
        vertices: [a, c, b],
        normal: -front.normal,
        emission: Rgb::ZERO,
        ..*front
    }
}

/// Rays from a triangle's back that decide whether it is a patch of its own.
const BACK_RAYS: u32 = 16;

/// Per scene triangle, whether its back is a patch of its own (a thin
/// surface lit on both sides: a lamp shade, a panel, a single-quad table):
/// diffuse, emitting nothing, without a coincident twin facing the other
/// way ([`back_twins`]), and such that one of [`BACK_RAYS`] cosine rays from
/// its back meets the front of a diffuse surface at a point light can
/// leave. Walls seen from outside a room see nothing; a block's faces seen
/// from inside it see only the floor under it, which no light reaches.
pub fn exposed_backs(scene: &Scene) -> Vec<bool> {
    use super::form_factor::{open_at, point_on};
    use crate::sampling::{Sampler, SamplerKind};
    let geometry = &scene.geometry;
    let twins = back_twins(geometry);
    let diffuse = |material: u32| {
        let m = &scene.materials[material as usize];
        matches!(m.bsdf, Bsdf::Diffuse { .. } | Bsdf::Glossy { .. })
    };
    let none = vec![false; geometry.triangles().len()];
    let exposed = |i: usize, v: &[Vec3A; 3]| -> bool {
        let material = geometry.triangle_material(i);
        let front = Element::new(i as u32, *v, Rgb::ZERO, Rgb::ZERO);
        if twins[i] != u32::MAX
            || !diffuse(material)
            || scene.materials[material as usize].emission.max_element() > 0.0
            || !(front.area > 0.0)
        {
            return false;
        }
        let back = back_of(&front, 0);
        let frame = crate::math::Frame::from_normal(back.normal);
        let mut sampler = Sampler::new(SamplerKind::Stratified, 0x5eed_0004, BACK_RAYS);
        (0..BACK_RAYS).any(|k| {
            sampler.start(i as u32, k);
            let (x, x_error) = point_on(&back, sampler.next_2d());
            let w = frame.to_world(crate::sampling::warp::square_to_cosine_hemisphere(
                sampler.next_2d(),
            ));
            let origin = crate::math::offset_ray_origin(x, x_error, back.normal, w);
            let Some(hit) = geometry.intersect(&crate::math::Ray::new(origin, w)) else {
                return false;
            };
            hit.normal.dot(w) < 0.0
                && diffuse(hit.material)
                && open_at(
                    geometry,
                    &none,
                    hit.point,
                    hit.error,
                    hit.normal,
                    sampler.next_2d(),
                )
                .0
        })
    };
    // In parallel: each triangle's rays are its own (on one thread, this
    // was about half of the serial time of a solve of a sphere of 100 000
    // triangles).
    geometry
        .triangles()
        .par_iter()
        .enumerate()
        .map(|(i, v)| exposed(i, v))
        .collect()
}
