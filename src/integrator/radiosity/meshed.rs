//! Radiosity on a scene split along its shadows' discontinuity lines
//! ([`crate::radiosity::discontinuity`]).

use crate::scene::Scene;

/// A scene split along its discontinuity lines.
pub struct Meshed {
    pub scene: std::sync::Arc<Scene>,
    /// Per triangle of `scene`, which of its edges (opposite the vertex of
    /// that index) lie on a discontinuity line.
    pub on_line: Vec<[bool; 3]>,
    /// Per triangle of `scene`, whether it is a piece that contact lines
    /// enclose (the floor under a block): not a patch.
    pub hidden: Vec<bool>,
    pub lines: usize,
}

impl Meshed {
    /// `scene` as it is, no edge on a line.
    pub fn whole(scene: Scene) -> Meshed {
        Meshed {
            on_line: vec![[false; 3]; scene.geometry.triangle_count()],
            hidden: Vec::new(),
            scene: std::sync::Arc::new(scene),
            lines: 0,
        }
    }

    /// The pieces' edges that lie on discontinuity lines, for the smooth
    /// display's one-sided fits.
    pub fn line_edges(&self) -> Vec<crate::radiosity::reconstruct::LineEdge> {
        let triangles = self.scene.geometry.triangles();
        triangles
            .iter()
            .zip(&self.on_line)
            .flat_map(|(v, flags)| {
                let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
                (0..3)
                    .filter(|&i| flags[i])
                    .map(move |i| crate::radiosity::reconstruct::LineEdge {
                        ends: [v[(i + 1) % 3], v[(i + 2) % 3]],
                        normal,
                    })
            })
            .collect()
    }
}

/// `scene` split along the discontinuities its polygonal lights cast, and
/// notes saying what was found. With a base (the matrix solvers), the
/// receivers are meshed as it says, keeping a penumbra's lines only where
/// it is narrower than the limit beside it, if any.
pub(super) fn discontinuity_mesh(
    scene: &Scene,
    base: Option<(crate::radiosity::discontinuity::Base, Option<f32>)>,
) -> (Meshed, Vec<String>) {
    use crate::radiosity::discontinuity;
    let found = discontinuity::find(scene);
    let total = found.count();
    let lines = match base {
        Some((_, Some(limit))) => found.narrower_than(limit),
        _ => found,
    };
    let (pieces, left_whole) = discontinuity::split(scene, &lines, base.map(|(b, _)| b));
    let corners: Vec<Vec<[glam::Vec3A; 3]>> = pieces
        .iter()
        .map(|p| p.iter().map(|p| p.vertices).collect())
        .collect();
    let (meshed, from) = scene.with_pieces(&corners);
    let hidden = discontinuity::enclosed(&meshed, &from, &lines);
    // Pieces are found again by their corners, which the split keeps to the bit.
    let key = |v: &[glam::Vec3A; 3]| v.map(|p| p.to_array().map(f32::to_bits));
    let flags: std::collections::HashMap<_, [bool; 3]> = pieces
        .iter()
        .flatten()
        .map(|p| (key(&p.vertices), p.on_line))
        .collect();
    let on_line: Vec<[bool; 3]> = meshed
        .geometry
        .triangles()
        .iter()
        .map(|v| flags.get(&key(v)).copied().unwrap_or_default())
        .collect();
    let count = lines.count();
    let kept = if count == total {
        String::new()
    } else {
        format!(" ({count} kept, in penumbrae narrower than the limit)")
    };
    let split = pieces.iter().filter(|p| !p.is_empty()).count();
    let mut notes = lines.notes;
    let enclosed = hidden.iter().filter(|&&h| h).count();
    if enclosed > 0 {
        notes.push(format!(
            "{enclosed} pieces enclosed by contact lines (under what stands on them) are not \
             patches: no light reaches or leaves them"
        ));
    }
    if left_whole > 0 {
        notes.push(format!(
            "{left_whole} elements that lines cross left whole: a piece would have been smaller \
             than the minimum piece area"
        ));
    }
    notes.push(format!(
        "discontinuity meshing: {} critical wedges (VE {}, EV {}) and {} contact tests, {} rays, \
         gave {} line segments{kept}; {split} triangles split into {} pieces",
        lines.wedges[0] + lines.wedges[1],
        lines.wedges[0],
        lines.wedges[1],
        lines.wedges[2],
        lines.rays,
        total,
        pieces.iter().map(Vec::len).sum::<usize>(),
    ));
    (
        Meshed {
            scene: std::sync::Arc::new(meshed),
            on_line,
            hidden,
            lines: count,
        },
        notes,
    )
}
