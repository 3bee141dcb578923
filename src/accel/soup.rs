//! Small meshes without a BVH: every triangle is tested, eight at a time.
//!
//! For a few dozen triangles (the Cornell box has 36) a hierarchy costs more
//! than it saves: a ray visits several CWBVH nodes to reach 3 triangles. Here
//! the same watertight test as `triangle.rs` (Woop, Benthin & Wald) runs on
//! eight triangles per instruction, stored as structure-of-arrays blocks.

use super::triangle::{ShearedRay, permuted_axes};
use crate::math::{Ray, gamma};
use glam::Vec3A;
use wide::f32x8;

/// Triangles per block (SIMD lanes).
pub const LANES: usize = 8;

/// Eight triangles: `v[vertex][axis]`, one lane per triangle.
#[derive(Clone, Debug)]
struct Block {
    v: [[f32x8; 3]; 3],
    /// Bit i set when lane i holds a triangle (the last block may be partial).
    lanes: u32,
}

/// All triangles of a small scene in blocks of eight.
#[derive(Clone, Debug, Default)]
pub struct TriangleSoup {
    blocks: Vec<Block>,
}

/// A hit found in the soup: triangle index, t and barycentrics (b1, b2).
pub type SoupHit = (usize, f32, f32, f32);

impl TriangleSoup {
    /// Packs triangles (in the given order) into blocks.
    pub fn new(triangles: &[[Vec3A; 3]]) -> Self {
        let blocks = triangles
            .chunks(LANES)
            .map(|chunk| {
                let mut v = [[[0.0f32; LANES]; 3]; 3];
                for (lane, tri) in chunk.iter().enumerate() {
                    for (vertex, p) in tri.iter().enumerate() {
                        for axis in 0..3 {
                            v[vertex][axis][lane] = p[axis];
                        }
                    }
                }
                Block {
                    v: v.map(|vertex| vertex.map(f32x8::new)),
                    lanes: (1u32 << chunk.len()) - 1,
                }
            })
            .collect();
        TriangleSoup { blocks }
    }

