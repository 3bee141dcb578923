//! Small geometric helpers shared by every module: colours, rays, frames and
//! the robust ray-origin offset.

use glam::Vec3A;

/// Linear RGB radiance or reflectance.
pub type Rgb = Vec3A;

/// Rec. 709 luminance of a linear RGB value.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// A ray `origin + t * direction` for `t` in `[0, t_max)`. Directions are unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3A,
    pub direction: Vec3A,
    pub t_max: f32,
}

impl Ray {
    /// A ray without an upper bound.
    #[inline]
    pub fn new(origin: Vec3A, direction: Vec3A) -> Self {
        Ray { origin, direction, t_max: f32::INFINITY }
    }

    /// Point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + t * self.direction
    }
}

/// Orthonormal basis with `n` as the local +z axis.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3A,
    pub t: Vec3A,
    pub n: Vec3A,
}

impl Frame {
    /// Branchless basis from a unit normal (Duff et al. 2017, "Building an
    /// Orthonormal Basis, Revisited"): no singularity except at exactly -z,
    /// which the sign trick handles.
    #[inline]
    pub fn from_normal(n: Vec3A) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3A::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Offsets a surface point along its geometric normal `n` (pointing to the
/// side the new ray leaves from) so that the new ray cannot re-hit the surface
/// it starts on. The offset is a fixed number of float ULPs, so it scales with
/// the magnitude of the coordinates rather than being a magic epsilon
/// (Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
/// Ray Tracing Gems, ch. 6). Near the origin, where ULPs become tiny, a small
/// absolute offset takes over.
#[inline]
pub fn offset_ray_origin(p: Vec3A, n: Vec3A) -> Vec3A {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let offset_component = |p: f32, n: f32| -> f32 {
        let of_i = (INT_SCALE * n) as i32;
        let bits = p.to_bits() as i32;
        let moved = f32::from_bits((bits + if p < 0.0 { -of_i } else { of_i }) as u32);
        if p.abs() < ORIGIN { p + FLOAT_SCALE * n } else { moved }
    };
    Vec3A::new(
        offset_component(p.x, n.x),
        offset_component(p.y, n.y),
        offset_component(p.z, n.z),
    )
}

/// Mirror reflection of `w` about the normal `n` (both pointing away from the surface).
#[inline]
pub fn reflect(w: Vec3A, n: Vec3A) -> Vec3A {
    2.0 * w.dot(n) * n - w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_awkward_normals() {
        for n in [
            Vec3A::Z,
            -Vec3A::Z,
            Vec3A::X,
            Vec3A::new(0.0, -1.0, 1e-7).normalize(),
            Vec3A::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5);
            let v = Vec3A::new(0.3, -0.2, 0.9);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn offset_moves_to_the_normal_side_at_every_scale() {
        for scale in [1e-6f32, 1e-2, 1.0, 1e3, 1e5] {
            let p = Vec3A::new(0.7, -0.3, 0.2) * scale;
            let n = Vec3A::new(0.0, 1.0, 0.0);
            let q = offset_ray_origin(p, n);
            assert!(q.y > p.y, "scale {scale}: {q:?} not above {p:?}");
            assert_eq!(q.x, p.x);
            // The offset is tiny relative to the coordinate scale, with an
            // absolute floor of 1/65536 near the origin.
            assert!((q - p).length() <= (1e-4 * scale).max(2.0 / 65536.0));
        }
    }
}
