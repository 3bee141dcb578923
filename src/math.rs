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
    /// Instant within the shutter interval at which the ray samples a moving
    /// scene; every ray of one path carries its camera ray's time.
    pub time: f32,
}

impl Ray {
    /// A ray without an upper bound.
    #[inline]
    pub fn new(origin: Vec3A, direction: Vec3A) -> Self {
        Ray {
            origin,
            direction,
            t_max: f32::INFINITY,
            time: 0.0,
        }
    }

    /// The same ray at `time`.
    #[inline]
    pub fn at_time(self, time: f32) -> Self {
        Ray { time, ..self }
    }

    /// Point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + t * self.direction
    }
}

/// A stored frame that [`Frame::turned`] leaves as [`Frame::from_normal`]
/// builds it (an isotropic surface, which may turn any way).
pub const NO_TURN: u16 = u16::MAX;

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

    /// The frame of normal `n` whose first axis is `tangent` made
    /// perpendicular to `n` (Mitsuba's shading frame from dp/du); the
    /// frame of [`Frame::from_normal`] where that is degenerate.
    #[inline]
    pub fn with_tangent(n: Vec3A, tangent: Vec3A) -> Self {
        let s = (tangent - n * n.dot(tangent)).normalize_or_zero();
        if s == Vec3A::ZERO {
            return Frame::from_normal(n);
        }
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }

    /// How far `tangent`, seen in the frame's plane, turns from `s`, in
    /// 65 535ths of a turn: what a stored vertex keeps (16 bits, 1e-4
    /// radians) to rebuild [`Frame::with_tangent`] by [`Frame::turned`].
    #[inline]
    pub fn turn_towards(&self, tangent: Vec3A) -> u16 {
        let phi = tangent.dot(self.t).atan2(tangent.dot(self.s));
        ((phi / std::f32::consts::TAU).rem_euclid(1.0) * 65535.0).round() as u16 % 65535
    }

    /// The frame turned about its normal by `turn` ([`Frame::turn_towards`]);
    /// itself for [`NO_TURN`].
    #[inline]
    pub fn turned(&self, turn: u16) -> Frame {
        if turn == NO_TURN {
            return *self;
        }
        let (sin, cos) = (turn as f32 * (std::f32::consts::TAU / 65535.0)).sin_cos();
        let s = self.s * cos + self.t * sin;
        Frame {
            s,
            t: self.n.cross(s),
            n: self.n,
        }
    }

    // Always: three dot products, which BDPT's connect otherwise called.
    #[inline(always)]
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline(always)]
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Bound on the relative rounding error of `n` chained float operations:
/// gamma(n) = n u / (1 - n u) with u = 2^-24 (Higham; pbrt-v4 3.9).
#[inline]
pub const fn gamma(n: i32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}

/// The next float towards +infinity.
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v >= 0.0 { bits + 1 } else { bits - 1 })
}

/// The next float towards -infinity.
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v > 0.0 { bits - 1 } else { bits + 1 })
}

/// Origin for a ray leaving the surface point `p` in direction `w`.
///
/// `p_error` bounds, per component, how far the computed `p` may be from the
/// true surface (each intersection routine derives it from the operations
/// that produced `p`). Moving `p` along the geometric normal `n` by the
/// projection of that box onto `n`, to the side `w` leaves from, and rounding
/// away from `p`, puts the origin strictly on that side of the surface, so the
/// new ray cannot hit the surface it starts on; no epsilon, at any scale
/// (pbrt-v4, 6.8.6 "Robust Spawned Ray Origins").
#[inline(always)]
pub fn offset_ray_origin(p: Vec3A, p_error: Vec3A, n: Vec3A, w: Vec3A) -> Vec3A {
    let d = n.abs().dot(p_error);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    round_outwards(p + offset, offset)
}

