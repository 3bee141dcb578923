//! Watertight ray/triangle intersection, one triangle at a time.

use crate::math::{Ray, gamma};
use glam::{Mat3A, Vec3A};

/// Per-ray constants of the watertight test (Woop, Benthin & Wald, JCGT 2013):
/// a change of basis that permutes the ray's dominant axis to z and shears the
/// ray onto +z. The edge functions are then exact in sign, so rays through a
/// shared edge or vertex hit exactly one of the triangles (watertight). The
/// permutation and shear are folded into one matrix, so each vertex costs one
/// SIMD matrix-vector product instead of per-component indexing; the zero
/// entries add exact zeros, so results equal the textbook formulation.
#[derive(Clone, Copy)]
pub struct ShearedRay {
    origin: Vec3A,
    shear: Mat3A,
}

/// Axes (kx, ky, kz) of the watertight test: kz is the direction's dominant
/// axis, and kx, ky are swapped when it points down kz so that the sheared
/// triangle keeps its winding.
#[inline(always)]
pub fn permuted_axes(d: Vec3A) -> (usize, usize, usize) {
    // The largest |d| component, the first of equal ones (as glam's
    // `max_position`), chosen by selects: every ray does this once.
    let a = d.abs();
    let y_wins = a.y > a.x;
    let largest = if y_wins { a.y } else { a.x };
    let kz = if a.z > largest {
        2
    } else {
        usize::from(y_wins)
    };
    const NEXT: [usize; 3] = [1, 2, 0];
    let (kx, ky) = (NEXT[kz], NEXT[NEXT[kz]]);
    if d.to_array()[kz] < 0.0 {
        (ky, kx, kz)
    } else {
        (kx, ky, kz)
    }
}

/// The shear (sx, sy, sz) = (d[kx], d[ky], 1) / d[kz]: one division and
/// two products, the same in the scalar and the eight-lane test.
#[inline(always)]
pub fn shear_factors(d: Vec3A, kx: usize, ky: usize, kz: usize) -> (f32, f32, f32) {
    let d = d.to_array();
    let sz = 1.0 / d[kz];
    (d[kx] * sz, d[ky] * sz, sz)
}

impl ShearedRay {
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.direction;
        let (kx, ky, kz) = permuted_axes(d);
        let (sx, sy, sz) = shear_factors(d, kx, ky, kz);
        let axis = |k: usize| Vec3A::AXES[k];
        // Rows: x' = v[kx] - sx v[kz], y' = v[ky] - sy v[kz], z' = sz v[kz].
        let rows = [
            axis(kx) - sx * axis(kz),
            axis(ky) - sy * axis(kz),
            sz * axis(kz),
        ];
        ShearedRay {
            origin: ray.origin,
            shear: Mat3A::from_cols(rows[0], rows[1], rows[2]).transpose(),
        }
    }

    /// Returns (t, b1, b2) of a hit in (0, t_max), or None.
    #[inline(always)]
    pub fn intersect(&self, v: &[Vec3A; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let a = self.shear * (v[0] - self.origin);
        let b = self.shear * (v[1] - self.origin);
        let c = self.shear * (v[2] - self.origin);
        let mut e0 = c.x * b.y - c.y * b.x;
        let mut e1 = a.x * c.y - a.y * c.x;
        let mut e2 = b.x * a.y - b.y * a.x;
        // Exactly zero edge functions are ambiguous in single precision:
        // redo them in double so that shared edges are never missed.
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
            e0 = (c.x * b.y - c.y * b.x) as f32;
            e1 = (a.x * c.y - a.y * c.x) as f32;
            e2 = (b.x * a.y - b.y * a.x) as f32;
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }
        let t_scaled = e0 * a.z + e1 * b.z + e2 * c.z;
        // Compare t * det against (0, t_max * det) without dividing.
        let sign = det.signum();
        let (t_abs, det_abs) = (t_scaled * sign, det.abs());
        if t_abs <= 0.0 || t_abs >= t_max * det_abs {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // Reject hits whose t is not provably positive given the rounding of
        // the computation (pbrt-v4, 6.8.4 "Conservative Ray-Triangle t").
        let max_z = a.z.abs().max(b.z.abs()).max(c.z.abs());
        let max_x = a.x.abs().max(b.x.abs()).max(c.x.abs());
        let max_y = a.y.abs().max(b.y.abs()).max(c.y.abs());
        let delta_z = gamma(3) * max_z;
        let delta_x = gamma(5) * (max_x + max_z);
        let delta_y = gamma(5) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some((t, e1 * inv_det, e2 * inv_det))
    }
}

/// The closest hit among all `triangles` by the scalar test, in storage
/// order (index, t, b1, b2): what every faster query must reproduce.
#[cfg(test)]
pub fn closest_by_scalar_test(
    ray: &Ray,
    triangles: &[[Vec3A; 3]],
) -> Option<(usize, f32, f32, f32)> {
    let sheared = ShearedRay::new(ray);
    let mut best: Option<(usize, f32, f32, f32)> = None;
    for (k, tri) in triangles.iter().enumerate() {
        let t_max = best.map_or(f32::INFINITY, |h| h.1);
        if let Some((t, b1, b2)) = sheared.intersect(tri, t_max) {
            best = Some((k, t, b1, b2));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The select form picks the axes glam's `max_position` did, ties and
    /// zeros included (the first of equal components wins).
    #[test]
    fn permuted_axes_match_the_first_largest_component() {
        let reference = |d: Vec3A| {
            let kz = d.abs().max_position();
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 {
                (ky, kx, kz)
            } else {
                (kx, ky, kz)
            }
        };
        let values = [0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 2.0, f32::NAN];
        for x in values {
            for y in values {
                for z in values {
                    let d = Vec3A::new(x, y, z);
                    assert_eq!(permuted_axes(d), reference(d), "{d}");
                }
            }
        }
    }
}
