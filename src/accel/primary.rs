//! Camera rays of a pinhole camera tested against only the triangles that
//! can cover their pixel.
//!
//! Every camera ray of pixel (x, y) leaves the eye through the pixel's
//! square on the image plane, so it can only hit a triangle whose projection
//! overlaps that square. A triangle-square overlap test (separating axes:
//! the square's two, the triangle's three edge normals) on the projected
//! vertices, done once per scene and camera, leaves one or two candidates
//! for most pixels of a room, where the soup would test all of its blocks.
//! Candidates are tested in storage order by the same watertight test, so
//! the hit is the one the soup finds.

use super::seen_emitters::integrate_seen_emitters;
use crate::math::Rgb;
use crate::scene::camera::Camera;
use glam::{DVec2, DVec3, Vec3A};

/// A pixel with more candidates than this tests the whole scene instead.
const MAX_CANDIDATES: usize = 16;

/// Pixels (fractions of one) by which a pixel's square is enlarged: covers
/// the rounding of the camera ray's direction (about 10^-5 pixel at 16k
/// pixels across) with a wide margin; a larger square only adds candidates.
const MARGIN: f64 = 1.0 / 64.0;

/// Per-pixel candidate triangles of camera rays, for one camera.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimaryCandidates {
    /// The camera the lists are for: a moved camera needs new lists.
    camera: Camera,
    /// Per pixel, [first, count] of its list in `triangles`; a count of
    /// [`FULL_TEST`] marks a pixel whose list would be too long.
    ranges: Vec<[u32; 2]>,
    /// The lists, one after the other, each in storage order.
    triangles: Vec<u32>,
    /// Per pixel, an index into `seen_values` or [`NOT_SEEN`]; empty when
    /// no pixel sees an emitter (see [`PrimaryCandidates::with_seen_emitters`]).
    seen_index: Vec<u32>,
    /// Emission seen through a pixel, integrated over its square.
    seen_values: Vec<Rgb>,
}

/// What a renderer knows in advance about the camera rays of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrimaryPixel<'a> {
    /// The only triangles they can hit, in storage order, where known.
    pub candidates: Option<&'a [u32]>,
    /// The emission they see directly, integrated exactly over the pixel
    /// (`crate::accel::seen_emitters`); where it is known, a camera ray's
    /// hit on an emitter adds no emission of its own.
    pub seen_emission: Option<Rgb>,
}

/// Marks a pixel whose seen emission is not known.
const NOT_SEEN: u32 = u32::MAX;

/// Marks a pixel whose camera rays test the whole scene.
const FULL_TEST: u32 = u32::MAX;

