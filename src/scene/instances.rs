//! Instances as loaders give them ([`InstancesInput`]), checked and sorted
//! at build into what is shared and what is copied.

use super::material::Material;
use super::{Dropped, MAX_COORDINATE, in_range};
use crate::accel::TriangleInput;
use crate::error::{Error, Result};
use glam::{Affine3A, Vec3A};

/// Shared geometry placed several times (Mitsuba's `shapegroup` and
/// `instance`): each prototype's triangles are stored and searched once.
#[derive(Clone, Debug, Default)]
pub struct InstancesInput {
    /// Each prototype's triangles, in its own space.
    pub prototypes: Vec<Vec<TriangleInput>>,
    /// (prototype, to world) per instance. A transform must be invertible
    /// and keep orientation (loaders copy a mirrored instance instead).
    pub placements: Vec<(u32, Affine3A)>,
}

impl InstancesInput {
    /// The prototype's triangles placed by `to_world`, as copies.
    pub fn copy(prototype: &[TriangleInput], to_world: Affine3A) -> Vec<TriangleInput> {
        let normals = to_world.matrix3.inverse().transpose();
        prototype
            .iter()
            .map(|t| TriangleInput {
                vertices: t.vertices.map(|v| to_world.transform_point3a(v)),
                normals: t.normals.map(|n| n.map(|n| (normals * n).normalize())),
                ..*t
            })
            .collect()
    }
}

/// Checks the instances and keeps what can be shared: prototypes without
/// degenerate triangles, placed by transforms in range. A prototype with
/// an emitter is copied into `triangles` at each placement (a light is
/// sampled where it is), as is each mirrored placement (see
/// [`InstancesInput`]). Returns the prototypes and the shared placements.
#[allow(clippy::type_complexity)]
pub(super) fn checked(
    input: InstancesInput,
    materials: &[Material],
    triangles: &mut Vec<TriangleInput>,
    dropped: &mut Dropped,
) -> Result<(Vec<Vec<TriangleInput>>, Vec<(u32, Affine3A)>)> {
    let prototypes: Vec<Vec<TriangleInput>> = input
        .prototypes
        .into_iter()
        .map(|p| dropped.triangles(p))
        .collect();
    let bounds: Vec<(Vec3A, Vec3A)> = prototypes
        .iter()
        .map(|p| {
            p.iter().flat_map(|t| t.vertices).fold(
                (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                |(lo, hi), v| (lo.min(v), hi.max(v)),
            )
        })
        .collect();
    // Per prototype, once: whether it emits (then it is copied).
    let mut emits = Vec::with_capacity(prototypes.len());
    for p in &prototypes {
        let mut any = false;
        for t in p {
            let material = materials.get(t.material as usize).ok_or_else(|| {
                Error::new("internal: a prototype's triangle refers to no material")
            })?;
            any |= material.is_emissive();
        }
        emits.push(any);
    }
    let mut placements = Vec::new();
    for (prototype, to_world) in input.placements {
        let Some(local) = prototypes.get(prototype as usize) else {
            return Err(Error::new(format!(
                "internal: an instance of prototype {prototype}"
            )));
        };
        let det = to_world.matrix3.determinant();
        if !(to_world.is_finite() && det.is_normal()) {
            return Err(Error::new(
                "an instance's transform is singular or not finite",
            ));
        }
        let (lo, hi) = bounds[prototype as usize];
        let corners = (0..8).map(|c: u32| {
            let pick = |axis: u32, lo: f32, hi: f32| if c >> axis & 1 == 0 { lo } else { hi };
            Vec3A::new(
                pick(0, lo.x, hi.x),
                pick(1, lo.y, hi.y),
                pick(2, lo.z, hi.z),
            )
        });
        let reach = |p: Vec3A| in_range(p) && in_range(to_world.transform_point3a(p));
        if !local.is_empty() && !corners.into_iter().all(reach) {
            return Err(Error::new(format!(
                "an instance reaches beyond ±{MAX_COORDINATE:e} (or is not finite): areas and distances would overflow"
            )));
        }
        if emits[prototype as usize] || det < 0.0 {
            triangles.extend(InstancesInput::copy(local, to_world));
        } else if !local.is_empty() {
            placements.push((prototype, to_world));
        }
    }
    Ok((prototypes, placements))
}
