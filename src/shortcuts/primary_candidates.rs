//! Camera rays of a pinhole camera tested against only the triangles that
//! can cover their pixel.
//!
//! Every camera ray of pixel (x, y) leaves the eye through the pixel's
//! square on the image plane, so it can only hit a triangle whose projection
//! overlaps that square. A triangle-square overlap test (separating axes:
//! the square's two, the triangle's three edge normals) on the projected
//! vertices, done once per camera, leaves one or two candidates for most
//! pixels of a room, where the soup would test all of its blocks.
//! Candidates are tested in storage order by the same watertight test, so
//! the hit is the one the soup finds.
//!
//! The lists are built in two passes over the triangles (count, then fill),
//! so nothing is stored per (pixel, triangle) pair; the cost and the memory
//! are checked against their caps before the lists are allocated.

use super::NotApplied;
use super::projection::{EdgeTests, project_triangle};
use super::seen_emitters::integrate_seen_emitters;
use crate::camera::Camera;
use crate::math::Rgb;
use glam::{DVec2, Vec3A};

/// A pixel with more candidates than this tests the whole scene instead.
const MAX_CANDIDATES: u32 = 16;

/// Overlap tests per pixel the build may take (the sum of the triangles'
/// projected bounding boxes, in pixels, over the pixel count): about 3 for
/// the Cornell box; 30 quads stacked across the whole frame need 62.
const MAX_TESTS_PER_PIXEL: f64 = 24.0;

/// Bytes per pixel the lists may take on average, besides the 4 of each
/// pixel's start: four candidates per pixel (the Cornell box needs 0.7 at
/// 3840x2160, 1.4 at 256x256), about half the film's 28.
const MAX_LIST_BYTES_PER_PIXEL: f64 = 16.0;

/// Bytes the lists and starts may take in all: the Cornell box at
/// 3840x2160 needs 57 MB; at the CLI's 16384x16384 it would need 1.9 GB and
/// renders without them.
const MAX_LIST_BYTES: u64 = 512 << 20;

/// Pixels (fractions of one) by which a pixel's square is enlarged: covers
/// the rounding of the camera ray's direction (about 10^-5 pixel at 16k
/// pixels across) with a wide margin; a larger square only adds candidates.
const MARGIN: f64 = 1.0 / 64.0;

/// Flag of a pixel whose camera rays test the whole scene.
const FULL_TEST: u32 = 1 << 31;

/// Flag of a pixel whose seen emission is known.
const SEEN: u32 = 1 << 30;

/// The start of a pixel's list, without its flags.
const START: u32 = SEEN - 1;

/// Per-pixel candidate triangles of camera rays through their pixel's
/// square, for one camera (a render whose rays leave it does not read them:
/// [`crate::shortcuts::CameraSampling`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PrimaryCandidates {
    /// The camera the lists are for: a moved camera needs new lists.
    camera: Camera,
    /// Per pixel, where its list starts in `triangles`, with the flags
    /// [`FULL_TEST`] and [`SEEN`]; one entry more ends the last list.
    starts: Vec<u32>,
    /// The lists, one after the other, each in storage order.
    triangles: Vec<u32>,
    /// Emission seen through a pixel, integrated over its square, for the
    /// pixels flagged [`SEEN`], sorted by pixel.
    seen: Vec<(u32, Rgb)>,
}

/// What a renderer knows in advance about the camera rays of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrimaryPixel<'a> {
    /// The only triangles they can hit, in storage order, where known.
    pub candidates: Option<&'a [u32]>,
    /// The emission they see directly, integrated exactly over the pixel
    /// (`crate::shortcuts::seen_emitters`); where it is known, a camera
    /// ray's hit on an emitter adds no emission of its own.
    pub seen_emission: Option<Rgb>,
}

/// A triangle's footprint on the film: its edges and the pixels of its box.
struct Footprint {
    edges: EdgeTests,
    xs: std::ops::Range<usize>,
    ys: std::ops::Range<usize>,
}

impl Footprint {
    /// Calls `f` with each pixel whose square the triangle overlaps.
    fn for_each_pixel(&self, width: usize, mut f: impl FnMut(usize)) {
        for y in self.ys.clone() {
            for x in self.xs.clone() {
                let square_lo = DVec2::new(x as f64, y as f64) - MARGIN;
                let square_hi = square_lo + (1.0 + 2.0 * MARGIN);
                if self.edges.overlaps(square_lo, square_hi) {
                    f(y * width + x);
                }
            }
        }
    }

