//! Ray/sphere intersection.

use glam::Vec3A;

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