/// Per component, `next_float_up(v)` where `o > 0`, `next_float_down(v)`
/// where `o < 0`, else `v`. The signs of an offset follow the surface a path
/// hit, which a branch predictor cannot know: callgrind's branch simulation
/// counted 4 mispredictions per Cornell box path for the two branches per
/// component, and LLVM keeps branches even for a scalar select form, so on
/// x86-64 this is written with SSE2 masks.
#[inline(always)]
fn round_outwards(v: Vec3A, o: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of x86-64; the intrinsics only compute.
        unsafe {
            let (vf, of) = (__m128::from(v), __m128::from(o));
            let zero = _mm_setzero_ps();
            let sign = _mm_set1_epi32(i32::MIN);
            let v_bits = _mm_castps_si128(vf);
            let direction = _mm_and_si128(_mm_castps_si128(of), sign);
            // A zero steps to the smallest subnormal on the side it moves to.
            let is_zero = _mm_castps_si128(_mm_cmpeq_ps(vf, zero));
            let bits = _mm_or_si128(
                _mm_and_si128(is_zero, direction),
                _mm_andnot_si128(is_zero, v_bits),
            );
            // Away from zero (+1) when moving to the side of the sign, else -1.
            let outward = _mm_cmpeq_epi32(_mm_and_si128(bits, sign), direction);
            let step = _mm_sub_epi32(_mm_and_si128(outward, _mm_set1_epi32(2)), _mm_set1_epi32(1));
            let stepped = _mm_add_epi32(bits, step);
            // No offset (or NaN), or an infinity already at that end: unchanged.
            let moving = _mm_or_ps(_mm_cmpgt_ps(of, zero), _mm_cmplt_ps(of, zero));
            let magnitude = _mm_andnot_ps(_mm_castsi128_ps(sign), vf);
            let infinite = _mm_cmpeq_ps(magnitude, _mm_set1_ps(f32::INFINITY));
            let stays = _mm_or_si128(
                _mm_andnot_si128(_mm_castps_si128(moving), _mm_set1_epi32(-1)),
                _mm_and_si128(outward, _mm_castps_si128(infinite)),
            );
            let out = _mm_or_si128(
                _mm_and_si128(stays, v_bits),
                _mm_andnot_si128(stays, stepped),
            );
            Vec3A::from(_mm_castsi128_ps(out))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let round = |v: f32, o: f32| {
            if o > 0.0 {
                next_float_up(v)
            } else if o < 0.0 {
                next_float_down(v)
            } else {
                v
            }
        };
        Vec3A::new(round(v.x, o.x), round(v.y, o.y), round(v.z, o.z))
    }
}

/// How spawned rays leave a surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum OffsetMode {
    /// By the point's rounding-error bound: correct at any scene scale.
    #[default]
    Robust,
    /// By a fixed distance along the normal, the classic "epsilon": too
    /// small for large or far-away scenes (shadow acne), too large for small
    /// ones (light leaks, missing contact shadows). Kept to show exactly that.
    Fixed(f32),
}

impl OffsetMode {
    /// Parses `robust` or `fixed:EPS`.
    pub fn parse(text: &str) -> Result<OffsetMode, String> {
        if text == "robust" {
            return Ok(OffsetMode::Robust);
        }
        let eps = text
            .strip_prefix("fixed:")
            .and_then(|e| e.parse::<f32>().ok())
            .filter(|e| e.is_finite() && *e >= 0.0);
        eps.map(OffsetMode::Fixed)
            .ok_or_else(|| format!("`{text}`: expected `robust` or `fixed:EPS` with EPS >= 0"))
    }

    /// The error bound to spawn from: `robust_error` itself, or the bound
    /// that makes [`offset_ray_origin`] move exactly `eps` along `normal`.
    #[inline]
    pub fn spawn_error(self, robust_error: Vec3A, normal: Vec3A) -> Vec3A {
        match self {
            OffsetMode::Robust => robust_error,
            OffsetMode::Fixed(eps) => {
                let l1 = normal.abs().element_sum();
                if l1 > 0.0 {
                    Vec3A::splat(eps / l1)
                } else {
                    Vec3A::ZERO
                }
            }
        }
    }
}

/// Fraction of a segment's length left out at its far end, so that a shadow
/// ray never reaches the surface of the point it aims at (pbrt's ShadowEpsilon).
pub const SHADOW_EPSILON: f32 = 1e-4;