impl PrimaryCandidates {
    /// The candidate lists of `camera`'s pixels for `triangles`, or None
    /// where they do not apply: a thin lens (rays leave from anywhere on the
    /// lens), or a triangle reaching behind the eye's image plane (its
    /// projection is unbounded).
    pub fn build(camera: &Camera, triangles: &[[Vec3A; 3]]) -> Option<Self> {
        if camera.aperture_radius > 0.0 || camera.width == 0 || camera.height == 0 {
            return None;
        }
        let (width, height) = (camera.width as usize, camera.height as usize);
        // (pixel, triangle) pairs, triangles in storage order.
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (index, triangle) in triangles.iter().enumerate() {
            let depths = triangle.map(|v| f64::from((v - camera.eye).dot(camera.forward)));
            // Camera rays point into the half-space in front of the eye, so a
            // triangle entirely behind it is never hit.
            if depths.iter().all(|&z| z <= 0.0) {
                continue;
            }
            let projected = project_triangle(camera, triangle)?;
            let lo = projected.iter().fold(DVec2::INFINITY, |a, &p| a.min(p)) - MARGIN;
            let hi = projected.iter().fold(DVec2::NEG_INFINITY, |a, &p| a.max(p)) + MARGIN;
            if hi.x < 0.0 || hi.y < 0.0 || lo.x > width as f64 || lo.y > height as f64 {
                continue;
            }
            let x_range = (lo.x.max(0.0).floor() as usize)..(hi.x.ceil() as usize).min(width);
            let y_range = (lo.y.max(0.0).floor() as usize)..(hi.y.ceil() as usize).min(height);
            let edges = EdgeTests::new(&projected);
            for y in y_range {
                for x in x_range.clone() {
                    let square_lo = DVec2::new(x as f64, y as f64) - MARGIN;
                    let square_hi = square_lo + (1.0 + 2.0 * MARGIN);
                    if edges.overlaps(square_lo, square_hi) {
                        pairs.push(((y * width + x) as u32, index as u32));
                    }
                }
            }
        }
        // Counting sort by pixel, stable: each list stays in storage order.
        let mut ranges = vec![[0u32, 0u32]; width * height];
        for &(pixel, _) in &pairs {
            ranges[pixel as usize][1] += 1;
        }
        let mut total = 0;
        for range in &mut ranges {
            if range[1] as usize > MAX_CANDIDATES {
                *range = [0, FULL_TEST];
            } else {
                range[0] = total;
                total += range[1];
            }
        }
        let mut lists = vec![0u32; total as usize];
        let mut filled = vec![0u32; width * height];
        for &(pixel, triangle) in &pairs {
            let [first, count] = ranges[pixel as usize];
            if count != FULL_TEST {
                let slot = &mut filled[pixel as usize];
                lists[(first + *slot) as usize] = triangle;
                *slot += 1;
            }
        }
        Some(PrimaryCandidates {
            camera: *camera,
            ranges,
            triangles: lists,
            seen_index: Vec::new(),
            seen_values: Vec::new(),
        })
    }

    /// Adds each pixel's directly seen emission, integrated over the pixel,
    /// where it can be known exactly (`crate::accel::seen_emitters`).
    /// `seen_radiance(i)`: what triangle `i` (storage order) emits towards
    /// the eye, None when it is not a light.
    pub fn with_seen_emitters(
        mut self,
        triangles: &[[Vec3A; 3]],
        seen_radiance: impl Fn(usize) -> Option<Rgb>,
    ) -> Self {
        let pixels = self.ranges.len() as u32;
        let seen = integrate_seen_emitters(
            &self.camera,
            triangles,
            (0..pixels).map(|p| self.of_pixel(p)),
            seen_radiance,
        );
        self.seen_values.clear();
        self.seen_index = seen
            .iter()
            .map(|value| match value {
                Some(v) => {
                    self.seen_values.push(*v);
                    self.seen_values.len() as u32 - 1
                }
                None => NOT_SEEN,
            })
            .collect();
        if self.seen_values.is_empty() {
            self.seen_index = Vec::new();
        }
        self
    }

    /// What is known about `pixel`'s camera rays.
    #[inline(always)]
    pub fn pixel(&self, pixel: u32) -> PrimaryPixel<'_> {
        let seen_emission = match self.seen_index.get(pixel as usize) {
            Some(&i) if i != NOT_SEEN => Some(self.seen_values[i as usize]),
            _ => None,
        };
        PrimaryPixel {
            candidates: self.of_pixel(pixel),
            seen_emission,
        }
    }

    /// Pixels whose seen emission is integrated exactly.
    pub fn pixels_with_seen_emission(&self) -> usize {
        self.seen_values.len()
    }

    /// True when the lists were made for `camera`.
    pub fn is_for(&self, camera: &Camera) -> bool {
        self.camera == *camera
    }

    /// The triangles a camera ray of `pixel` may hit, in storage order, or
    /// None when that pixel's rays must test the whole scene.
    #[inline(always)]
    pub fn of_pixel(&self, pixel: u32) -> Option<&[u32]> {
        let [first, count] = self.ranges[pixel as usize];
        (count != FULL_TEST).then(|| &self.triangles[first as usize..(first + count) as usize])
    }

    /// Mean candidates per pixel, and pixels that test the whole scene.
    pub fn summary(&self) -> (f64, usize) {
        let full = self.ranges.iter().filter(|r| r[1] == FULL_TEST).count();
        (
            self.triangles.len() as f64 / self.ranges.len().max(1) as f64,
            full,
        )
    }
}

