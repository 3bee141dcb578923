//! Emitters seen directly through a pixel, integrated exactly over it.
//!
//! Under the box filter a pixel's value is the mean of L over its square on
//! the film. Where a flat emitter of constant radiance Le is the nearest
//! surface wherever it covers the square, its share of that mean is
//! (covered fraction) x Le: a number, known once the camera is. The path
//! tracer adds that number to every sample of the pixel and drops the
//! emission its camera rays find there, so the pixel keeps only the noise of
//! what the emitter does not explain. An area light's rim (in the Cornell
//! box a step from 17 to 0.5 inside one pixel) is then no longer sampled.
//!
//! The share is exact only where nothing can hide part of the emitter
//! inside the pixel. Each other candidate triangle of the pixel must either
//! lie wholly behind the emitter's plane, seen from the eye (so a camera
//! ray meets the emitter first), or not overlap the emitter inside the
//! pixel at all (its neighbours in the same mesh). Pixels where that cannot
//! be shown keep the sampled estimate.

use super::projection::{EdgeTests, project_triangle};
use crate::camera::Camera;
use crate::math::Rgb;
use glam::{DVec2, DVec3, Vec3A};

/// Overlap (in pixels^2) that counts as none: shared edges of a mesh clip to
/// slivers of rounding size. An overlap this small would bias the pixel by
/// at most this fraction of Le.
const NO_OVERLAP: f64 = 1e-7;

/// How far behind an emitter's plane (relative to the eye's distance from
/// it) another triangle must lie for its hits to be farther by more than
/// the watertight test's rounding of t (about 1e-6 relative in f32).
const BEHIND_MARGIN: f64 = 1e-5;

/// A triangle as the check needs it: projected corners and the 3D plane.
struct Candidate {
    projected: [DVec2; 3],
    vertices: [DVec3; 3],
}

/// The emission that `camera` sees through each pixel, integrated over the
/// pixel's square, for pixels where it is exact: `lists[pixel]` are the
/// pixel's candidate triangles (None: unknown), `seen_radiance(i)` the
/// radiance that triangle `i` sends towards the eye when it is a light.
/// Returns the pixels where an emitter is a candidate and the check holds,
/// in order, with what they see.
pub fn integrate_seen_emitters<'a>(
    camera: &Camera,
    triangles: &[[Vec3A; 3]],
    lists: impl Iterator<Item = Option<&'a [u32]>>,
    seen_radiance: impl Fn(usize) -> Option<Rgb>,
) -> Vec<(u32, Rgb)> {
    let width = camera.width as usize;
    let eye = camera.eye.as_dvec3();
    lists
        .enumerate()
        .filter_map(|(pixel, list)| {
            let list = list?;
            if !list.iter().any(|&i| seen_radiance(i as usize).is_some()) {
                return None;
            }
            let (x, y) = ((pixel % width) as f64, (pixel / width) as f64);
            let square = square(DVec2::new(x, y));
            let candidates: Vec<Candidate> = list
                .iter()
                .map(|&i| {
                    let triangle = &triangles[i as usize];
                    Some(Candidate {
                        projected: project_triangle(camera, triangle)?,
                        vertices: triangle.map(|v| v.as_dvec3()),
                    })
                })
                .collect::<Option<_>>()?;
            let mut total = Rgb::ZERO;
            for (k, &i) in list.iter().enumerate() {
                let Some(radiance) = seen_radiance(i as usize) else {
                    continue;
                };
                let emitter = &candidates[k];
                let covered = clip_to_triangle(&square, &emitter.projected);
                let area = polygon_area(&covered);
                if area <= NO_OVERLAP {
                    continue;
                }
                let hidden = candidates.iter().enumerate().any(|(j, other)| {
                    j != k
                        && !behind(other, emitter, eye)
                        && polygon_area(&clip_to_triangle(&covered, &other.projected)) > NO_OVERLAP
                });
                if hidden {
                    return None;
                }
                total += radiance * area as f32;
            }
            Some((pixel as u32, total))
        })
        .collect()
}