/// A shadow ray between two surface points, each given with its error bound
/// and geometric normal (a zero normal and error for points in free space).
/// Both ends are moved off their surfaces towards each other. The ray is at
/// time 0: a caller in a moving scene sets the path's time with [`Ray::at_time`].
#[inline(always)]
pub fn ray_between(
    from: Vec3A,
    from_error: Vec3A,
    from_normal: Vec3A,
    to: Vec3A,
    to_error: Vec3A,
    to_normal: Vec3A,
) -> Ray {
    let origin = offset_ray_origin(from, from_error, from_normal, to - from);
    let target = offset_ray_origin(to, to_error, to_normal, origin - to);
    let d = target - origin;
    let distance = d.length();
    Ray {
        origin,
        direction: d / distance,
        t_max: distance * (1.0 - SHADOW_EPSILON),
        time: 0.0,
    }
}

/// Mirror reflection of `w` about the normal `n` (both pointing away from the surface).
#[inline]
pub fn reflect(w: Vec3A, n: Vec3A) -> Vec3A {
    2.0 * w.dot(n) * n - w
}

/// Asks the cache for the line holding `value`: a hint for a caller that
/// knows an address well before it reads it, so that work done meanwhile
/// hides the miss.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: prefetching is a hint; it never faults, and the address
        // is that of a live value.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((value as *const T).cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// The error function (Abramowitz and Stegun 7.1.26, |error| < 1.5e-7).
pub fn erf(x: f32) -> f32 {
    erf_and_gaussian(x).0
}

/// erf(x) and the e^{-x²} it is made from, for callers that need both
/// (Beckmann's Λ and its visible slopes): one exponential instead of two.
#[inline]
pub fn erf_and_gaussian(x: f32) -> (f32, f32) {
    let gaussian = (-x * x).exp();
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_6
            + t * (-0.284_496_74 + t * (1.421_413_8 + t * (-1.453_152_1 + t * 1.061_405_4))));
    ((1.0 - poly * gaussian).copysign(x), gaussian)
}

