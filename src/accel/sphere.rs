//! Ray/sphere intersection.

use super::Sphere;
use glam::Vec3A;
use wide::f32x8;

/// Nearest sphere intersection in (0, t_max) for a unit-length direction.
/// The discriminant is computed from the perpendicular distance to the centre
/// (pbrt-v4, 6.8.1), which stays accurate when the sphere is small and far away.
#[inline(always)]
pub fn intersect_sphere(
    origin: Vec3A,
    direction: Vec3A,
    center: Vec3A,
    radius: f32,
    t_max: f32,
) -> Option<f32> {
    let f = origin - center;
    let b = f.dot(direction);
    let perp = f - b * direction;
    let discriminant = radius * radius - perp.length_squared();
    if discriminant < 0.0 {
        return None;
    }
    let c = f.length_squared() - radius * radius;
    let q = -b - discriminant.sqrt().copysign(b);
    let (mut t0, mut t1) = (c / q, q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > 0.0 && t0 < t_max {
        Some(t0)
    } else if t1 > 0.0 && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// Fewest spheres (without a BVH) tested in lanes of eight rather than one
/// by one. Path tracing, 2 threads, alternating renders: four spheres
/// (veach-mis, `scenes/sphere_light.toml`) +2% and +4%, three +3%, two
/// small ones +1% (within the spread); one large sphere (SmallVCM's mirror
/// ball, and each of `motion_blur.toml`'s moving balls, which are tested
/// alone) −4.5% and −5%, where the lanes pay their root and division on
/// most rays.
pub const SPHERE_LANES_MIN: usize = 3;

/// Up to eight spheres tested by one instruction per step, a lane each: the
/// few spheres of a scene that gets no sphere BVH (veach-mis's four lights,
/// tested one by one, were 5% of its path tracing on one thread). Each lane
/// computes exactly what [`intersect_sphere`] does, in the same order, so
/// hits are bit-identical to the scalar test's.
#[derive(Clone, Debug)]
pub struct SphereLanes {
    center: [f32x8; 3],
    /// r², and -1 in unused lanes (a negative discriminant: never hit).
    radius2: f32x8,
    /// Index of the first sphere of the lanes.
    first: u32,
}

impl SphereLanes {
    /// The spheres in groups of eight, in order.
    pub fn pack(spheres: &[Sphere]) -> Vec<SphereLanes> {
        spheres
            .chunks(8)
            .enumerate()
            .map(|(k, chunk)| {
                let mut center = [[0.0f32; 8]; 3];
                let mut radius2 = [-1.0f32; 8];
                for (lane, sphere) in chunk.iter().enumerate() {
                    for axis in 0..3 {
                        center[axis][lane] = sphere.center[axis];
                    }
                    radius2[lane] = sphere.radius * sphere.radius;
                }
                SphereLanes {
                    center: center.map(f32x8::new),
                    radius2: f32x8::new(radius2),
                    first: (8 * k) as u32,
                }
            })
            .collect()
    }

    /// Per lane, the nearest hit in (0, t_max), or infinity.
    #[inline(always)]
    fn hits(&self, origin: Vec3A, direction: Vec3A, t_max: f32) -> f32x8 {
        let o = origin.to_array().map(f32x8::splat);
        let d = direction.to_array().map(f32x8::splat);
        let f = [0, 1, 2].map(|a| o[a] - self.center[a]);
        let b = f[0] * d[0] + f[1] * d[1] + f[2] * d[2];
        let perp = [0, 1, 2].map(|a| f[a] - b * d[a]);
        let zero = f32x8::ZERO;
        let discriminant =
            self.radius2 - (perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]);
        let none = f32x8::splat(f32::INFINITY);
        let reached = discriminant.simd_ge(zero);
        // Most rays pass every sphere: no root or division for them.
        if !reached.any() {
            return none;
        }
        let c = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) - self.radius2;
        let root = discriminant.max(zero).sqrt();
        let q = -b - b.is_sign_negative().select(-root, root);
        let (t0, t1) = (c / q, q);
        let swap = t0.simd_gt(t1);
        let (near, far) = (swap.select(t1, t0), swap.select(t0, t1));
        let limit = f32x8::splat(t_max);
        let t = (near.simd_gt(zero) & near.simd_lt(limit)).select(
            near,
            (far.simd_gt(zero) & far.simd_lt(limit)).select(far, none),
        );
        reached.select(t, none)
    }

    /// The nearest hit among the lanes in (0, t_max): sphere index and t
    /// (the first sphere on a tie, as a loop in order finds).
    #[inline(always)]
    pub fn closest(&self, origin: Vec3A, direction: Vec3A, t_max: f32) -> Option<(usize, f32)> {
        let t = self.hits(origin, direction, t_max).to_array();
        let mut best: Option<(usize, f32)> = None;
        for (lane, &t) in t.iter().enumerate() {
            if t < best.map_or(t_max, |b| b.1) {
                best = Some((self.first as usize + lane, t));
            }
        }
        best
    }

    /// Whether some sphere of the lanes is hit in (0, t_max).
    #[inline(always)]
    pub fn any(&self, origin: Vec3A, direction: Vec3A, t_max: f32) -> bool {
        self.hits(origin, direction, t_max)
            .simd_lt(f32x8::splat(f32::INFINITY))
            .any()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash::{hash_combine, to_unit_float};

    /// The lanes find the sphere and the t (to the bit) that testing the
    /// spheres one by one in order finds, nearest first, and say whether
    /// any is hit as the loop does: nine spheres (two groups, one not
    /// full), some overlapping, rays from inside and outside, and rays
    /// whose t_max stops short.
    #[test]
    fn lanes_agree_with_the_scalar_test() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let spheres: Vec<Sphere> = (0..9u64)
            .map(|i| Sphere {
                center: Vec3A::new(u(1, i), u(2, i), u(3, i)) * 4.0 - Vec3A::splat(2.0),
                radius: 0.1 + u(4, i),
                material: 0,
                light: 0,
            })
            .collect();
        let lanes = SphereLanes::pack(&spheres);
        assert_eq!(lanes.len(), 2);
        let (mut hits, mut misses) = (0, 0);
        for i in 0..50_000u64 {
            let origin = Vec3A::new(u(5, i), u(6, i), u(7, i)) * 6.0 - Vec3A::splat(3.0);
            let random = Vec3A::new(u(8, i), u(9, i), u(10, i)) * 2.0 - Vec3A::ONE;
            // Every other ray aims near a sphere, so that hits are many.
            let direction = if i % 2 == 0 {
                random.normalize()
            } else {
                let s = spheres[(i / 2 % 9) as usize];
                (s.center + 1.2 * s.radius * random - origin).normalize()
            };
            let t_max = if i % 3 == 0 { 1.0 } else { f32::INFINITY };
            let mut expected = None;
            for (k, s) in spheres.iter().enumerate() {
                let limit = expected.map_or(t_max, |(_, t)| t);
                if let Some(t) = intersect_sphere(origin, direction, s.center, s.radius, limit) {
                    expected = Some((k, t));
                }
            }
            let mut found: Option<(usize, f32)> = None;
            for group in &lanes {
                let limit = found.map_or(t_max, |(_, t)| t);
                if let Some(hit) = group.closest(origin, direction, limit) {
                    found = Some(hit);
                }
            }
            assert_eq!(
                found.map(|(k, t)| (k, t.to_bits())),
                expected.map(|(k, t)| (k, t.to_bits())),
                "ray {i}"
            );
            let any = lanes.iter().any(|g| g.any(origin, direction, t_max));
            assert_eq!(any, expected.is_some(), "ray {i}");
            if expected.is_some() {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        // Both outcomes are exercised.
        assert!(
            hits > 15_000 && misses > 15_000,
            "{hits} hits, {misses} misses"
        );
    }
}