/// True when every vertex of `other` lies behind `emitter`'s plane as seen
/// from `eye`, by a margin that the hit distances cannot round away.
fn behind(other: &Candidate, emitter: &Candidate, eye: DVec3) -> bool {
    let [a, b, c] = emitter.vertices;
    let normal = (b - a).cross(c - a);
    let length = normal.length();
    if length == 0.0 {
        return false;
    }
    let normal = normal / length;
    let eye_side = normal.dot(eye - a);
    let margin = BEHIND_MARGIN * (eye - a).length();
    if eye_side.abs() <= margin {
        return false;
    }
    other
        .vertices
        .iter()
        .all(|&v| normal.dot(v - a) * eye_side.signum() < -margin)
}

/// The unit square of the pixel whose corner is `lo`, counter-clockwise.
fn square(lo: DVec2) -> Vec<DVec2> {
    vec![lo, lo + DVec2::X, lo + DVec2::ONE, lo + DVec2::Y]
}

/// The part of convex `polygon` inside `triangle` (Sutherland–Hodgman, one
/// edge line at a time). A triangle seen edge-on keeps nothing.
fn clip_to_triangle(polygon: &[DVec2], triangle: &[DVec2; 3]) -> Vec<DVec2> {
    let edges = EdgeTests::new(triangle);
    if edges.degenerate {
        return Vec::new();
    }
    let mut clipped = polygon.to_vec();
    for &(normal, offset) in &edges.edges {
        clipped = clip_half_plane(&clipped, normal, offset);
        if clipped.is_empty() {
            break;
        }
    }
    clipped
}