    fn pixels(&self) -> usize {
        self.xs.len() * self.ys.len()
    }
}

impl PrimaryCandidates {
    /// The candidate lists of `camera`'s pixels for `triangles`, or why
    /// they do not apply: a thin lens (rays leave from anywhere on the
    /// lens), a triangle reaching behind the eye's image plane (its
    /// projection is unbounded), a build or lists past their caps, or lists
    /// too long to save anything.
    pub fn build(camera: &Camera, triangles: &[[Vec3A; 3]]) -> Result<Self, NotApplied> {
        if camera.aperture_radius > 0.0 {
            return Err(NotApplied::ThinLens);
        }
        let (width, height) = (camera.width as usize, camera.height as usize);
        let pixels = width * height;
        let mut footprints: Vec<Option<Footprint>> = Vec::with_capacity(triangles.len());
        for triangle in triangles {
            let depths = triangle.map(|v| f64::from((v - camera.eye).dot(camera.forward)));
            // Camera rays point into the half-space in front of the eye, so a
            // triangle entirely behind it is never hit.
            if depths.iter().all(|&z| z <= 0.0) {
                footprints.push(None);
                continue;
            }
            let projected = project_triangle(camera, triangle).ok_or(NotApplied::BehindEye)?;
            let lo = projected.iter().fold(DVec2::INFINITY, |a, &p| a.min(p)) - MARGIN;
            let hi = projected.iter().fold(DVec2::NEG_INFINITY, |a, &p| a.max(p)) + MARGIN;
            if hi.x < 0.0 || hi.y < 0.0 || lo.x > width as f64 || lo.y > height as f64 {
                footprints.push(None);
                continue;
            }
            footprints.push(Some(Footprint {
                edges: EdgeTests::new(&projected),
                xs: (lo.x.max(0.0).floor() as usize)..(hi.x.ceil() as usize).min(width),
                ys: (lo.y.max(0.0).floor() as usize)..(hi.y.ceil() as usize).min(height),
            }));
        }
        let tests: usize = footprints.iter().flatten().map(Footprint::pixels).sum();
        let tests_per_pixel = tests as f64 / pixels.max(1) as f64;
        if tests_per_pixel > MAX_TESTS_PER_PIXEL {
            return Err(NotApplied::Crowded { tests_per_pixel });
        }

        // The starts alone, before any list.
        let starts_bytes = 4 * (pixels as u64 + 1);
        if starts_bytes > MAX_LIST_BYTES {
            return Err(NotApplied::Memory {
                bytes: starts_bytes,
            });
        }
        // Pass 1: each pixel's count.
        let mut starts = vec![0u32; pixels + 1];
        for footprint in footprints.iter().flatten() {
            footprint.for_each_pixel(width, |p| starts[p] += 1);
        }
        let full = starts.iter().filter(|&&n| n > MAX_CANDIDATES).count();
        if full * 2 > pixels {
            // Most rays would test everything anyway, after a lookup.
            return Err(NotApplied::Crowded { tests_per_pixel });
        }
        // Inclusive prefix sums; pixels with too many test everything.
        let mut total = 0u64;
        for start in &mut starts[..pixels] {
            if *start > MAX_CANDIDATES {
                *start = FULL_TEST | total as u32;
            } else {
                total += u64::from(*start);
                *start = total as u32;
            }
        }
        let bytes = 4 * (total + pixels as u64 + 1);
        if (4 * total) as f64 > MAX_LIST_BYTES_PER_PIXEL * pixels as f64
            || bytes > MAX_LIST_BYTES
            || total >= u64::from(START)
        {
            return Err(NotApplied::Memory { bytes });
        }
        starts[pixels] = total as u32;

        // Pass 2: fill each list from its end, triangles in reverse, so that
        // each ends up in storage order and each start where it begins.
        let mut lists = vec![0u32; total as usize];
        for (index, footprint) in footprints.iter().enumerate().rev() {
            let Some(footprint) = footprint else { continue };
            footprint.for_each_pixel(width, |p| {
                if starts[p] & FULL_TEST == 0 {
                    starts[p] -= 1;
                    lists[starts[p] as usize] = index as u32;
                }
            });
        }
        Ok(PrimaryCandidates {
            camera: *camera,
            starts,
            triangles: lists,
            seen: Vec::new(),
        })
    }

