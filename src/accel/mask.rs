//! Opacity masks (Mitsuba's `mask`, a null BSDF): a surface that keeps a
//! fraction of the hits on it and lets the rest pass, for camera, light and
//! shadow rays alike. The choice is stochastic, by a hash of the ray and
//! the hit (pbrt-v4's alpha test), so it is the same every time a ray is
//! asked the same question, and a segment's expected transmission is
//! 1 − opacity without any estimator knowing about masks.
//!
//! Scenes without masks never reach this code: [`super::Geometry`] tests
//! for a mask table once per query.

use super::{Geometry, SurfaceHit};
use crate::math::{Ray, offset_ray_origin};
use crate::sampling::hash::hash_combine;
use crate::texture::Texture;
use glam::Vec3A;

/// How much of a surface is there.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Opacity {
    /// Every hit counts (every surface but a mask's).
    #[default]
    Opaque,
    /// A fraction of hits in [0, 1] counts (0: Mitsuba's `null`).
    Constant(f32),
    /// The luminance of a texture (an index into the scene's textures),
    /// clamped to [0, 1], as Mitsuba reads a float from a colour bitmap.
    Texture(u32),
}

/// The opacity of every material and the textures they read, held by the
/// geometry so that traversal can cut holes without the scene.
#[derive(Clone, Debug)]
pub struct Masks {
    pub by_material: Vec<Opacity>,
    pub textures: Vec<Texture>,
}

/// Hits passed through on one query at most: past it the ray stops at the
/// next one (a stack of thousands of leaves is not a scene, and the loop
/// must end).
pub const MAX_PASSES: u32 = 256;

impl Masks {
    /// True when some material is not opaque.
    pub fn any(by_material: &[Opacity]) -> bool {
        by_material.iter().any(|o| *o != Opacity::Opaque)
    }

    /// True when every hit on `material` is kept.
    #[inline]
    pub fn is_opaque(&self, material: u32) -> bool {
        match self.by_material.get(material as usize) {
            None | Some(Opacity::Opaque) => true,
            Some(Opacity::Constant(a)) => *a >= 1.0,
            Some(Opacity::Texture(_)) => false,
        }
    }

    /// True when the hit of `ray` at `point` on `material`, with texture
    /// coordinates from `uv`, is kept.
    #[inline]
    pub fn keeps(
        &self,
        material: u32,
        ray: &Ray,
        point: Vec3A,
        uv: impl FnOnce() -> glam::Vec2,
    ) -> bool {
        let opacity = match self.by_material.get(material as usize) {
            None | Some(Opacity::Opaque) => return true,
            Some(Opacity::Constant(a)) => *a,
            Some(Opacity::Texture(t)) => opacity_of(self.textures[*t as usize].eval_1(uv())),
        };
        if opacity >= 1.0 {
            return true;
        }
        if !(opacity > 0.0) {
            return false;
        }
        hash_unit(ray.direction, point) < opacity
    }
}

/// A texel's opacity: its luminance in [0, 1]; NaN is transparent.
#[inline]
fn opacity_of(a: f32) -> f32 {
    if a.is_nan() { 0.0 } else { a.clamp(0.0, 1.0) }
}

/// A number in [0, 1) from a ray's direction and a point on it.
#[inline]
fn hash_unit(d: Vec3A, p: Vec3A) -> f32 {
    let mut h = 0x6d61_736b_u64;
    for v in [d.x, d.y, d.z, p.x, p.y, p.z] {
        h = hash_combine(h, u64::from(v.to_bits()));
    }
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// The ray going on past a hit at `point` (error bound `error`, normal
/// `normal`) that a mask let through, with what is left of its extent.
#[inline]
pub fn continue_past(ray: &Ray, t: f32, point: Vec3A, error: Vec3A, normal: Vec3A) -> Ray {
    let origin = offset_ray_origin(point, error, normal, ray.direction);
    Ray {
        origin,
        t_max: ray.t_max - t,
        ..*ray
    }
}

impl Geometry {
    /// The closest hit that the masks keep: past each one they drop, the
    /// ray goes on from it (out of line: only scenes with masks come here).
    #[inline(never)]
    pub(super) fn intersect_masked(&self, ray: &Ray, masks: &Masks) -> Option<SurfaceHit> {
        let mut r = *ray;
        let mut travelled = 0.0;
        for pass in 1..=MAX_PASSES {
            let hit = self.intersect_all(&r)?;
            if pass == MAX_PASSES || masks.keeps(hit.material, &r, hit.point, || self.uv(&hit)) {
                return Some(SurfaceHit {
                    t: hit.t + travelled,
                    ..hit
                });
            }
            travelled += hit.t;
            // As the techniques' rays leave surfaces (`--offset fixed:EPS`
            // shows a fixed epsilon passing over a thin sheet's far face).
            let error = self.offset.spawn_error(hit.error, hit.normal);
            r = continue_past(&r, hit.t, hit.point, error, hit.normal);
        }
        None
    }

    /// Occlusion where masks cut holes: one any-hit traversal that counts
    /// only opaque triangles settles most shadow rays; a ray that met a
    /// masked triangle, or is blocked by anything but triangles at rest, is
    /// followed through the hits by closest-hit queries (out of line: only
    /// scenes with masks come here).
    #[inline(never)]
    pub(super) fn occluded_masked(&self, ray: &Ray, masks: &Masks) -> bool {
        let mut met_mask = false;
        let mut opaque = |i: usize| {
            let opaque = masks.is_opaque(self.tri_shading[i].material);
            met_mask |= !opaque;
            opaque
        };
        if self.triangle_blocks(ray, &mut opaque) {
            return true;
        }
        let maybe = met_mask || self.spheres_block::<true>(ray) || self.occluded_elsewhere(ray);
        maybe && self.intersect_masked(ray, masks).is_some()
    }
}
