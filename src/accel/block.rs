//! Eight triangles per instruction: the blocks that the triangle soup and
//! the wide BVH's leaves are made of, the watertight test on a block, and
//! the slab test of a ray against eight boxes.

use super::triangle::{ShearedRay, permuted_axes, shear_factors};
use crate::math::{Ray, gamma};
use glam::Vec3A;
use wide::f32x8;

/// Triangles per block and boxes per slab test (SIMD lanes).
pub const LANES: usize = 8;

/// A hit: triangle index, t and barycentrics (b1, b2).
pub type TriangleHit = (usize, f32, f32, f32);

/// Up to eight triangles: `v[vertex][axis]`, one lane per triangle.
/// Aligned to cache lines: 320 bytes, five lines, not six.
#[derive(Clone, Debug)]
#[repr(align(64))]
pub struct Block {
    v: [[f32x8; 3]; 3],
    /// Index of the block's first triangle; its triangles are contiguous.
    pub first: u32,
    /// Bit i set when lane i holds a triangle.
    lanes: u32,
}

impl Block {
    /// A block of no triangles, a slot before it is filled.
    pub fn empty() -> Self {
        Block {
            v: [[f32x8::ZERO; 3]; 3],
            first: 0,
            lanes: 0,
        }
    }

    /// The block of `triangles` (at most [`LANES`]), the first of which has
    /// index `first`.
    pub fn new(triangles: &[[Vec3A; 3]], first: usize) -> Self {
        debug_assert!(!triangles.is_empty() && triangles.len() <= LANES);
        let mut v = [[[0.0f32; LANES]; 3]; 3];
        for (lane, tri) in triangles.iter().enumerate() {
            for (vertex, p) in tri.iter().enumerate() {
                for axis in 0..3 {
                    v[vertex][axis][lane] = p[axis];
                }
            }
        }
        Block {
            v: v.map(|vertex| vertex.map(f32x8::new)),
            first: first as u32,
            lanes: (1u32 << triangles.len()) - 1,
        }
    }

    /// The vertices of the triangle in `lane`: read from the block, which a
    /// query has just loaded, instead of from the triangle array (a cache
    /// miss on large meshes: 24% of closest-hit time on 100k triangles).
    #[inline]
    pub fn vertices(&self, lane: usize) -> [Vec3A; 3] {
        self.v
            .map(|vertex| Vec3A::from_array(vertex.map(|axis| axis.to_array()[lane])))
    }

    /// Updates `best` (and `best_t`) with the closest hit of this block
    /// nearer than `best_t`.
    #[inline(always)]
    pub fn closest(
        &self,
        axes: &Axes,
        ray: &Ray,
        triangles: &[[Vec3A; 3]],
        best_t: &mut f32,
        best: &mut Option<TriangleHit>,
    ) {
        let Some(hits) = block_hits(self, axes, *best_t) else {
            return;
        };
        let first = self.first as usize;
        let (ts, b1s, b2s) = (hits.t.to_array(), hits.b1.to_array(), hits.b2.to_array());
        let mut lanes = hits.mask;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if ts[lane] < *best_t {
                *best_t = ts[lane];
                *best = Some((first + lane, ts[lane], b1s[lane], b2s[lane]));
            }
        }
        // Edge functions of exactly zero: the scalar test decides in double precision.
        let mut lanes = hits.ambiguous;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let index = first + lane;
            if let Some((t, b1, b2)) = ShearedRay::new(ray).intersect(&triangles[index], *best_t) {
                *best_t = t;
                *best = Some((index, t, b1, b2));
            }
        }
    }

    /// True when a triangle of this block that `accept` (called with its
    /// index) accepts is hit in (0, t_max).
    #[inline(always)]
    pub fn any_where(
        &self,
        axes: &Axes,
        ray: &Ray,
        triangles: &[[Vec3A; 3]],
        t_max: f32,
        accept: &mut impl FnMut(usize) -> bool,
    ) -> bool {
        let Some(hits) = block_hits(self, axes, t_max) else {
            return false;
        };
        let first = self.first as usize;
        let mut lanes = hits.mask;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if accept(first + lane) {
                return true;
            }
        }
        let mut lanes = hits.ambiguous;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let index = first + lane;
            if ShearedRay::new(ray)
                .intersect(&triangles[index], t_max)
                .is_some()
                && accept(index)
            {
                return true;
            }
        }
        false
    }
}

