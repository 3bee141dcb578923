//! Indexed triangle meshes as the importers read them (PLY, Mitsuba's
//! serialized format, glTF, Mitsuba's built-in shapes), placed into the
//! scene by a transform.

use crate::accel::TriangleInput;
use glam::{Mat3A, Mat4, Vec2, Vec3, Vec3A};
use std::f32::consts::TAU;

/// A mesh in its own coordinates.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// Per-vertex normals (smooth shading), if the file has them.
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub indices: Vec<[u32; 3]>,
}

/// How a mesh's orientation follows a mirroring transform.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Orientation {
    /// The front is where the transformed winding says (mesh files in
    /// Mitsuba: a mirror turns them inside out).
    Winding,
    /// The front follows the normal transformed by the inverse transpose
    /// (Mitsuba's analytic shapes: a mirror keeps them outward).
    Normal,
}

/// Where a mesh's triangles go: see [`MeshData::triangles`].
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    to_world: Mat4,
    normal_matrix: Mat3A,
    /// Corners taken in the other order.
    reverse: bool,
    normal_sign: f32,
    face_normals: bool,
    material: u32,
}

impl Placement {
    pub fn new(
        to_world: Mat4,
        orientation: Orientation,
        flip: bool,
        face_normals: bool,
        material: u32,
    ) -> Placement {
        let mirrored = to_world.determinant() < 0.0;
        Placement {
            to_world,
            normal_matrix: Mat3A::from_mat4(to_world).inverse().transpose(),
            reverse: flip ^ (mirrored && orientation == Orientation::Normal),
            normal_sign: if flip { -1.0 } else { 1.0 },
            face_normals,
            material,
        }
    }
}

