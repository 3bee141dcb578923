//! The unit of radiosity's meshes and links: a flat triangle of constant
//! radiance, with its patch's reflectance and emission.

use crate::math::Rgb;
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
    /// The element on `vertices` (of patch `triangle`), its normal along
    /// their winding and its area from them.
    pub fn new(triangle: u32, vertices: [Vec3A; 3], reflectance: Rgb, emission: Rgb) -> Element {
        let [a, b, c] = vertices;
        let n = (b - a).cross(c - a);
        Element {
            triangle,
            vertices,
            normal: n.normalize(),
            area: 0.5 * n.length(),
            reflectance,
            emission,
        }
    }

    /// The point at barycentrics (b1, b2) of the element.
    #[inline]
    pub fn point(&self, b1: f32, b2: f32) -> Vec3A {
        let [a, b, c] = self.vertices;
        a + b1 * (b - a) + b2 * (c - a)
    }
}