/// Eight axis-aligned boxes, one lane each.
#[derive(Clone, Debug)]
pub struct Boxes8 {
    /// The six bounding planes: min x, y, z, then max x, y, z.
    planes: [f32x8; 6],
    /// Bit i set when lane i holds a box.
    lanes: u32,
}

impl Boxes8 {
    /// Up to [`LANES`] boxes given as (min, max).
    pub fn new(boxes: &[(Vec3A, Vec3A)]) -> Self {
        debug_assert!(boxes.len() <= LANES);
        let mut min = [[0.0f32; LANES]; 3];
        let mut max = [[0.0f32; LANES]; 3];
        for (lane, (lo, hi)) in boxes.iter().enumerate() {
            for axis in 0..3 {
                min[axis][lane] = lo[axis];
                max[axis][lane] = hi[axis];
            }
        }
        let [min, max] = [min, max].map(|planes| planes.map(f32x8::new));
        Boxes8 {
            planes: [min[0], min[1], min[2], max[0], max[1], max[2]],
            lanes: (1u32 << boxes.len()) - 1,
        }
    }
}

/// The ray in the permuted, sheared frame of the watertight test.
pub struct Axes {
    kx: usize,
    ky: usize,
    kz: usize,
    origin: [f32x8; 3],
    sx: f32x8,
    sy: f32x8,
    sz: f32x8,
}