/// The inverse error function (Giles 2010, single precision).
pub fn erfinv(x: f32) -> f32 {
    let mut w = -((1.0 - x) * (1.0 + x)).max(1e-30).ln();
    let p = if w < 5.0 {
        w -= 2.5;
        let mut p = 2.810_226_4e-8;
        p = 3.432_739_4e-7 + p * w;
        p = -3.523_387_7e-6 + p * w;
        p = -4.391_506_5e-6 + p * w;
        p = 2.185_808_7e-4 + p * w;
        p = -1.253_725e-3 + p * w;
        p = -4.177_681_6e-3 + p * w;
        p = 2.466_407_3e-1 + p * w;
        1.501_409_4 + p * w
    } else {
        w = w.sqrt() - 3.0;
        let mut p = -2.002_142_6e-4;
        p = 1.009_505_6e-4 + p * w;
        p = 1.349_343_2e-3 + p * w;
        p = -3.673_428_4e-3 + p * w;
        p = 5.739_507_7e-3 + p * w;
        p = -7.622_461_3e-3 + p * w;
        p = 9.438_870_5e-3 + p * w;
        p = 1.001_674_1 + p * w;
        2.832_976_8 + p * w
    };
    p * x
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
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            let v = Vec3A::new(0.3, -0.2, 0.9);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn offset_leaves_the_surface_by_its_error_bound_at_every_scale() {
        for scale in [1e-6f32, 1e-2, 1.0, 1e3, 1e5] {
            let p = Vec3A::new(0.7, -0.3, 0.2) * scale;
            let error = p.abs() * gamma(7);
            let n = Vec3A::new(0.0, 1.0, 0.0);
            let up = offset_ray_origin(p, error, n, Vec3A::new(0.3, 0.5, 0.0));
            let down = offset_ray_origin(p, error, n, Vec3A::new(0.3, -0.5, 0.0));
            assert!(
                up.y - p.y > error.y && p.y - down.y > error.y,
                "scale {scale}"
            );
            assert_eq!((up.x, up.z), (p.x, p.z));
            // The offset is a few ULPs of the coordinates, not an absolute epsilon.
            assert!(up.y - p.y < 1e-5 * scale);
        }
    }

    #[test]
    fn next_float_steps_one_ulp() {
        assert!(next_float_up(1.0) > 1.0 && next_float_down(1.0) < 1.0);
        assert_eq!(next_float_up(-0.0), f32::from_bits(1));
        assert_eq!(next_float_down(0.0), -f32::from_bits(1));
        assert_eq!(next_float_down(next_float_up(3.5)), 3.5);
    }

    /// The mask form of the offset's rounding agrees bit for bit with the
    /// branches it replaced, on zeros, subnormals, infinities and ordinary
    /// values of either sign, for offsets of either sign and none.
    #[test]
    fn rounding_outwards_matches_next_float_up_and_down() {
        let values = [
            0.0f32,
            -0.0,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MIN_POSITIVE,
            1.0,
            -1.0,
            3.5e-20,
            -7.25e12,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let offsets = [1e-6f32, -1e-6, 0.0, -0.0, f32::NAN];
        for v in values {
            for o in offsets {
                let expected = if o > 0.0 {
                    next_float_up(v)
                } else if o < 0.0 {
                    next_float_down(v)
                } else {
                    v
                };
                // In every lane, beside other values and offsets.
                for lane in 0..3 {
                    let mut vs = Vec3A::new(1.5, -0.0, f32::MAX);
                    let mut os = Vec3A::new(-1.0, 1.0, 0.0);
                    vs[lane] = v;
                    os[lane] = o;
                    let got = round_outwards(vs, os)[lane];
                    assert_eq!(got.to_bits(), expected.to_bits(), "v {v:e} o {o:e}");
                }
            }
        }
    }
}

/// A unit vector in two 16-bit numbers (the octahedral map; Cigolle et
/// al. 2014): under 1e-3 radians of error (6e-4 measured), far below a
/// mesh's facets.
#[inline]
pub fn octahedral_encode(n: Vec3A) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let (mut x, mut y) = (n.x, n.y);
    if n.z < 0.0 {
        (x, y) = (
            (1.0 - n.y.abs()) * n.x.signum(),
            (1.0 - n.x.abs()) * n.y.signum(),
        );
    }
    let q = |v: f32| (((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65534.0).round() as u32).min(65534);
    q(x) | (q(y) << 16)
}

#[inline]
pub fn octahedral_decode(p: u32) -> Vec3A {
    let d = |q: u32| (q & 0xffff) as f32 / 65534.0 * 2.0 - 1.0;
    let (x, y) = (d(p), d(p >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3A::new(x, y, z).normalize()
}

#[cfg(test)]
mod packing_tests {
    use super::*;
    use glam::Vec3A;

    /// A frame rebuilt from its stored turn is the frame built from the
    /// tangent, within the 16 bits' 1e-4 radians, and NO_TURN is never a turn.
    #[test]
    fn a_frames_turn_rebuilds_it() {
        let normals = [Vec3A::Z, -Vec3A::Z, Vec3A::new(0.3, -0.8, 0.2).normalize()];
        for n in normals {
            for k in 0..64 {
                let angle = k as f32 * 0.1 - 3.2;
                let base = Frame::from_normal(n);
                let tangent = base.s * angle.cos() + base.t * angle.sin() + n * 0.4;
                let exact = Frame::with_tangent(n, tangent);
                let turn = base.turn_towards(tangent);
                assert_ne!(turn, NO_TURN);
                let rebuilt = base.turned(turn);
                assert!((rebuilt.s - exact.s).length() < 2e-4, "{n:?} {angle}");
                assert!((rebuilt.t - exact.t).length() < 2e-4, "{n:?} {angle}");
            }
        }
    }

    #[test]
    fn octahedral_packing_keeps_normals_within_1e3_radians() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            let (u, v) = (
                (i as f32 * 0.618034).fract(),
                (i as f32 * 0.7548777).fract(),
            );
            let z = 1.0 - 2.0 * u;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * v;
            let n = Vec3A::new(r * phi.cos(), r * phi.sin(), z);
            let back = octahedral_decode(octahedral_encode(n));
            worst = worst.max(n.dot(back).clamp(-1.0, 1.0).acos());
        }
        assert!(worst < 1e-3, "{worst}");
        assert_ne!(
            octahedral_encode(Vec3A::Z),
            u32::MAX,
            "u32::MAX stays free as a sentinel"
        );
    }
}
