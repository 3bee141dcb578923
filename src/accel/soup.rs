//! Small meshes without a BVH: every triangle is tested, eight at a time.
//!
//! For a few dozen triangles (the Cornell box has 32) a hierarchy costs more
//! than it saves: a ray visits several nodes to reach 3 triangles. Here the
//! watertight test of `triangle.rs` (Woop, Benthin & Wald) runs on eight
//! triangles per instruction (`block.rs`). Measured on the Cornell box:
//! bounding boxes per block tested first (grouped by a surface-area split)
//! cost more than they saved, 2.99 -> 2.70 M paths/s, with only 4 blocks.

use super::block::{Axes, Block, LANES, TriangleHit};
use crate::math::Ray;
use glam::Vec3A;

/// All triangles of a small scene in blocks of eight.
#[derive(Clone, Debug, Default)]
pub struct TriangleSoup {
    blocks: Vec<Block>,
}

impl TriangleSoup {
    /// Packs triangles (in the given order) into blocks.
    pub fn new(triangles: &[[Vec3A; 3]]) -> Self {
        let blocks = triangles
            .chunks(LANES)
            .enumerate()
            .map(|(b, chunk)| Block::new(chunk, b * LANES))
            .collect();
        TriangleSoup { blocks }
    }

    /// Bytes of the blocks.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.blocks[..])
    }

    /// Closest hit in (0, t_max).
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32, triangles: &[[Vec3A; 3]]) -> Option<TriangleHit> {
        let axes = Axes::new(ray);
        let mut best = None;
        let mut best_t = t_max;
        for block in &self.blocks {
            block.closest(&axes, ray, triangles, &mut best_t, &mut best);
        }
        best
    }

    /// True when any triangle is hit in (0, t_max).
    #[inline]
    pub fn any(&self, ray: &Ray, t_max: f32, triangles: &[[Vec3A; 3]]) -> bool {
        let axes = Axes::new(ray);
        self.blocks
            .iter()
            .any(|block| block.any(&axes, ray, triangles, t_max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::triangle::ShearedRay;
    use crate::sampling::hash::{hash_combine, to_unit_float};

    #[test]
    fn agrees_with_the_scalar_test_on_random_rays() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let triangles: Vec<[Vec3A; 3]> = (0..37u64)
            .map(|i| {
                let p = |k| Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) * 2.0 - Vec3A::ONE;
                [p(10), p(20), p(30)]
            })
            .collect();
        let soup = TriangleSoup::new(&triangles);
        for i in 0..20_000u64 {
            let origin = Vec3A::new(u(1, i), u(2, i), u(3, i)) * 4.0 - Vec3A::splat(2.0);
            let direction = (Vec3A::new(u(4, i), u(5, i), u(6, i)) * 2.0 - Vec3A::ONE).normalize();
            let ray = Ray::new(origin, direction);
            let sheared = ShearedRay::new(&ray);
            let mut expected: Option<TriangleHit> = None;
            for (k, tri) in triangles.iter().enumerate() {
                let t_max = expected.map_or(f32::INFINITY, |h| h.1);
                if let Some((t, b1, b2)) = sheared.intersect(tri, t_max) {
                    expected = Some((k, t, b1, b2));
                }
            }
            assert_eq!(
                soup.closest(&ray, f32::INFINITY, &triangles),
                expected,
                "ray {i}"
            );
            assert_eq!(
                soup.any(&ray, 1.0, &triangles),
                expected.is_some_and(|h| h.1 < 1.0),
                "ray {i}"
            );
        }
    }
}