/// The triangle's vertices in pixel coordinates (x right, y down, as
/// [`Camera::generate_ray`] reads its film position), or None when a vertex
/// lies on or behind the eye's image plane.
pub(super) fn project_triangle(camera: &Camera, triangle: &[Vec3A; 3]) -> Option<[DVec2; 3]> {
    let aspect = f64::from(camera.width) / f64::from(camera.height);
    let tan_y = f64::from(camera.tan_half_fov_y);
    let (right, up, forward) = (
        camera.right.as_dvec3(),
        camera.up.as_dvec3(),
        camera.forward.as_dvec3(),
    );
    let eye = camera.eye.as_dvec3();
    let mut out = [DVec2::ZERO; 3];
    for (p, v) in out.iter_mut().zip(triangle) {
        let d: DVec3 = v.as_dvec3() - eye;
        let z = d.dot(forward);
        // Far enough in front that the division stays well conditioned.
        if z <= 1e-6 * d.length() {
            return None;
        }
        let ndc_x = d.dot(right) / z / (tan_y * aspect);
        let ndc_y = d.dot(up) / z / tan_y;
        *p = DVec2::new(
            (ndc_x + 1.0) * 0.5 * f64::from(camera.width),
            (1.0 - ndc_y) * 0.5 * f64::from(camera.height),
        );
    }
    Some(out)
}

/// The projected triangle's edge lines, oriented so that its inside is on
/// their positive side.
pub(super) struct EdgeTests {
    /// (normal, offset): a point p is on the inner side when normal . p >= offset.
    pub(super) edges: [(DVec2, f64); 3],
    /// A triangle seen edge-on has no inside to test: its bounding box decides.
    pub(super) degenerate: bool,
}

impl EdgeTests {
    pub(super) fn new(p: &[DVec2; 3]) -> Self {
        let area2 = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        let orientation = area2.signum();
        let edges = [0, 1, 2].map(|i| {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            // Left normal of a -> b, flipped for clockwise triangles.
            let normal = DVec2::new(a.y - b.y, b.x - a.x) * orientation;
            (normal, normal.dot(a))
        });
        let scale = (p[1] - p[0]).length() * (p[2] - p[0]).length();
        EdgeTests {
            edges,
            degenerate: area2.abs() <= 1e-9 * scale,
        }
    }

