//! What a surface is at a hit: its BSDF with its textures read, what it
//! emits, and its shading normal (interpolated vertex normals, tilted by
//! a material's normal or bump map). Every technique asks here.

use super::Scene;
use super::light::EmissionTexture;
use super::material::{Material, NormalMap};
use crate::accel::SurfaceHit;
use crate::math::Frame;
use glam::Vec3A;

impl Scene {
    /// The BSDF at `hit`, its textures read.
    #[inline(always)]
    pub fn bsdf_at(&self, hit: &SurfaceHit) -> crate::bsdf::Bsdf {
        let material = &self.materials[hit.material as usize];
        if material.textures.is_empty() {
            return material.bsdf;
        }
        self.textured_bsdf_at(material, hit)
    }

    /// Asks the cache for the texels [`Scene::bsdf_at`] reads at `hit`.
    #[inline(always)]
    pub fn prefetch_bsdf(&self, hit: &SurfaceHit) {
        if !self.features.textures {
            return;
        }
        let material = &self.materials[hit.material as usize];
        if !material.textures.is_empty() {
            material.prefetch_textures(&self.textures, self.geometry.uv(hit));
        }
    }

    /// Whether the BSDF at `hit` is specular, before it is read
    /// (textures change its parameters, never its kind).
    #[inline(always)]
    pub fn bsdf_is_specular(&self, hit: &SurfaceHit) -> bool {
        self.materials[hit.material as usize].bsdf.is_specular()
    }

    /// Radiance that the surface at `hit` emits towards `w`: its
    /// material's emission, times its texture where it has one.
    #[inline]
    pub fn emitted(&self, hit: &SurfaceHit, w: Vec3A) -> crate::math::Rgb {
        let material = &self.materials[hit.material as usize];
        let emitted = material.emitted(hit.normal, w);
        match material.emission_texture {
            Some(t) if emitted.max_element() > 0.0 => {
                emitted * self.textures[t as usize].eval(self.geometry.uv(hit))
            }
            _ => emitted,
        }
    }

    /// What triangle `i` emits, averaged over it where its emission is
    /// textured: for what reads one value per surface (radiosity).
    pub fn triangle_emission(&self, i: usize) -> crate::math::Rgb {
        let material = &self.materials[self.geometry.triangle_material(i) as usize];
        match material.emission_texture {
            Some(texture) => {
                let t = EmissionTexture {
                    texture,
                    corners: Some(self.geometry.triangle_uvs(i)),
                };
                material.emission * t.mean(&self.textures)
            }
            None => material.emission,
        }
    }

    /// [`Scene::bsdf_at`] where a texture is read, out of line: with it
    /// inlined LLVM kept the whole lookup out of the integrators' loops,
    /// a call and a copy of the model at every hit of untextured scenes.
    #[inline(never)]
    fn textured_bsdf_at(&self, material: &Material, hit: &SurfaceHit) -> crate::bsdf::Bsdf {
        material.bsdf_at(&self.textures, self.geometry.uv(hit))
    }

    /// The shading normal at `hit`: the interpolated vertex normal (the
    /// geometric one without), tilted by the material's normal map. BSDFs
    /// act in its frame; offsets, emission and densities keep the geometric
    /// normal.
    #[inline(always)]
    pub fn shading_normal(&self, hit: &SurfaceHit) -> Vec3A {
        if !self.features.shading_normals {
            return hit.normal;
        }
        let n = self.geometry.shading_normal(hit);
        if !self.features.normal_maps {
            return n;
        }
        match self.materials[hit.material as usize].normal_map {
            Some(map) => self.normal_mapped(hit, n, map),
            None => n,
        }
    }

    /// The frame BSDFs act in at `hit`: around the shading normal, its
    /// first axis along dp/du where the material is anisotropic (as
    /// Mitsuba's), any other way elsewhere.
    #[inline(always)]
    pub fn shading_frame(&self, hit: &SurfaceHit) -> Frame {
        let n = self.shading_normal(hit);
        match self.shading_tangent(hit) {
            Some(tangent) => Frame::with_tangent(n, tangent),
            None => Frame::from_normal(n),
        }
    }

    /// The direction the first axis of [`Scene::shading_frame`] follows
    /// at `hit`, where the material needs one.
    #[inline(always)]
    pub fn shading_tangent(&self, hit: &SurfaceHit) -> Option<Vec3A> {
        if !self.features.anisotropic || !self.materials[hit.material as usize].is_anisotropic() {
            return None;
        }
        Some(self.surface_tangent(hit))
    }

    /// The turn of the frame about shading normal `n` at `hit` from
    /// [`Frame::from_normal`]'s, as stored vertices keep it.
    #[inline(always)]
    pub fn shading_turn(&self, hit: &SurfaceHit, n: Vec3A) -> u16 {
        match self.shading_tangent(hit) {
            Some(tangent) => Frame::from_normal(n).turn_towards(tangent),
            None => crate::math::NO_TURN,
        }
    }

    /// dp/du, or without texture coordinates the first axis of the
    /// geometric normal's frame (as Mitsuba's meshes without uv).
    #[inline(never)]
    fn surface_tangent(&self, hit: &SurfaceHit) -> Vec3A {
        match self.geometry.uv_derivatives(hit) {
            Some((dpdu, _)) => dpdu,
            None => Frame::from_normal(hit.normal).s,
        }
    }

    /// `n` tilted by `map` at `hit` (Mitsuba's `normalmap` and `bumpmap`);
    /// `n` where the surface has no uv derivatives or the map no direction.
    #[inline(never)]
    fn normal_mapped(&self, hit: &SurfaceHit, n: Vec3A, map: NormalMap) -> Vec3A {
        let Some((dpdu, dpdv)) = self.geometry.uv_derivatives(hit) else {
            return n;
        };
        let uv = self.geometry.uv(hit);
        let m = match map {
            NormalMap::Tangent { texture, scale } => {
                let s = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
                if s == Vec3A::ZERO {
                    return n;
                }
                let t = n.cross(s);
                let local = self.textures[texture as usize].eval(uv) * 2.0 - Vec3A::ONE;
                s * (local.x * scale) + t * (local.y * scale) + n * local.z
            }
            NormalMap::Bump { texture, scale } => {
                let g = scale * self.textures[texture as usize].eval_gradient(uv);
                let du = dpdu + n * (g.x - n.dot(dpdu));
                let dv = dpdv + n * (g.y - n.dot(dpdv));
                let m = du.cross(dv);
                // On the side of the geometric normal, as Mitsuba flips it.
                if m.dot(hit.normal) < 0.0 { -m } else { m }
            }
        }
        .normalize_or_zero();
        if m.is_finite() && m != Vec3A::ZERO {
            m
        } else {
            n
        }
    }
}