impl Axes {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.direction;
        let (kx, ky, kz) = permuted_axes(d);
        let shear = shear_factors(d, kx, ky, kz);
        // Array indexing: glam's `Index` on Vec3A is a match per access.
        let o = ray.origin.to_array();
        Axes {
            kx,
            ky,
            kz,
            origin: [
                f32x8::splat(o[kx]),
                f32x8::splat(o[ky]),
                f32x8::splat(o[kz]),
            ],
            sx: f32x8::splat(shear.0),
            sy: f32x8::splat(shear.1),
            sz: f32x8::splat(shear.2),
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

/// The ray as the slab test of bounding boxes wants it. Apart from [`Axes`]
/// because the triangle soup tests no boxes: its three divisions were 6% of
/// a Cornell box render there.
pub struct SlabAxes {
    /// Per axis, the index in [`Boxes8`]'s planes of the plane the ray
    /// enters by (min for a positive direction) and of the one it leaves by.
    near: [usize; 3],
    far: [usize; 3],
    origin: [f32x8; 3],
    inv_direction: [f32x8; 3],
    /// The reciprocals, enlarged once per ray so that exit distances come
    /// out conservative without a product per node (see [`Self::reaches`]).
    inv_direction_far: [f32x8; 3],
}

impl SlabAxes {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let (o, d) = (ray.origin, ray.direction);
        let inv = d.recip();
        let inv_far = inv * (1.0 + 2.0 * gamma(4));
        // By the sign bit: a direction component of -0 has reciprocal -inf,
        // for which the max plane is entered first, as for any negative one.
        let negative = d.to_array().map(|c| usize::from(c.is_sign_negative()));
        let (inv, inv_far, o) = (inv.to_array(), inv_far.to_array(), o.to_array());
        // Written out: `[0, 1, 2].map` of an index was left a call (2% of
        // BDPT's time on veach-bidir, in every shadow ray's set-up).
        SlabAxes {
            near: [negative[0] * 3, 1 + negative[1] * 3, 2 + negative[2] * 3],
            far: [
                3 - negative[0] * 3,
                4 - negative[1] * 3,
                5 - negative[2] * 3,
            ],
            origin: o.map(f32x8::splat),
            inv_direction: inv.map(f32x8::splat),
            inv_direction_far: inv_far.map(f32x8::splat),
        }
    }

    /// Slab test against eight boxes (pbrt-v4 6.8.7): the lanes of `boxes`
    /// whose box the ray enters in [0, t_max], and the entry distances.
    ///
    /// Conservative under rounding: an entry distance (a difference, a
    /// reciprocal and a product) is within gamma(3) of the exact one; an
    /// exit distance, through the reciprocal enlarged by W = 1 + 2 gamma(4)
    /// (one rounding more), is at least W (1 - gamma(4)) > 1 + gamma(3)
    /// times the exact one, so a box the exact ray enters is never missed.
    ///
    /// A slab giving 0 x inf = NaN (a direction component of zero and the
    /// origin on a face's plane) does not constrain t: the ray runs inside
    /// that plane, which counts as inside, so a NaN distance keeps the
    /// running bound.
    #[inline(always)]
    pub fn reaches(&self, boxes: &Boxes8, t_max: f32) -> (u32, [f32; LANES]) {
        let mut t_near = f32x8::splat(0.0);
        let mut t_far = f32x8::splat(t_max);
        for axis in 0..3 {
            // The direction's sign says which plane is entered first, so no
            // min and max of the two distances are needed.
            let t0 = (boxes.planes[self.near[axis]] - self.origin[axis]) * self.inv_direction[axis];
            let t1 =
                (boxes.planes[self.far[axis]] - self.origin[axis]) * self.inv_direction_far[axis];
            t_near = bound_unless_nan::<true>(t0, t_near);
            t_far = bound_unless_nan::<false>(t1, t_far);
        }
        let reached = t_near.simd_le(t_far).to_bitmask() & boxes.lanes;
        (reached, t_near.to_array())
    }
}

/// Per lane max(a, b) (`MAX`) or min(a, b), and b where a is NaN. x86's
/// max and min instructions have exactly these semantics (they return
/// their second operand when either is NaN); elsewhere an ordered
/// comparison does it. A check of the NaN per node instead cost the
/// traversal a compare and branch per axis.
#[inline(always)]
fn bound_unless_nan<const MAX: bool>(a: f32x8, b: f32x8) -> f32x8 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    {
        use std::arch::x86_64::{_mm256_max_ps, _mm256_min_ps};
        let (a, b) = (a.into(), b.into());
        // SAFETY: the build enables AVX (the cfg above).
        f32x8::from(unsafe {
            if MAX {
                _mm256_max_ps(a, b)
            } else {
                _mm256_min_ps(a, b)
            }
        })
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    {
        let keep_a = if MAX { a.simd_gt(b) } else { a.simd_lt(b) };
        keep_a.select(a, b)
    }
}

/// Hits of one block.
pub struct BlockHits {
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
pub fn block_hits(block: &Block, axes: &Axes, t_max: f32) -> Option<BlockHits> {
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
    // Most blocks end here: the ray's line passes beside all eight triangles.
    if (!mixed_signs | ambiguous) & block.lanes == 0 {
        return None;
    }
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
        // Conservative bound on t's rounding error (pbrt-v4 6.8.4). Plain
        // max instructions: a NaN coordinate makes an edge function and
        // t_scaled NaN, so its lane is not in `mask` (wide's NaN-aware max
        // costs three instructions for one).
        let max_z = az.abs().fast_max(bz.abs()).fast_max(cz.abs());
        let max_x = ax.abs().fast_max(bx.abs()).fast_max(cx.abs());
        let max_y = ay.abs().fast_max(by.abs()).fast_max(cy.abs());
        let delta_z = f32x8::splat(gamma(3)) * max_z;
        let delta_x = f32x8::splat(gamma(5)) * (max_x + max_z);
        let delta_y = f32x8::splat(gamma(5)) * (max_y + max_z);
        let delta_e = f32x8::splat(2.0)
            * (f32x8::splat(gamma(2)) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().fast_max(e1.abs()).fast_max(e2.abs());
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

    #[test]
    fn slab_bounds_keep_the_running_value_where_the_distance_is_nan() {
        let nan = f32::NAN;
        let a = f32x8::new([nan, 1.0, -2.0, 5.0, nan, 0.0, -0.0, f32::INFINITY]);
        let b = f32x8::new([3.0, 2.0, -1.0, 4.0, -7.0, -0.0, 0.0, 1.0]);
        let max = bound_unless_nan::<true>(a, b).to_array();
        let min = bound_unless_nan::<false>(a, b).to_array();
        assert_eq!(max[..5], [3.0, 2.0, -1.0, 5.0, -7.0]);
        assert_eq!(min[..5], [3.0, 1.0, -2.0, 4.0, -7.0]);
        assert_eq!((max[7], min[7]), (f32::INFINITY, 1.0));
        // Equal zeros: either is a bound of the same value.
        assert!(max[5] == 0.0 && min[6] == 0.0);
    }

    #[test]
    fn exit_distances_are_enlarged_beyond_the_entry_rounding() {
        // W (1 - gamma(4)) > 1 + gamma(3): the margin reaches() relies on.
        let w = 1.0 + 2.0 * gamma(4);
        assert!(f64::from(w) * (1.0 - f64::from(gamma(4))) > 1.0 + f64::from(gamma(3)));
    }
}
