//! What VCM keeps of a light subpath's vertices: all of each for the
//! connections, in path order, and what a merge reads for the photon map.

use super::photon_map::Stored;
use crate::math::{Frame, Rgb};
use glam::{Vec3, Vec3A};

/// A light subpath's non-specular vertex, as merges and connections read
/// it.
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    pub(super) point: Vec3A,
    pub(super) error: Vec3A,
    pub(super) normal: Vec3A,
    /// The shading normal, which frames the BSDF, packed in 32 bits
    /// ([`LightVertex::shading`]), so that the vertex stays 112 bytes.
    pub(super) packed_shading: u32,
    /// Unit direction towards the previous vertex (where the light came from).
    pub(super) wo: Vec3A,
    /// The subpath's weight up to here (flux of one of N subpaths).
    pub(super) beta: Rgb,
    pub(super) material: u32,
    /// Texture coordinates, to read the material's textures.
    pub(super) uv: glam::Vec2,
    /// Segments from the light to here.
    pub(super) segments: u16,
    /// The BSDF frame's turn about the shading normal
    /// (`Scene::shading_turn`), in the 16 bits beside `segments`.
    pub(super) turn: u16,
    /// Georgiev et al.'s recursive MIS quantities at this vertex.
    pub(super) d_vcm: f32,
    pub(super) d_vc: f32,
    pub(super) d_vm: f32,
}

impl LightVertex {
    /// The shading normal (the geometric one where the mesh has no vertex
    /// normals, exactly).
    #[inline]
    pub(super) fn shading(&self) -> Vec3A {
        match self.packed_shading {
            SAME_AS_GEOMETRIC => self.normal,
            p => crate::math::octahedral_decode(p),
        }
    }

    /// The frame of its BSDF.
    #[inline]
    pub(super) fn frame(&self) -> Frame {
        Frame::from_normal(self.shading()).turned(self.turn)
    }
}

/// A shading normal that is the geometric one.
const SAME_AS_GEOMETRIC: u32 = u32::MAX;

// An iteration keeps millions of light vertices: the frame's turn fits
// beside the segment count, not in a 128-byte vertex.
const _: () = assert!(std::mem::size_of::<LightVertex>() == 112);

#[inline]
pub(super) fn pack_shading(ns: Vec3A, ng: Vec3A) -> u32 {
    if ns == ng {
        SAME_AS_GEOMETRIC
    } else {
        crate::math::octahedral_encode(ns)
    }
}

impl Stored for LightVertex {
    #[inline]
    fn position(&self) -> Vec3A {
        self.point
    }
    #[inline]
    fn facing(&self) -> Vec3A {
        if self.normal.dot(self.wo) >= 0.0 {
            self.normal
        } else {
            -self.normal
        }
    }
}

/// What a merge reads of a light vertex, in one cache line: the map holds
/// these in cell order, so that a lookup's tens of merges (in a room lit by
/// a million light paths) read a few runs of lines, not two misses each.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct MergeVertex {
    pub(super) point: Vec3,
    pub(super) segments: u32,
    pub(super) wo: Vec3,
    pub(super) d_vcm: f32,
    pub(super) facing: Vec3,
    pub(super) d_vm: f32,
    pub(super) beta: Vec3,
}

impl From<&LightVertex> for MergeVertex {
    #[inline]
    fn from(v: &LightVertex) -> MergeVertex {
        MergeVertex {
            point: v.point.into(),
            segments: u32::from(v.segments),
            wo: v.wo.into(),
            d_vcm: v.d_vcm,
            facing: v.facing().into(),
            d_vm: v.d_vm,
            beta: v.beta.into(),
        }
    }
}

impl Stored for MergeVertex {
    #[inline]
    fn position(&self) -> Vec3A {
        self.point.into()
    }
    #[inline]
    fn facing(&self) -> Vec3A {
        self.facing.into()
    }
}
