//! Meshing for radiosity: every diffuse triangle of the scene is a patch,
//! split into elements by midpoint subdivision (4 children per level) until
//! its longest edge is at most the target size. Sizes are fractions of the
//! scene's bounding-box diagonal, so the mesh does not depend on units.

use crate::math::Rgb;
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::Vec3A;

/// One element: a flat triangle of constant radiance.
#[derive(Clone, Copy, Debug)]
pub struct Element {
    /// The scene triangle it subdivides (index in the geometry).
    pub triangle: u32,
    pub vertices: [Vec3A; 3],
    /// Unit normal (the triangle's winding).
    pub normal: Vec3A,
    pub area: f32,
    /// Diffuse reflectance ρ.
    pub reflectance: Rgb,
    /// Emitted radiance (one-sided, along `normal`).
    pub emission: Rgb,
}

impl Element {
    /// The point at barycentrics (b1, b2) of the element.
    #[inline]
    pub fn point(&self, b1: f32, b2: f32) -> Vec3A {
        let [a, b, c] = self.vertices;
        a + b1 * (b - a) + b2 * (c - a)
    }
}

/// The elements of a scene and where each scene triangle's elements are.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub elements: Vec<Element>,
    /// Per scene triangle: its first element and its subdivision depth
    /// (`u32::MAX` where the triangle is not a patch).
    first: Vec<u32>,
    depth: Vec<u8>,
    /// Triangles left out and why (mirrors and glass are traced through).
    pub notes: Vec<String>,
}

/// Deepest subdivision of one triangle (4^8 = 65 536 elements).
const MAX_DEPTH: u8 = 8;

impl Mesh {
    /// Meshes `scene` into elements of at most `size` (fraction of the
    /// bounding-box diagonal) along their longest edge; refuses meshes of
    /// more than `max_elements`, with the count.
    pub fn build(scene: &Scene, size: f32, max_elements: usize) -> Result<Mesh, String> {
        if !(size > 0.0 && size.is_finite()) {
            return Err(format!(
                "patch size {size} is not a positive fraction of the scene's size"
            ));
        }
        let geometry = &scene.geometry;
        let bounds = geometry.bounds();
        let target = size * (bounds.max - bounds.min).length();
        let triangles = geometry.triangles();
        let mut depths = Vec::with_capacity(triangles.len());
        let (mut glossy, mut specular) = (0usize, 0usize);
        let mut total = 0usize;
        for (i, v) in triangles.iter().enumerate() {
            let material = &scene.materials[geometry.triangle_material(i) as usize];
            let diffuse = match material.bsdf {
                Bsdf::Diffuse { .. } => true,
                Bsdf::Glossy { .. } => {
                    glossy += 1;
                    true
                }
                Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => {
                    specular += 1;
                    false
                }
            };
            let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            if !diffuse || !(area > 0.0) {
                depths.push(None);
                continue;
            }
            let longest = (v[1] - v[0])
                .length()
                .max((v[2] - v[1]).length())
                .max((v[0] - v[2]).length());
            let mut depth = 0u8;
            while depth < MAX_DEPTH && longest / (1u32 << depth) as f32 > target {
                depth += 1;
            }
            total += 1usize << (2 * depth);
            depths.push(Some(depth));
        }
        if total == 0 {
            return Err("radiosity needs diffuse surfaces: the scene has none".into());
        }
        if total > max_elements {
            return Err(format!(
                "patch size {size} gives {total} elements, more than the {max_elements} the \
                 form factor matrix fits in memory for: choose a larger --patch-size"
            ));
        }
        let mut mesh = Mesh {
            elements: Vec::with_capacity(total),
            first: Vec::with_capacity(triangles.len()),
            depth: Vec::with_capacity(triangles.len()),
            notes: Vec::new(),
        };
        for (i, (v, depth)) in triangles.iter().zip(depths).enumerate() {
            let Some(depth) = depth else {
                mesh.first.push(u32::MAX);
                mesh.depth.push(0);
                continue;
            };
            let material = &scene.materials[geometry.triangle_material(i) as usize];
            let reflectance = match material.bsdf {
                Bsdf::Diffuse { albedo } => albedo,
                Bsdf::Glossy { diffuse, .. } => diffuse,
                _ => Rgb::ZERO,
            };
            mesh.first.push(mesh.elements.len() as u32);
            mesh.depth.push(depth);
            subdivide(*v, depth, &mut |vertices| {
                let n = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
                mesh.elements.push(Element {
                    triangle: i as u32,
                    vertices,
                    normal: n.normalize(),
                    area: 0.5 * n.length(),
                    reflectance,
                    emission: material.emission,
                });
            });
        }
        if glossy > 0 {
            mesh.notes.push(format!(
                "{glossy} glossy triangles are treated as diffuse with their diffuse reflectance"
            ));
        }
        if specular > 0 {
            mesh.notes.push(format!(
                "{specular} mirror and glass triangles are not patches: they block light between \
                 patches, and camera rays are traced through them (caustics are missing)"
            ));
        }
        if !mesh.elements.iter().any(|e| e.emission.max_element() > 0.0) {
            return Err(
                "radiosity needs an emissive diffuse surface: the scene has none \
                        (point lights and spheres are not patches)"
                    .into(),
            );
        }
        Ok(mesh)
    }