    /// True unless an edge line separates the square [lo, hi] from the
    /// triangle (the bounding boxes are known to overlap).
    fn overlaps(&self, lo: DVec2, hi: DVec2) -> bool {
        self.degenerate
            || self.edges.iter().all(|&(normal, offset)| {
                // The square's corner furthest along the normal.
                let corner = DVec2::new(
                    if normal.x >= 0.0 { hi.x } else { lo.x },
                    if normal.y >= 0.0 { hi.y } else { lo.y },
                );
                normal.dot(corner) >= offset
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::triangle::closest_by_scalar_test;
    use crate::sampling::hash::{hash_combine, to_unit_float};
    use glam::Vec2;

    /// The closest hit over all triangles by the scalar test: (index, t).
    fn closest(ray: &crate::math::Ray, triangles: &[[Vec3A; 3]]) -> Option<(usize, f32)> {
        closest_by_scalar_test(ray, triangles).map(|(k, t, _, _)| (k, t))
    }

    /// Random triangles in front of a camera, a room's floor and walls
    /// among them: every camera ray, at random film positions in every pixel
    /// and at the pixels' corners and edges, hits the triangle the whole set
    /// gives it, and that triangle is among its pixel's candidates.
    #[test]
    fn every_camera_ray_hits_one_of_its_pixels_candidates() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let camera = Camera::look_at(
            Vec3A::new(0.0, 1.0, -4.0),
            Vec3A::new(0.1, 0.9, 0.0),
            Vec3A::Y,
            50.0,
            40,
            30,
            0.0,
            1.0,
        );
        let mut triangles: Vec<[Vec3A; 3]> = (0..40u64)
            .map(|i| {
                let p = |k| Vec3A::new(u(k, i) * 4.0 - 2.0, u(k + 1, i) * 3.0, u(k + 2, i) * 3.0);
                [p(10), p(20), p(30)]
            })
            .collect();
        let (a, b, c, d) = (
            Vec3A::new(-2.0, 0.0, -1.0),
            Vec3A::new(2.0, 0.0, -1.0),
            Vec3A::new(2.0, 0.0, 3.0),
            Vec3A::new(-2.0, 0.0, 3.0),
        );
        triangles.extend([[a, b, c], [a, c, d]]);
        let up = Vec3A::new(0.0, 3.0, 0.0);
        triangles.extend([[d, c, c + up], [d, c + up, d + up]]);
        let lists = PrimaryCandidates::build(&camera, &triangles).expect("pinhole, all in front");
        let (mean, full) = lists.summary();
        assert!(mean > 1.0 && mean < 16.0, "{mean}");
        let mut hits = 0;
        for y in 0..camera.height {
            for x in 0..camera.width {
                let pixel = y * camera.width + x;
                let candidates = lists.of_pixel(pixel);
                let film_points = (0..12u64)
                    .map(|s| {
                        Vec2::new(
                            u(1, u64::from(pixel) * 16 + s),
                            u(2, u64::from(pixel) * 16 + s),
                        )
                    })
                    .chain([Vec2::ZERO, Vec2::new(0.5, 0.0), Vec2::new(0.0, 0.5)]);
                for offset in film_points {
                    let film = Vec2::new(x as f32, y as f32) + offset;
                    let ray = camera.generate_ray(film, Vec2::splat(0.5));
                    let expected = closest(&ray, &triangles);
                    let Some(candidates) = candidates else {
                        continue;
                    };
                    let subset: Vec<[Vec3A; 3]> =
                        candidates.iter().map(|&i| triangles[i as usize]).collect();
                    let among = closest(&ray, &subset).map(|(k, t)| (candidates[k] as usize, t));
                    assert_eq!(among, expected, "pixel ({x}, {y}) at {offset}");
                    hits += usize::from(expected.is_some());
                }
            }
        }
        assert!(full < 40 * 30 / 10, "{full} pixels test everything");
        // Most rays hit something (the test is not vacuous).
        assert!(hits > 40 * 30 * 4, "{hits}");
    }

    #[test]
    fn a_thin_lens_or_a_triangle_behind_the_eye_gets_no_lists() {
        let camera =
            |aperture| Camera::look_at(Vec3A::ZERO, Vec3A::Z, Vec3A::Y, 40.0, 8, 8, aperture, 1.0);
        let in_front = [
            Vec3A::new(-1.0, -1.0, 2.0),
            Vec3A::new(1.0, -1.0, 2.0),
            Vec3A::new(0.0, 1.0, 2.0),
        ];
        let straddling = [
            Vec3A::new(-1.0, -1.0, -2.0),
            Vec3A::new(1.0, -1.0, 2.0),
            Vec3A::new(0.0, 1.0, 2.0),
        ];
        let behind = in_front.map(|v| -v);
        assert!(PrimaryCandidates::build(&camera(0.0), &[in_front, behind]).is_some());
        assert!(PrimaryCandidates::build(&camera(0.1), &[in_front]).is_none());
        assert!(PrimaryCandidates::build(&camera(0.0), &[in_front, straddling]).is_none());
        // The triangle in front covers the centre pixels; the one behind none.
        let lists = PrimaryCandidates::build(&camera(0.0), &[in_front, behind]).unwrap();
        assert_eq!(lists.of_pixel(4 * 8 + 4), Some(&[0u32][..]));
        assert_eq!(lists.of_pixel(0), Some(&[][..]));
    }
}
