//! Blends of two materials (Mitsuba's `blendbsdf`): each point of the
//! surface takes the second material with probability `weight`, chosen
//! once by a hash of the point (pbrt-v4's `MixMaterial`). The choice is
//! made where a query finds the hit, so every technique, every vertex of
//! a path and every MIS density at it sees one material, and a pixel's
//! mean is the blend's: (1 − w) f₀ + w f₁ over the points it covers.
//!
//! Scenes without blends never reach this code: [`super::Geometry`] keeps
//! it off its plain path.

use super::SurfaceHit;
use crate::sampling::hash::hash_combine;
use crate::texture::Texture;
use glam::{Vec2, Vec3A};

/// How much of a surface takes the second material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Weight {
    /// A fraction in [0, 1].
    Constant(f32),
    /// The luminance of a texture (an index into the scene's textures),
    /// clamped to [0, 1], as Mitsuba reads a float from a colour bitmap.
    Texture(u32),
}

/// The second material of a blend and its weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    pub second: u32,
    pub weight: Weight,
}

/// Every material's blend, where it has one, and the textures they read.
#[derive(Clone, Debug)]
pub struct Blends {
    pub by_material: Vec<Option<Blend>>,
    pub textures: Vec<Texture>,
}

impl Blends {
    /// True when some material blends.
    pub fn any(by_material: &[Option<Blend>]) -> bool {
        by_material.iter().any(Option::is_some)
    }

    /// The material that `hit` takes: the second one of its blend where
    /// its point takes it (texture coordinates from `uv`), else its own.
    #[inline]
    pub fn material_at(&self, hit: &SurfaceHit, uv: impl FnOnce() -> Vec2) -> u32 {
        let Some(Some(blend)) = self.by_material.get(hit.material as usize) else {
            return hit.material;
        };
        let weight = match blend.weight {
            Weight::Constant(w) => w,
            Weight::Texture(t) => self.textures[t as usize].eval_1(uv()),
        };
        // NaN takes the first material, as the comparison fails.
        if hash_point(hit.point) < weight.min(1.0) {
            blend.second
        } else {
            hit.material
        }
    }
}

/// A number in [0, 1) from a point alone, so that a point has one material
/// whichever ray finds it.
#[inline]
fn hash_point(p: Vec3A) -> f32 {
    let mut h = 0x0062_6c65_6e64_u64;
    for v in [p.x, p.y, p.z] {
        h = hash_combine(h, u64::from(v.to_bits()));
    }
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fraction of points that take the second material is the weight:
    /// over n = 100 000 points the count is binomial, standard error
    /// √(w (1 − w) / n) ≤ 0.0016; the tolerance is 4 of them.
    #[test]
    fn the_second_material_takes_the_weights_share_of_points() {
        for w in [0.0, 0.1, 0.5, 0.9, 1.0] {
            let blends = Blends {
                by_material: vec![
                    Some(Blend {
                        second: 1,
                        weight: Weight::Constant(w),
                    }),
                    None,
                ],
                textures: Vec::new(),
            };
            let n = 100_000;
            let mut second = 0;
            for i in 0..n {
                let x = i as f32 * 1e-3;
                let hit = SurfaceHit {
                    t: 1.0,
                    point: Vec3A::new(x, (x * 7.3).sin(), 0.25),
                    error: Vec3A::ZERO,
                    normal: Vec3A::Z,
                    material: 0,
                    light: crate::accel::NO_LIGHT,
                    time: 0.0,
                    barycentric: Vec2::ZERO,
                    primitive: 0,
                    instance: crate::accel::NO_INSTANCE,
                };
                second += usize::from(blends.material_at(&hit, || Vec2::ZERO) == 1);
                // Material 1 blends with nothing: it stays.
                let other = SurfaceHit { material: 1, ..hit };
                assert_eq!(blends.material_at(&other, || Vec2::ZERO), 1);
            }
            let share = second as f64 / n as f64;
            let tolerance = 4.0 * (0.25f64 / n as f64).sqrt();
            assert!(
                (share - w as f64).abs() <= tolerance,
                "w {w}: share {share}"
            );
        }
    }
}
