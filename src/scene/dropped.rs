//! What a scene's build drops and checks of its primitives before the
//! BVHs are built.

use super::in_range;
use crate::accel::{Sphere, TriangleInput};
use rayon::prelude::*;

/// Counts of degenerate primitives dropped at build.
#[derive(Default)]
pub(super) struct Dropped {
    pub(super) triangles: usize,
    pub(super) triangle_total: usize,
    pub(super) spheres: usize,
}

impl Dropped {
    /// Keeps triangles with a representable area and normal: a zero-area one
    /// has no normal, no hits and emits nothing.
    pub(super) fn triangles(&mut self, all: Vec<TriangleInput>) -> Vec<TriangleInput> {
        let total = all.len();
        let kept: Vec<TriangleInput> = all.into_iter().filter(|t| !t.is_degenerate()).collect();
        self.triangle_total += total;
        self.triangles += total - kept.len();
        kept
    }

    pub(super) fn spheres(&mut self, all: Vec<Sphere>) -> Vec<Sphere> {
        let total = all.len();
        let kept: Vec<Sphere> = all.into_iter().filter(|s| s.radius > 0.0).collect();
        self.spheres += total - kept.len();
        kept
    }
}

/// What one pass over a scene's triangles finds: a million of them were
/// read once for each of these, the degenerate ones copied out on one core.
#[derive(Default)]
pub(super) struct Survey {
    pub(super) degenerate: usize,
    /// Whether a triangle with an area reaches out of range.
    pub(super) out_of_range: bool,
    /// A material index beyond the scene's materials.
    pub(super) bad_material: Option<u32>,
}

impl Survey {
    pub(super) fn of(triangles: &[TriangleInput], materials: usize) -> Survey {
        let add = |mut s: Survey, t: &TriangleInput| {
            if t.is_degenerate() {
                s.degenerate += 1;
            } else {
                s.out_of_range |= !t.vertices.iter().all(|&v| in_range(v));
                if t.material as usize >= materials {
                    s.bad_material = Some(t.material);
                }
            }
            s
        };
        let merge = |a: Survey, b: Survey| Survey {
            degenerate: a.degenerate + b.degenerate,
            out_of_range: a.out_of_range || b.out_of_range,
            bad_material: a.bad_material.or(b.bad_material),
        };
        (triangles.par_iter().with_min_len(1 << 12))
            .fold(Survey::default, add)
            .reduce(Survey::default, merge)
    }
}