/// The part of `polygon` where normal . p >= offset.
fn clip_half_plane(polygon: &[DVec2], normal: DVec2, offset: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (da, db) = (normal.dot(a) - offset, normal.dot(b) - offset);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Area of a simple polygon (shoelace), either orientation.
fn polygon_area(polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|i| polygon[i].perp_dot(polygon[(i + 1) % n]))
        .sum::<f64>()
        .abs()
        * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash::{hash_combine, to_unit_float};
    use glam::Vec2;

    fn camera() -> Camera {
        Camera::look_at(
            Vec3A::new(0.0, 0.0, -4.0),
            Vec3A::ZERO,
            Vec3A::Y,
            40.0,
            24,
            16,
            0.0,
            1.0,
        )
    }

    /// Distance along `ray` to `triangle` (Möller–Trumbore in f64).
    fn hit(origin: DVec3, direction: DVec3, triangle: &[Vec3A; 3]) -> Option<f64> {
        let [a, b, c] = triangle.map(|v| v.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-15 {
            return None;
        }
        let s = origin - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = direction.dot(q) / det;
        let t = e2.dot(q) / det;
        (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
    }

    fn seen(camera: &Camera, triangles: &[[Vec3A; 3]], emitters: &[usize]) -> Vec<Option<Rgb>> {
        // Every triangle is a candidate of every pixel: a superset of the
        // camera lists, which the check must handle the same way.
        let all: Vec<u32> = (0..triangles.len() as u32).collect();
        let pixels = (camera.width * camera.height) as u32;
        let sparse = integrate_seen_emitters(
            camera,
            triangles,
            (0..pixels).map(|_| Some(&all[..])),
            |i| emitters.contains(&i).then_some(Rgb::ONE),
        );
        let mut dense = vec![None; pixels as usize];
        for (pixel, value) in sparse {
            dense[pixel as usize] = Some(value);
        }
        dense
    }

    #[test]
    fn clipping_a_square_by_a_half_plane_keeps_the_right_area() {
        let unit = square(DVec2::ZERO);
        assert!((polygon_area(&unit) - 1.0).abs() < 1e-15);
        let half = clip_half_plane(&unit, DVec2::new(1.0, 1.0), 1.0);
        assert!((polygon_area(&half) - 0.5).abs() < 1e-15);
        let corner = clip_half_plane(&unit, DVec2::new(-1.0, 0.0), -0.25);
        assert!((polygon_area(&corner) - 0.25).abs() < 1e-15);
    }

    /// The exact coverage of an emitter triangle agrees with the fraction of
    /// uniform film points whose camera rays hit it. With n points per
    /// pixel the hit fraction has standard deviation sqrt(a (1 - a) / n)
    /// <= 0.5 / sqrt(n); 5 of those is a tolerance no correct pixel misses
    /// (about 1 in 3.5 million each) and a coverage off by 2% does.
    #[test]
    fn coverage_matches_the_hit_fraction_of_camera_rays() {
        let camera = camera();
        let emitter = [
            Vec3A::new(-0.9, -0.4, 0.5),
            Vec3A::new(0.7, -0.6, 0.2),
            Vec3A::new(0.1, 0.8, 0.9),
        ];
        let seen = seen(&camera, &[emitter], &[0]);
        let n = 4000u64;
        let mut partial = 0;
        for (pixel, value) in seen.iter().enumerate() {
            let (x, y) = (pixel as u32 % camera.width, pixel as u32 / camera.width);
            let hits = (0..n)
                .filter(|&s| {
                    let key = hash_combine(pixel as u64, s);
                    let u = Vec2::new(to_unit_float(key), to_unit_float(hash_combine(key, 7)));
                    let ray = camera.generate_ray(Vec2::new(x as f32, y as f32) + u, Vec2::ZERO);
                    let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
                    hit(o, d, &emitter).is_some()
                })
                .count();
            let fraction = hits as f64 / n as f64;
            let covered = value.map_or(0.0, |v| f64::from(v.x));
            let tolerance = 5.0 * 0.5 / (n as f64).sqrt();
            assert!(
                (fraction - covered).abs() <= tolerance,
                "pixel ({x}, {y}): coverage {covered}, hit fraction {fraction}"
            );
            partial += usize::from(covered > 0.05 && covered < 0.95);
        }
        assert!(
            partial >= 10,
            "the emitter's rim crosses only {partial} pixels"
        );
    }

    /// A triangle in front of the emitter leaves the pixels it overlaps to
    /// sampling; one behind it, or beside it in its plane, does not.
    #[test]
    fn an_occluder_in_front_disables_the_shortcut_and_one_behind_does_not() {
        let camera = camera();
        let (a, b, c, d) = (
            Vec3A::new(-1.0, -1.0, 0.0),
            Vec3A::new(1.0, -1.0, 0.0),
            Vec3A::new(1.0, 1.0, 0.0),
            Vec3A::new(-1.0, 1.0, 0.0),
        );
        // Two emitter triangles of one quad, sharing the diagonal.
        let quad = [[a, b, c], [a, c, d]];
        let alone = seen(&camera, &quad, &[0, 1]);
        let full = alone
            .iter()
            .filter(|v| v.is_some_and(|v| v.x > 0.999))
            .count();
        assert!(full > 20, "{full} fully covered pixels");
        for v in alone.iter().flatten() {
            assert!(v.x <= 1.0 + 1e-9, "coverage {} over one", v.x);
        }

        let shift = |t: [Vec3A; 3], z: f32| t.map(|v| v * 0.5 + Vec3A::new(0.2, 0.1, z));
        let in_front = [quad[0], quad[1], shift(quad[0], -0.5)];
        let hidden = seen(&camera, &in_front, &[0, 1]);
        let behind = [quad[0], quad[1], shift(quad[0], 0.5)];
        let shown = seen(&camera, &behind, &[0, 1]);
        let mut disabled = 0;
        for pixel in 0..alone.len() {
            assert_eq!(shown[pixel], alone[pixel], "pixel {pixel}");
            if hidden[pixel] != alone[pixel] {
                assert_eq!(hidden[pixel], None, "pixel {pixel}");
                disabled += 1;
            }
        }
        assert!(disabled > 5, "only {disabled} pixels disabled");
    }
}
