//! Warps from the unit square to the domains a renderer samples, each next to
//! the density it produces (Nori's warptest vocabulary). Every warp is checked
//! against its pdf by the chi-square tests in `tests/chi2.rs`.

use glam::{Vec2, Vec3A};
use std::f32::consts::{FRAC_PI_4, PI};

/// Uniform point on the unit disk; Shirley–Chiu concentric map keeps strata compact.
#[inline]
pub fn square_to_concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // theta = pi/4 (y/x) in the left and right wedges, pi/2 - pi/4 (x/y) in
    // the others; cos(pi/2 - phi) = sin(phi) keeps the argument in
    // [-pi/4, pi/4], where a short polynomial is exact to about an ulp. The
    // wedge is chosen by selects: a branch on it is a coin flip per bounce
    // (callgrind: 1.7 mispredictions per Cornell box path).
    let left_right = o.x.abs() > o.y.abs();
    let (radius, across) = if left_right { (o.x, o.y) } else { (o.y, o.x) };
    let (sin, cos) = sin_cos_quarter_pi(FRAC_PI_4 * (across / radius));
    let (along_x, along_y) = if left_right { (cos, sin) } else { (sin, cos) };
    radius * Vec2::new(along_x, along_y)
}

/// sin and cos of x in [-pi/4, pi/4] by the minimax polynomials of Cephes'
/// `sinf`/`cosf` (error about 1 ulp there). libm's `sincosf` first reduces
/// the argument from any range, which is most of its cost: the profile of
/// path tracing showed it at 4.4% of the render.
#[inline]
pub fn sin_cos_quarter_pi(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let sin = x + x * x2 * (-1.666_665_5e-1 + x2 * (8.332_161e-3 + x2 * -1.951_529_6e-4));
    let cos =
        1.0 - 0.5 * x2 + x2 * x2 * (4.166_664_6e-2 + x2 * (-1.388_731_6e-3 + x2 * 2.443_315_7e-5));
    (sin, cos)
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3A {
    let d = square_to_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3A::new(d.x, d.y, z)
}

/// Density wrt. solid angle: cos(theta) / pi.
#[inline]
pub fn cosine_hemisphere_pdf(w: Vec3A) -> f32 {
    if w.z > 0.0 { w.z / PI } else { 0.0 }
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3A {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3A::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density wrt. solid angle: 1 / (4 pi).
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone of half-angle acos(cos_max) around +z.
#[inline]
pub fn square_to_uniform_cone(u: Vec2, cos_max: f32) -> Vec3A {
    square_to_uniform_cap(u, 1.0 - cos_max)
}

/// Density wrt. solid angle: 1 / (2 pi (1 - cos_max)) inside the cone.
#[inline]
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    uniform_cap_pdf(1.0 - cos_max)
}

/// Uniform direction in the spherical cap of height `h` = 1 − cos_max
/// around +z. Given the height, a narrow cap keeps its precision: 1 − cos θ
/// and sin θ come from u h without the cancellation of 1 − cos² θ near 1.
#[inline]
pub fn square_to_uniform_cap(u: Vec2, h: f32) -> Vec3A {
    let one_minus_cos = u.x * h;
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3A::new(
        sin_theta * phi.cos(),
        sin_theta * phi.sin(),
        1.0 - one_minus_cos,
    )
}

/// Density wrt. solid angle: 1 / (2 pi h) inside the cap of height h.
#[inline]
pub fn uniform_cap_pdf(h: f32) -> f32 {
    1.0 / (2.0 * PI * h)
}

/// Height 1 − cos θ_max of the cap a sphere fills as seen from outside,
/// from sin² θ_max = r² / d². Written as sin² / (1 + cos), not 1 − cos:
/// for a small or distant sphere 1 − sin² rounds to 1 in f32, and the
/// difference lost 5% of a light of angular radius 5e-4 and all of one
/// below 2.4e-4 (Mitsuba 3 loses the same).
#[inline]
pub fn sphere_cap_height(sin2_max: f32) -> f32 {
    let sin2_max = sin2_max.clamp(0.0, 1.0);
    sin2_max / (1.0 + (1.0 - sin2_max).sqrt())
}

/// Uniform barycentrics (b1, b2) on a triangle: the square-root warp folds the
/// square onto the triangle with constant density 2 per unit parameter area.
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// Direction around +z with density proportional to cos^n(alpha) on the
/// hemisphere about +z: the lobe of the normalized modified Phong BRDF.
#[inline]
pub fn square_to_phong_lobe(u: Vec2, exponent: f32) -> Vec3A {
    let cos_alpha = u.x.powf(1.0 / (exponent + 1.0));
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3A::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha)
}

/// Density wrt. solid angle: (n + 1) / (2 pi) cos^n(alpha) for cos(alpha) > 0.
#[inline]
pub fn phong_lobe_pdf(cos_alpha: f32, exponent: f32) -> f32 {
    if cos_alpha > 0.0 {
        (exponent + 1.0) / (2.0 * PI) * cos_alpha.powf(exponent)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_narrow_cap_keeps_its_height_and_its_angles() {
        // Against f64: the cap of a sphere of angular radius 1e-5 (1 − sin²
        // rounds to 1 in f32) and the angle of a direction drawn in it.
        for sin in [0.5f64, 1e-2, 1e-3, 1e-5, 1e-7] {
            // 1 − cos as sin² / (1 + cos): f64's own 1 − cos loses digits at 1e-7.
            let exact = sin * sin / (1.0 + (1.0 - sin * sin).sqrt());
            let h = sphere_cap_height((sin * sin) as f32);
            assert!(
                (h as f64 / exact - 1.0).abs() < 1e-6,
                "sin {sin}: {h} against {exact}"
            );
            let d = square_to_uniform_cap(Vec2::new(0.25, 0.1), h);
            let sin_theta = (d.x as f64).hypot(d.y as f64);
            let exact_sin = (0.25 * exact * (2.0 - 0.25 * exact)).sqrt();
            assert!(
                (sin_theta / exact_sin - 1.0).abs() < 1e-6,
                "sin {sin}: {sin_theta}"
            );
        }
    }

    #[test]
    fn quarter_pi_sin_cos_matches_libm() {
        for i in 0..=10_000 {
            let x = std::f32::consts::FRAC_PI_4 * (i as f32 / 5_000.0 - 1.0);
            let (sin, cos) = super::sin_cos_quarter_pi(x);
            assert!(
                (sin - x.sin()).abs() <= 2.0 * f32::EPSILON * x.sin().abs().max(1e-30),
                "{x}"
            );
            assert!((cos - x.cos()).abs() <= 2.0 * f32::EPSILON, "{x}");
        }
    }

    #[test]
    fn warps_land_in_their_domains() {
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new(i as f32 / 31.0, j as f32 / 31.0).min(Vec2::splat(0.99999));
                assert!(square_to_concentric_disk(u).length() <= 1.0 + 1e-6);
                let w = square_to_cosine_hemisphere(u);
                assert!(w.z >= 0.0 && (w.length() - 1.0).abs() < 1e-5);
                assert!((square_to_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
                assert!(square_to_uniform_cone(u, 0.8).z >= 0.8 - 1e-6);
                let b = square_to_uniform_triangle(u);
                assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
                assert!(square_to_phong_lobe(u, 20.0).z >= 0.0);
            }
        }
    }
}

/// A sample of the density on [0, 1] proportional to the line from `a` at 0
/// to `b` at 1 (a, b >= 0, not both 0), by inverting its cumulative
/// distribution (pbrt-v4's `SampleLinear`).
#[inline]
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + (a * a + u * (b * b - a * a)).max(0.0).sqrt());
    x.min(1.0 - f32::EPSILON / 2.0)
}

/// A point of the unit square with density proportional to the bilinear
/// interpolation of the corner values `w` = [w(0, 0), w(1, 0), w(0, 1),
/// w(1, 1)], all >= 0 (pbrt-v4's `SampleBilinear`): y from the marginal,
/// then x given y.
#[inline]
pub fn square_to_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, w[0] + (w[2] - w[0]) * y, w[1] + (w[3] - w[1]) * y);
    Vec2::new(x, y)
}

/// The density of [`square_to_bilinear`] at `p`.
#[inline]
pub fn square_to_bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum == 0.0 {
        return 1.0;
    }
    4.0 * ((1.0 - p.x) * (1.0 - p.y) * w[0]
        + p.x * (1.0 - p.y) * w[1]
        + (1.0 - p.x) * p.y * w[2]
        + p.x * p.y * w[3])
        / sum
}
