//! Where a planar light is seen whole: shadow rays from there need no test.
//!
//! A shadow ray from a point p to a point on a flat light lies in the convex
//! hull of p and the light. Split the scene's box into voxels: if no
//! occluder meets the hull of a voxel and the light, every shadow ray from
//! that voxel to that light is unblocked, and its answer is known without
//! tracing it. Disjointness is shown by separating axes (the triangle's
//! normal, the coordinate axes, the light's normal, and the triangle's edges
//! crossed with those and with the light's edges and the voxel-to-light
//! direction); an axis that cannot be found leaves the voxel to the ray test,
//! so the shortcut only ever answers what the test would have.

use glam::{DVec3, Vec3A};
use rayon::prelude::*;

/// Voxels along the box's longest side: 16 keeps the build near 10 ms for
/// the Cornell box's 24 occluders (every voxel against every occluder).
const RESOLUTION: f32 = 16.0;

/// A voxel's corners and the light's corners on both sides of its plane
/// (a triangle light repeats a corner).
const HULL_POINTS: usize = 16;

/// Voxels of a box from which no shadow segment to one light can be blocked.
#[derive(Clone, Debug, Default)]
pub struct ClearVoxels {
    lo: Vec3A,
    /// Voxels per unit length.
    scale: f32,
    dims: [u32; 3],
    /// One bit per voxel, x fastest.
    clear: Vec<u64>,
}

impl ClearVoxels {
    /// Voxels of the box [lo, hi] from which the light polygon `light` (its
    /// corners, in order) is seen past none of `occluders`. `margin` enlarges
    /// each voxel and the light, covering the rounding of shadow rays' ends.
    pub fn build(
        lo: Vec3A,
        hi: Vec3A,
        light: &[Vec3A],
        occluders: &[[Vec3A; 3]],
        margin: f32,
    ) -> ClearVoxels {
        let extent = (hi - lo).max(Vec3A::splat(f32::MIN_POSITIVE));
        let scale = RESOLUTION / extent.max_element();
        let dims = (extent * scale)
            .ceil()
            .max(Vec3A::ONE)
            .to_array()
            .map(|d| d as u32);
        let count = (dims[0] * dims[1] * dims[2]) as usize;
        let margin = f64::from(margin);
        let light_points = light_hull_points(light, margin);
        let occluders: Vec<[DVec3; 3]> =
            occluders.iter().map(|t| t.map(|v| v.as_dvec3())).collect();
        // Each voxel against every occluder: about 10^5 separating-axis
        // tests for the Cornell box, spread over the threads.
        let is_clear = |index: usize| {
            let (x, y, z) = (
                index as u32 % dims[0],
                index as u32 / dims[0] % dims[1],
                index as u32 / (dims[0] * dims[1]),
            );
            let corner = |c: u32| {
                let v = Vec3A::new(
                    (x + (c & 1)) as f32,
                    (y + (c >> 1 & 1)) as f32,
                    (z + (c >> 2)) as f32,
                );
                let p = (lo + v / scale).as_dvec3();
                let outward = DVec3::new(
                    if c & 1 == 0 { -1.0 } else { 1.0 },
                    if c >> 1 & 1 == 0 { -1.0 } else { 1.0 },
                    if c >> 2 == 0 { -1.0 } else { 1.0 },
                );
                p + outward * margin
            };
            let mut hull = [DVec3::ZERO; HULL_POINTS];
            for (c, point) in hull[..8].iter_mut().enumerate() {
                *point = corner(c as u32);
            }
            hull[8..].copy_from_slice(&light_points[..HULL_POINTS - 8]);
            occluders.iter().all(|t| separated(t, &hull, light))
        };
        let flags: Vec<bool> = (0..count).into_par_iter().map(is_clear).collect();
        let mut clear = vec![0u64; count.div_ceil(64)];
        for (index, _) in flags.iter().enumerate().filter(|(_, c)| **c) {
            clear[index / 64] |= 1 << (index % 64);
        }
        ClearVoxels {
            lo,
            scale,
            dims,
            clear,
        }
    }

    /// True when every shadow ray from `p` to the light is unblocked (false
    /// outside the box).
    #[inline(always)]
    pub fn is_clear(&self, p: Vec3A) -> bool {
        let v = (p - self.lo) * self.scale;
        // Negative or NaN coordinates fail the >= test.
        if !v.cmpge(Vec3A::ZERO).all() {
            return false;
        }
        let [x, y, z] = v.to_array().map(|c| c as u32);
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return false;
        }
        let index = ((z * self.dims[1] + y) * self.dims[0] + x) as usize;
        self.clear[index / 64] >> (index % 64) & 1 == 1
    }

    /// The fraction of voxels that are clear (for summaries and tests).
    pub fn clear_fraction(&self) -> f64 {
        let count = self.dims.iter().product::<u32>() as f64;
        self.clear.iter().map(|w| w.count_ones()).sum::<u32>() as f64 / count
    }
}