impl MeshData {
    /// Checks indices and values; the message says what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.positions.len();
        if let Some(bad) = self.indices.iter().flatten().find(|&&i| i as usize >= n) {
            return Err(format!("vertex index {bad} out of range ({n} vertices)"));
        }
        if !self.positions.iter().all(|p| p.is_finite()) {
            return Err("a vertex position is not finite".into());
        }
        for (what, len) in [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("texture coordinates", self.uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(format!("{len} {what} for {n} vertices"));
            }
        }
        Ok(())
    }

    /// The triangles in world space. `flip` turns the front to the back
    /// (Mitsuba's `flip_normals`); `face_normals` drops vertex normals.
    pub fn triangles(
        &self,
        to_world: Mat4,
        orientation: Orientation,
        flip: bool,
        face_normals: bool,
        material: u32,
        out: &mut Vec<TriangleInput>,
    ) {
        let at = Placement::new(to_world, orientation, flip, face_normals, material);
        out.extend((0..self.indices.len()).map(|f| self.triangle(&at, f)));
    }

    /// Face `f` placed by `at`, made on its own so that an importer can
    /// make a scene's triangles on every core (transforming a corner costs
    /// less than writing the triangle).
    #[inline]
    pub fn triangle(&self, at: &Placement, f: usize) -> TriangleInput {
        let [a, b, c] = self.indices[f];
        let order = if at.reverse { [a, c, b] } else { [a, b, c] };
        let vertices =
            order.map(|i| (at.to_world).transform_point3a(Vec3A::from(self.positions[i as usize])));
        let normals = (self.normals.as_ref())
            .filter(|_| !at.face_normals)
            .map(|n| {
                order.map(|i| {
                    (at.normal_matrix * Vec3A::from(n[i as usize])).normalize_or_zero()
                        * at.normal_sign
                })
            })
            .filter(|n| n.iter().all(|v| *v != Vec3A::ZERO && v.is_finite()));
        let uvs = self.uvs.as_ref().map(|uv| order.map(|i| uv[i as usize]));
        TriangleInput {
            vertices,
            material: at.material,
            uvs,
            normals,
        }
    }

    /// Mitsuba's `rectangle`: [-1, 1]² at z = 0, facing +z, uv from the corner (-1, -1).
    pub fn rectangle() -> MeshData {
        MeshData {
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            normals: None,
            uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]),
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// Mitsuba's `cube`: [-1, 1]³, faces outward, each face's uv over [0, 1]².
    pub fn cube() -> MeshData {
        let mut m = MeshData {
            uvs: Some(Vec::new()),
            ..Default::default()
        };
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let n = Vec3::AXES[axis] * sign;
                let u = Vec3::AXES[(axis + 1) % 3];
                let v = n.cross(u);
                let base = m.positions.len() as u32;
                for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                    m.positions
                        .push(n + u * (2.0 * s - 1.0) + v * (2.0 * t - 1.0));
                    m.uvs.as_mut().unwrap().push(Vec2::new(s, t));
                }
                m.indices
                    .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
            }
        }
        m
    }

    /// Mitsuba's `disk` (unit radius at z = 0, facing +z) as a fan of
    /// `segments` triangles whose radius keeps the disk's area.
    pub fn disk(segments: u32) -> MeshData {
        let step = TAU / segments as f32;
        let radius = (TAU / (segments as f32 * step.sin())).sqrt();
        let mut m = MeshData {
            positions: vec![Vec3::ZERO],
            uvs: Some(vec![Vec2::ZERO]),
            ..Default::default()
        };
        for i in 0..segments {
            let phi = i as f32 * step;
            m.positions
                .push(Vec3::new(phi.cos(), phi.sin(), 0.0) * radius);
            m.uvs
                .as_mut()
                .unwrap()
                .push(Vec2::new(1.0, i as f32 / segments as f32));
            m.indices.push([0, 1 + i, 1 + (i + 1) % segments]);
        }
        m
    }

    /// Mitsuba's `cylinder`: an open tube of radius 1 from z = 0 to z = 1,
    /// facing outward, smooth normals.
    pub fn cylinder(segments: u32) -> MeshData {
        let mut m = MeshData {
            normals: Some(Vec::new()),
            uvs: Some(Vec::new()),
            ..Default::default()
        };
        for i in 0..=segments {
            // The seam's two columns at exactly the same points.
            let phi = (i % segments) as f32 * TAU / segments as f32;
            let n = Vec3::new(phi.cos(), phi.sin(), 0.0);
            for z in [0.0, 1.0] {
                m.positions.push(n + Vec3::Z * z);
                m.normals.as_mut().unwrap().push(n);
                m.uvs
                    .as_mut()
                    .unwrap()
                    .push(Vec2::new(i as f32 / segments as f32, z));
            }
        }
        for i in 0..segments {
            let (a, b) = (2 * i, 2 * i + 2);
            m.indices.extend([[a, b, b + 1], [a, b + 1, a + 1]]);
        }
        m
    }

    /// Smooth vertex normals, area-weighted, for a mesh that has none.
    pub fn compute_smooth_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for &[a, b, c] in &self.indices {
            let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
            let n = (pb - pa).cross(pc - pa);
            for i in [a, b, c] {
                normals[i as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        self.normals = Some(normals);
    }
}

/// Vertex normals for triangles that have none, as Blender's auto smooth
/// makes them: at each corner, the normals of the triangles that share its
/// position and meet its own within `max_angle` degrees, each weighted by
/// its angle at that corner (so that how a surface is cut into triangles
/// does not tilt the result). Sharper edges stay sharp; triangles given
/// normals keep them.
pub fn smooth_by_angle(triangles: &mut [TriangleInput], max_angle: f32) {
    use std::collections::HashMap;
    let cos_max = max_angle.to_radians().cos();
    let key = |v: Vec3A| v.to_array().map(f32::to_bits);
    let face: Vec<Vec3A> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.vertices;
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let corner_angle = |t: &TriangleInput, k: usize| {
        let v = t.vertices;
        let (e1, e2) = (v[(k + 1) % 3] - v[k], v[(k + 2) % 3] - v[k]);
        e1.normalize_or_zero()
            .dot(e2.normalize_or_zero())
            .clamp(-1.0, 1.0)
            .acos()
    };
    // Per position, the (triangle, weighted normal) pairs that touch it.
    let mut sharing: HashMap<[u32; 3], Vec<(u32, Vec3A)>> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        if t.normals.is_none() {
            for k in 0..3 {
                let weighted = face[i] * corner_angle(t, k);
                sharing
                    .entry(key(t.vertices[k]))
                    .or_default()
                    .push((i as u32, weighted));
            }
        }
    }
    for i in 0..triangles.len() {
        let own = face[i];
        if triangles[i].normals.is_some() || own == Vec3A::ZERO {
            continue;
        }
        let normals = triangles[i].vertices.map(|v| {
            let mut n = Vec3A::ZERO;
            for &(j, weighted) in &sharing[&key(v)] {
                if face[j as usize].dot(own) >= cos_max {
                    n += weighted;
                }
            }
            n.normalize_or_zero()
        });
        if normals.iter().all(|n| *n != Vec3A::ZERO) {
            triangles[i].normals = Some(normals);
        }
    }
}