    /// Per element, the radiance at its three vertices ([`vertex_average`]).
    pub fn vertex_average(&self, radiance: &[Rgb]) -> Vec<[Rgb; 3]> {
        vertex_average(self.elements.iter().zip(radiance.iter().copied()))
    }

    /// The element of scene triangle `triangle` that contains the point at
    /// barycentrics (b1, b2) of the triangle, if the triangle is a patch.
    pub fn element_at(&self, triangle: usize, b1: f32, b2: f32) -> Option<usize> {
        let first = *self.first.get(triangle)?;
        if first == u32::MAX {
            return None;
        }
        let mut b = [1.0 - b1 - b2, b1, b2];
        let mut index = 0usize;
        for _ in 0..self.depth[triangle] {
            // The child whose corner weight is at least 1/2, or the middle one.
            let child = (0..3).find(|&k| b[k] >= 0.5).unwrap_or(3);
            b = match child {
                3 => [1.0 - 2.0 * b[0], 1.0 - 2.0 * b[1], 1.0 - 2.0 * b[2]],
                k => {
                    let mut c = [2.0 * b[0], 2.0 * b[1], 2.0 * b[2]];
                    c[k] -= 1.0;
                    c
                }
            };
            index = 4 * index + child;
        }
        Some(first as usize + index)
    }
}

/// Per element, the radiance at its three vertices: the area-weighted mean
/// of the radiance of the elements that share the vertex (same position,
/// exactly: midpoints are computed alike on both sides of an edge) and lie
/// in the same plane, so that walls meeting at a corner keep their own
/// values. A vertex in the middle of a coarser neighbour's edge (a
/// T-vertex of a hierarchy) averages only the elements that have it.
pub fn vertex_average<'a>(
    elements: impl Iterator<Item = (&'a Element, Rgb)> + Clone,
) -> Vec<[Rgb; 3]> {
    use std::collections::HashMap;
    let key = |v: Vec3A, n: Vec3A| {
        let q = |x: f32| (x * 1024.0).round() as i32;
        (v.to_array().map(f32::to_bits), [q(n.x), q(n.y), q(n.z)])
    };
    let mut sums: HashMap<_, (Rgb, f32)> = HashMap::new();
    for (e, l) in elements.clone() {
        for v in e.vertices {
            let entry = sums.entry(key(v, e.normal)).or_insert((Rgb::ZERO, 0.0));
            entry.0 += l * e.area;
            entry.1 += e.area;
        }
    }
    elements
        .map(|(e, _)| {
            e.vertices.map(|v| {
                let (sum, area) = sums[&key(v, e.normal)];
                sum / area
            })
        })
        .collect()
}

/// Calls `emit` for the 4^depth children of triangle `v` in the order
/// [`Mesh::element_at`] numbers them: corner children 0, 1, 2 (at the
/// vertex of that index), then the middle one, recursively.
fn subdivide(v: [Vec3A; 3], depth: u8, emit: &mut impl FnMut([Vec3A; 3])) {
    if depth == 0 {
        emit(v);
        return;
    }
    // m[k] is the midpoint of the edge opposite vertex k.
    let m = [
        0.5 * (v[1] + v[2]),
        0.5 * (v[2] + v[0]),
        0.5 * (v[0] + v[1]),
    ];
    subdivide([v[0], m[2], m[1]], depth - 1, emit);
    subdivide([m[2], v[1], m[0]], depth - 1, emit);
    subdivide([m[1], m[0], v[2]], depth - 1, emit);
    // The middle child: its vertex k is m[k], so its barycentric k is
    // 1 - 2 b_k of the parent's.
    subdivide([m[0], m[1], m[2]], depth - 1, emit);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_lookup_finds_the_element_containing_the_point() {
        let v = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let mut elements = Vec::new();
        subdivide(v, 3, &mut |e| elements.push(e));
        let mesh = Mesh {
            elements: elements
                .iter()
                .map(|&vertices| Element {
                    triangle: 0,
                    vertices,
                    normal: Vec3A::Z,
                    area: 0.0,
                    reflectance: Rgb::ZERO,
                    emission: Rgb::ZERO,
                })
                .collect(),
            first: vec![0],
            depth: vec![3],
            notes: vec![],
        };
        for i in 0..40 {
            for j in 0..40 - i {
                let (b1, b2) = ((i as f32 + 0.3) / 41.0, (j as f32 + 0.3) / 41.0);
                let p = v[0] + b1 * v[1] + b2 * v[2];
                let e = &mesh.elements[mesh.element_at(0, b1, b2).unwrap()];
                // p inside e: all its edge functions agree in sign.
                let [a, b, c] = e.vertices;
                let side = |x: Vec3A, y: Vec3A| (y - x).cross(p - x).z;
                let s = [side(a, b), side(b, c), side(c, a)];
                assert!(
                    s.iter().all(|&x| x >= -1e-6) || s.iter().all(|&x| x <= 1e-6),
                    "{b1} {b2}"
                );
            }
        }
    }
}
