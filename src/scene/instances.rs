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

    /// Per placement, the eight corners of its prototype's box (`None`
    /// for an empty prototype), in its own space and placed: what framing
    /// and range checks need, without copying any triangle.
    pub fn placed_corners(&self) -> impl Iterator<Item = Option<[(Vec3A, Vec3A); 8]>> + '_ {
        let boxes: Vec<(Vec3A, Vec3A)> = self.prototypes.iter().map(|p| bounds(p)).collect();
        self.placements.iter().map(move |&(p, to_world)| {
            let (lo, hi) = *boxes.get(p as usize)?;
            (lo.cmple(hi).all()).then(|| {
                std::array::from_fn(|c| {
                    let pick = |axis: usize| if c >> axis & 1 == 0 { lo } else { hi };
                    let local = Vec3A::new(pick(0).x, pick(1).y, pick(2).z);
                    (local, to_world.transform_point3a(local))
                })
            })
        })
    }
}

/// The box around `triangles` (inverted when there are none).
fn bounds(triangles: &[TriangleInput]) -> (Vec3A, Vec3A) {
    triangles.iter().flat_map(|t| t.vertices).fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(v), hi.max(v)),
    )
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
    let input = InstancesInput {
        prototypes: input
            .prototypes
            .into_iter()
            .map(|p| dropped.triangles(p))
            .collect(),
        placements: input.placements,
    };
    let corners: Vec<_> = input.placed_corners().collect();
    let prototypes = input.prototypes;
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
    for ((prototype, to_world), corners) in input.placements.into_iter().zip(corners) {
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
        let reach = |(local, placed): &(Vec3A, Vec3A)| in_range(*local) && in_range(*placed);
        if corners.is_some_and(|c| !c.iter().all(reach)) {
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