/// A UV sphere of `rings` × `segments` quads (two triangles each; the
/// poles' fans degenerate to one), outward-facing.
pub fn uv_sphere(center: Vec3A, radius: f32, rings: u32, segments: u32) -> Vec<[Vec3A; 3]> {
    use std::f32::consts::PI;
    let point = |ring: u32, seg: u32| {
        let theta = PI * ring as f32 / rings as f32;
        let phi = 2.0 * PI * seg as f32 / segments as f32;
        center
            + radius
                * Vec3A::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                )
    };
    let mut triangles = Vec::with_capacity((2 * rings * segments) as usize);
    for ring in 0..rings {
        for seg in 0..segments {
            let (a, b) = (point(ring, seg), point(ring, seg + 1));
            let (c, d) = (point(ring + 1, seg + 1), point(ring + 1, seg));
            if ring > 0 {
                triangles.push([a, d, b]);
            }
            if ring + 1 < rings {
                triangles.push([b, d, c]);
            }
        }
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_by_angle_rounds_a_cylinder_and_keeps_a_cube_sharp() {
        let mut cube = Vec::new();
        MeshData::cube().triangles(
            Mat4::IDENTITY,
            Orientation::Normal,
            false,
            false,
            0,
            &mut cube,
        );
        smooth_by_angle(&mut cube, 30.0);
        for t in &cube {
            let [a, b, c] = t.vertices;
            let face = (b - a).cross(c - a).normalize();
            for n in t.normals.unwrap() {
                assert!(
                    (n - face).length() < 1e-6,
                    "cube edges are 90 degrees: sharp"
                );
            }
        }
        // A 24-gon band: neighbours meet at 15 degrees, so corners average.
        let ring = MeshData::cylinder(24);
        let mut band = Vec::new();
        let flat = MeshData {
            normals: None,
            ..ring
        };
        flat.triangles(
            Mat4::IDENTITY,
            Orientation::Normal,
            false,
            false,
            0,
            &mut band,
        );
        smooth_by_angle(&mut band, 30.0);
        for t in &band {
            for (v, n) in t.vertices.iter().zip(t.normals.unwrap()) {
                let radial = Vec3A::new(v.x, v.y, 0.0).normalize();
                assert!((n - radial).length() < 1e-5, "{n} vs {radial}");
            }
        }
    }

    fn area(m: &MeshData) -> f32 {
        m.indices
            .iter()
            .map(|&[a, b, c]| {
                let [pa, pb, pc] = [a, b, c].map(|i| m.positions[i as usize]);
                0.5 * (pb - pa).cross(pc - pa).length()
            })
            .sum()
    }

    #[test]
    fn built_in_shapes_have_mitsubas_areas_and_face_outward() {
        assert!((area(&MeshData::rectangle()) - 4.0).abs() < 1e-6);
        assert!((area(&MeshData::cube()) - 24.0).abs() < 1e-5);
        assert!((area(&MeshData::disk(64)) - std::f32::consts::PI).abs() < 1e-4);
        let cube = MeshData::cube();
        for &[a, b, c] in &cube.indices {
            let [pa, pb, pc] = [a, b, c].map(|i| cube.positions[i as usize]);
            let centroid = (pa + pb + pc) / 3.0;
            assert!((pb - pa).cross(pc - pa).dot(centroid) > 0.0);
        }
    }

    #[test]
    fn a_mirror_keeps_analytic_shapes_facing_out_and_turns_meshes_inside_out() {
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let facing = |orientation| {
            let mut out = Vec::new();
            MeshData::rectangle().triangles(mirror, orientation, false, false, 0, &mut out);
            let [a, b, c] = out[0].vertices;
            (b - a).cross(c - a).z
        };
        assert!(facing(Orientation::Normal) > 0.0);
        assert!(facing(Orientation::Winding) < 0.0);
    }
}