    /// Bytes of the blocks.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.blocks[..])
    }

    /// Closest hit in (0, t_max).
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32, triangles: &[[Vec3A; 3]]) -> Option<SoupHit> {
        let axes = Axes::new(ray);
        let mut best: Option<SoupHit> = None;
        let mut best_t = t_max;
        for (b, block) in self.blocks.iter().enumerate() {
            let Some(hits) = block_hits(block, &axes, best_t) else {
                continue;
            };
            let (ts, b1s, b2s) = (hits.t.to_array(), hits.b1.to_array(), hits.b2.to_array());
            let mut lanes = hits.mask;
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                if ts[lane] < best_t {
                    best_t = ts[lane];
                    best = Some((b * LANES + lane, ts[lane], b1s[lane], b2s[lane]));
                }
            }
            // Edge functions of exactly zero: the scalar test decides in double precision.
            let mut lanes = hits.ambiguous;
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let index = b * LANES + lane;
                if let Some((t, b1, b2)) = ShearedRay::new(ray).intersect(&triangles[index], best_t)
                {
                    best_t = t;
                    best = Some((index, t, b1, b2));
                }
            }
        }
        best
    }

    /// True when any triangle is hit in (0, t_max).
    #[inline]
    pub fn any(&self, ray: &Ray, t_max: f32, triangles: &[[Vec3A; 3]]) -> bool {
        let axes = Axes::new(ray);
        for (b, block) in self.blocks.iter().enumerate() {
            if let Some(hits) = block_hits(block, &axes, t_max) {
                if hits.mask != 0 {
                    return true;
                }
                let mut lanes = hits.ambiguous;
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    if ShearedRay::new(ray)
                        .intersect(&triangles[b * LANES + lane], t_max)
                        .is_some()
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// The ray in the permuted, sheared frame of the watertight test.
struct Axes {
    kx: usize,
    ky: usize,
    kz: usize,
    origin: [f32x8; 3],
    sx: f32x8,
    sy: f32x8,
    sz: f32x8,
}

impl Axes {
    #[inline]
    fn new(ray: &Ray) -> Self {
        let d = ray.direction;
        let (kx, ky, kz) = permuted_axes(d);
        let o = ray.origin;
        Axes {
            kx,
            ky,
            kz,
            origin: [
                f32x8::splat(o[kx]),
                f32x8::splat(o[ky]),
                f32x8::splat(o[kz]),
            ],
            sx: f32x8::splat(d[kx] / d[kz]),
            sy: f32x8::splat(d[ky] / d[kz]),
            sz: f32x8::splat(1.0 / d[kz]),
        }
    }

    /// Vertex in the sheared frame: (x - sx z, y - sy z, sz z), relative to the origin.
    #[inline(always)]
    fn shear(&self, v: &[f32x8; 3]) -> [f32x8; 3] {
        let x = v[self.kx] - self.origin[0];
        let y = v[self.ky] - self.origin[1];
        let z = v[self.kz] - self.origin[2];
        [x - self.sx * z, y - self.sy * z, self.sz * z]
    }
}

/// Hits of one block.
struct BlockHits {
    t: f32x8,
    b1: f32x8,
    b2: f32x8,
    /// Lanes hit in (0, t_max).
    mask: u32,
    /// Lanes with an edge function of exactly zero, which single precision
    /// cannot decide; the scalar test redoes them in double precision.
    ambiguous: u32,
}

/// The watertight test on eight triangles. Same operations as the scalar
/// test in `triangle.rs`, so both agree to the bit.
#[inline(always)]
fn block_hits(block: &Block, axes: &Axes, t_max: f32) -> Option<BlockHits> {
    let [ax, ay, az] = axes.shear(&block.v[0]);
    let [bx, by, bz] = axes.shear(&block.v[1]);
    let [cx, cy, cz] = axes.shear(&block.v[2]);
    let e0 = cx * by - cy * bx;
    let e1 = ax * cy - ay * cx;
    let e2 = bx * ay - by * ax;
    let zero = f32x8::splat(0.0);
    let sign = f32x8::splat(-0.0);
    let ambiguous =
        (e0.simd_eq(zero) | e1.simd_eq(zero) | e2.simd_eq(zero)).to_bitmask() & block.lanes;
    // With no edge function zero (ambiguous lanes are decided apart), the ray
    // is inside when all three have the same sign bit: two XORs instead of
    // six comparisons.
    let mixed_signs = ((e0 ^ e1) | (e1 ^ e2)).to_bitmask();
    let det = e0 + e1 + e2;
    let t_scaled = e0 * az + e1 * bz + e2 * cz;
    // t * det within (0, t_max * det), compared without dividing; the sign of
    // det is moved onto t_scaled by XOR.
    let t_abs = t_scaled ^ (det & sign);
    let det_abs = det.abs();
    let in_range =
        t_abs.simd_gt(zero) & t_abs.simd_lt(f32x8::splat(t_max) * det_abs) & det_abs.simd_gt(zero);
    let mut mask = in_range.to_bitmask() & !mixed_signs & block.lanes & !ambiguous;
    if mask == 0 && ambiguous == 0 {
        return None;
    }
    let inv_det = f32x8::splat(1.0) / det;
    let t = t_scaled * inv_det;
    if mask != 0 {
        // Conservative bound on t's rounding error (pbrt-v4 6.8.4).
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let delta_z = f32x8::splat(gamma(3)) * max_z;
        let delta_x = f32x8::splat(gamma(5)) * (max_x + max_z);
        let delta_y = f32x8::splat(gamma(5)) * (max_y + max_z);
        let delta_e = f32x8::splat(2.0)
            * (f32x8::splat(gamma(2)) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = f32x8::splat(3.0)
            * (f32x8::splat(gamma(3)) * max_e * max_z + delta_e * max_z + delta_z * max_e)
            * inv_det.abs();
        mask &= t.simd_gt(delta_t).to_bitmask();
    }
    Some(BlockHits {
        t,
        b1: e1 * inv_det,
        b2: e2 * inv_det,
        mask,
        ambiguous,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
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
            let mut expected: Option<SoupHit> = None;
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