    /// Adds each pixel's directly seen emission, integrated over the pixel,
    /// where it can be known exactly (`crate::shortcuts::seen_emitters`).
    /// `seen_radiance(i)`: what triangle `i` (storage order) emits towards
    /// the eye, None when it is not a light.
    pub fn with_seen_emitters(
        mut self,
        triangles: &[[Vec3A; 3]],
        seen_radiance: impl Fn(usize) -> Option<Rgb>,
    ) -> Self {
        let pixels = self.starts.len() as u32 - 1;
        self.seen = integrate_seen_emitters(
            &self.camera,
            triangles,
            (0..pixels).map(|p| self.of_pixel(p)),
            seen_radiance,
        );
        for &(pixel, _) in &self.seen {
            self.starts[pixel as usize] |= SEEN;
        }
        self
    }

    /// What is known about `pixel`'s camera rays.
    #[inline(always)]
    pub fn pixel(&self, pixel: u32) -> PrimaryPixel<'_> {
        let seen_emission = if self.starts[pixel as usize] & SEEN != 0 {
            self.seen
                .binary_search_by_key(&pixel, |&(p, _)| p)
                .ok()
                .map(|i| self.seen[i].1)
        } else {
            None
        };
        PrimaryPixel {
            candidates: self.of_pixel(pixel),
            seen_emission,
        }
    }

    /// Pixels whose seen emission is integrated exactly.
    pub fn pixels_with_seen_emission(&self) -> usize {
        self.seen.len()
    }

    /// True when the lists were made for `camera`.
    pub fn is_for(&self, camera: &Camera) -> bool {
        self.camera == *camera
    }

    /// The triangles a camera ray of `pixel` may hit, in storage order, or
    /// None when that pixel's rays must test the whole scene.
    #[inline(always)]
    pub fn of_pixel(&self, pixel: u32) -> Option<&[u32]> {
        let start = self.starts[pixel as usize];
        if start & FULL_TEST != 0 {
            return None;
        }
        let end = self.starts[pixel as usize + 1] & START;
        Some(&self.triangles[(start & START) as usize..end as usize])
    }

    /// Mean candidates per pixel, and pixels that test the whole scene.
    pub fn summary(&self) -> (f64, usize) {
        let full = self.starts.iter().filter(|&&s| s & FULL_TEST != 0).count();
        let pixels = (self.starts.len() - 1).max(1);
        (self.triangles.len() as f64 / pixels as f64, full)
    }

    /// Bytes the lists take.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.starts.len() + self.triangles.len()) + 16 * self.seen.len()
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

    /// Thirty quads stacked across the whole frame: every pixel would list
    /// 60 triangles, so the lists are refused before they are allocated.
    #[test]
    fn stacked_full_frame_quads_get_no_lists() {
        let camera = Camera::look_at(Vec3A::ZERO, Vec3A::Z, Vec3A::Y, 40.0, 64, 48, 0.0, 1.0);
        let triangles: Vec<[Vec3A; 3]> = (0..30)
            .flat_map(|i| {
                let z = 2.0 + i as f32;
                let (a, b, c, d) = (
                    Vec3A::new(-10.0, -10.0, z),
                    Vec3A::new(10.0, -10.0, z),
                    Vec3A::new(10.0, 10.0, z),
                    Vec3A::new(-10.0, 10.0, z),
                );
                [[a, b, c], [a, c, d]]
            })
            .collect();
        match PrimaryCandidates::build(&camera, &triangles) {
            Err(NotApplied::Crowded { tests_per_pixel }) => {
                assert!(tests_per_pixel > 30.0, "{tests_per_pixel}")
            }
            other => panic!("{other:?}"),
        }
        // Two of them still get lists: one or two candidates per pixel each.
        let lists = PrimaryCandidates::build(&camera, &triangles[..4]).unwrap();
        let (mean, full) = lists.summary();
        assert!((2.0..2.5).contains(&mean) && full == 0, "{mean} {full}");
        assert_eq!(
            lists.memory_bytes(),
            4 * (64 * 48 + 1) + 4 * lists.triangles.len()
        );
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
        assert!(PrimaryCandidates::build(&camera(0.0), &[in_front, behind]).is_ok());
        assert!(PrimaryCandidates::build(&camera(0.1), &[in_front]).is_err());
        assert!(PrimaryCandidates::build(&camera(0.0), &[in_front, straddling]).is_err());
        // The triangle in front covers the centre pixels; the one behind none.
        let lists = PrimaryCandidates::build(&camera(0.0), &[in_front, behind]).unwrap();
        assert_eq!(lists.of_pixel(4 * 8 + 4), Some(&[0u32][..]));
        assert_eq!(lists.of_pixel(0), Some(&[][..]));
    }
}