/// The light's corners moved off its plane by `margin` to both sides and
/// outward from its centre by `margin`.
fn light_hull_points(light: &[Vec3A], margin: f64) -> Vec<DVec3> {
    // A triangle's first corner twice, so that every light gives eight.
    let light: Vec<Vec3A> = light.iter().copied().cycle().take(4).collect();
    let points: Vec<DVec3> = light.iter().map(|v| v.as_dvec3()).collect();
    let centre = points.iter().sum::<DVec3>() / points.len() as f64;
    let normal = (points[1] - points[0])
        .cross(points[2] - points[0])
        .normalize_or_zero();
    points
        .iter()
        .flat_map(|&p| {
            let out = (p - centre).normalize_or_zero() * margin;
            [p + out + normal * margin, p + out - normal * margin]
        })
        .collect()
}

/// True when some axis separates the triangle from the convex hull of
/// `hull` (so they do not meet); false when none of the axes tried does.
/// The cheap axes come first: the box axes, then the triangle's normal.
fn separated(triangle: &[DVec3; 3], hull: &[DVec3; HULL_POINTS], light: &[Vec3A]) -> bool {
    let separates = |axis: DVec3| {
        if axis.length_squared() < 1e-24 {
            return false;
        }
        let (t_lo, t_hi) = interval(triangle, axis);
        let (h_lo, h_hi) = interval(hull, axis);
        t_hi < h_lo || h_hi < t_lo
    };
    if [DVec3::X, DVec3::Y, DVec3::Z].into_iter().any(separates) {
        return true;
    }
    let edges = [
        triangle[1] - triangle[0],
        triangle[2] - triangle[1],
        triangle[0] - triangle[2],
    ];
    let light_edges = [
        (light[1] - light[0]).as_dvec3(),
        (light[2] - light[1]).as_dvec3(),
    ];
    let light_normal = light_edges[0].cross(light_edges[1]);
    // Voxel centre to light centre (the hull's first eight points are the
    // voxel's corners).
    let centre = |points: &[DVec3]| points.iter().sum::<DVec3>() / points.len() as f64;
    let direction = centre(&hull[8..]) - centre(&hull[..8]);
    let crossed = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        light_normal,
        light_edges[0],
        light_edges[1],
        direction,
    ];
    separates(edges[0].cross(edges[1]))
        || separates(light_normal)
        || edges
            .iter()
            .any(|e| crossed.iter().any(|&a| separates(e.cross(a))))
}

/// The projections of `points` onto `axis`: (min, max).
fn interval(points: &[DVec3], axis: DVec3) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = p.dot(axis);
            (lo.min(d), hi.max(d))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::triangle::ShearedRay;
    use crate::math::Ray;
    use crate::sampling::hash::{hash_combine, to_unit_float};

    /// A floor-level room under a square light with a box standing in it:
    /// from every clear voxel, random rays to random light points miss every
    /// occluder (the scalar test says so), and there are clear voxels (the
    /// test is not vacuous) as well as blocked ones (near the box).
    #[test]
    fn rays_from_clear_voxels_to_the_light_are_never_blocked() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let (lo, hi) = (Vec3A::ZERO, Vec3A::splat(4.0));
        let light = [
            Vec3A::new(1.5, 3.9, 1.5),
            Vec3A::new(2.5, 3.9, 1.5),
            Vec3A::new(2.5, 3.9, 2.5),
            Vec3A::new(1.5, 3.9, 2.5),
        ];
        // A box [1, 2] x [0, 1.5] x [1, 2] as twelve triangles, and a slanted
        // panel.
        let corner = |c: u32| {
            Vec3A::new(
                1.0 + (c & 1) as f32,
                1.5 * (c >> 1 & 1) as f32,
                1.0 + (c >> 2) as f32,
            )
        };
        let mut occluders = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                let face: Vec<Vec3A> = (0..8)
                    .filter(|c| (c >> axis) & 1 == side)
                    .map(corner)
                    .collect();
                occluders.push([face[0], face[1], face[3]]);
                occluders.push([face[0], face[3], face[2]]);
            }
        }
        occluders.push([
            Vec3A::new(3.0, 2.0, 0.5),
            Vec3A::new(3.5, 3.0, 0.5),
            Vec3A::new(3.2, 2.5, 1.5),
        ]);
        let voxels = ClearVoxels::build(lo, hi, &light, &occluders, 1e-4);
        let fraction = voxels.clear_fraction();
        assert!(fraction > 0.2 && fraction < 0.95, "{fraction}");
        let mut tested = 0;
        for i in 0..200_000u64 {
            let p = Vec3A::new(u(1, i), u(2, i), u(3, i)) * 4.0;
            if !voxels.is_clear(p) {
                continue;
            }
            let (s, t) = (u(4, i), u(5, i));
            let q = light[0] + s * (light[1] - light[0]) + t * (light[3] - light[0]);
            let ray = Ray::new(p, (q - p).normalize());
            let sheared = ShearedRay::new(&ray);
            let t_max = (q - p).length();
            for tri in &occluders {
                assert!(
                    sheared.intersect(tri, t_max).is_none(),
                    "ray {i} from {p} is blocked"
                );
            }
            tested += 1;
        }
        assert!(tested > 20_000, "{tested}");
        // Right above the box, looking up at the light: clear; beside the
        // box on the floor, where its shadow falls partly: not clear.
        assert!(voxels.is_clear(Vec3A::new(1.5, 1.9, 1.5)));
        assert!(!voxels.is_clear(Vec3A::new(2.1, 0.05, 1.5)));
        assert!(!voxels.is_clear(Vec3A::new(-0.1, 1.0, 1.0)));
    }
}
