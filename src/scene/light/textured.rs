//! Textured emission (Mitsuba's area emitter with a textured `radiance`,
//! glTF's `emissiveTexture`): a light's radiance times a texture read at
//! the sampled point, found where the point's texture coordinates are the
//! ones a ray's hit there gets ([`crate::scene::Scene::emitted`]), so that
//! light samples and BSDF-sampled hits see the same emitter.

use super::Light;
use crate::accel::sphere_uv;
use crate::math::{Rgb, luminance};
use crate::sampling::warp::{square_to_uniform_sphere, square_to_uniform_triangle};
use crate::texture::Texture;
use glam::{Vec2, Vec3A};

/// The texture that multiplies one light's radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionTexture {
    /// Index into the scene's textures.
    pub texture: u32,
    /// A triangle's texture coordinates at its three corners (the corners
    /// of [`Light::Triangle`]'s `p0`, `p0 + e1`, `p0 + e2`); None for a
    /// sphere, whose coordinates follow from the normal as a hit's do.
    pub corners: Option<[Vec2; 3]>,
}

impl EmissionTexture {
    /// The texture's value at `point` (normal `normal`) on `light`.
    #[inline]
    pub fn at(&self, light: &Light, point: Vec3A, normal: Vec3A, textures: &[Texture]) -> Rgb {
        textures[self.texture as usize].eval(self.uv(light, point, normal))
    }

    /// Texture coordinates at `point`: a triangle's interpolated from its
    /// corners by the point's barycentrics, a sphere's from its normal.
    #[inline]
    fn uv(&self, light: &Light, point: Vec3A, normal: Vec3A) -> Vec2 {
        match (self.corners, light) {
            (Some([t0, t1, t2]), Light::Triangle(p) | Light::Parallelogram(p)) => {
                // point − p0 = b1 e1 + b2 e2, solved in the triangle's plane.
                let n = p.e1.cross(p.e2);
                let inverse = 1.0 / n.length_squared();
                let d = point - p.p0;
                let b1 = d.cross(p.e2).dot(n) * inverse;
                let b2 = p.e1.cross(d).dot(n) * inverse;
                (1.0 - b1 - b2) * t0 + b1 * t1 + b2 * t2
            }
            _ => sphere_uv(normal),
        }
    }

    /// The texture averaged over the emitter's surface, estimated on a
    /// 6 × 6 grid of points (uniform by area): lights are chosen, and
    /// radiosity's elements emit, by it.
    pub fn mean(&self, textures: &[Texture]) -> Rgb {
        const N: usize = 6;
        let texture = &textures[self.texture as usize];
        let mut sum = Rgb::ZERO;
        for i in 0..N * N {
            let u = Vec2::new(
                ((i % N) as f32 + 0.5) / N as f32,
                ((i / N) as f32 + 0.5) / N as f32,
            );
            let uv = match self.corners {
                Some([t0, t1, t2]) => {
                    let b = square_to_uniform_triangle(u);
                    (1.0 - b.x - b.y) * t0 + b.x * t1 + b.y * t2
                }
                None => sphere_uv(square_to_uniform_sphere(u)),
            };
            sum += texture.eval(uv);
        }
        sum / (N * N) as f32
    }

    /// [`EmissionTexture::mean`], never below 1% of the texture's mean: a
    /// light whose grid points all fall on black texels can still be
    /// chosen, so that choosing lights by it stays unbiased.
    pub fn choice_weight(&self, textures: &[Texture]) -> Rgb {
        let (mean, floor) = (
            self.mean(textures),
            0.01 * textures[self.texture as usize].mean(),
        );
        if luminance(mean) < luminance(floor) {
            floor
        } else {
            mean
        }
    }
}
