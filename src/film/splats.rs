//! The splat buffer of splatting estimators: per-pixel sums whose value does
//! not depend on the order in which threads add to them.

use crate::filter::PixelFilter;
use crate::math::Rgb;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Per-pixel sums of light-tracing splats in 32.32 fixed point: integer
/// additions commute, so the sums are the same in any thread order.
pub(crate) struct SplatBuffer {
    width: u32,
    height: u32,
    filter: PixelFilter,
    sums: Vec<[AtomicU64; 3]>,
}

/// 2^32: resolution 2.3e-10 per splat, overflow past 4e9 per pixel and pass.
const SPLAT_SCALE: f64 = 4294967296.0;

impl SplatBuffer {
    #[cfg(test)]
    pub(crate) fn new(width: u32, height: u32) -> Self {
        Self::with_filter(width, height, PixelFilter::Box)
    }

    /// A buffer whose splats spread over the pixels `filter` covers.
    pub(crate) fn with_filter(width: u32, height: u32, filter: PixelFilter) -> Self {
        // Filled in parallel: a pass makes one before any thread can start.
        let sums = (0..width as usize * height as usize)
            .into_par_iter()
            .map(|_| [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)])
            .collect();
        SplatBuffer {
            width,
            height,
            filter,
            sums,
        }
    }

    /// Asks for the cache line of the pixel containing `film`: splats land
    /// anywhere on the film, and an atomic add that misses the cache waits
    /// for the line with nothing else in flight (13% of BDPT's time on
    /// SmallVCM's scene, 512 x 512).
    /// A filtered splat's pixels are asked for too: a row's first and last
    /// (a tent's 2 x 2 pixels span two rows and up to four lines).
    #[inline]
    fn prefetch(&self, film: Vec2, filtered: bool) {
        let r = if filtered { self.filter.radius() } else { 0.0 };
        if r == 0.0 || self.filter == PixelFilter::Box {
            let (x, y) = (film.x as u32, film.y as u32);
            if x < self.width && y < self.height {
                crate::math::prefetch(&self.sums[(y * self.width + x) as usize]);
            }
            return;
        }
        let x0 = (film.x - r - 0.5).ceil().max(0.0) as u32;
        let x1 = ((film.x + r - 0.5).floor().min(self.width as f32 - 1.0)).max(0.0) as u32;
        let y0 = (film.y - r - 0.5).ceil().max(0.0) as u32;
        let y1 = ((film.y + r - 0.5).floor().min(self.height as f32 - 1.0)).max(0.0) as u32;
        for y in y0..=y1.min(y0 + 3) {
            if y < self.height && x0 <= x1 {
                let row = (y * self.width) as usize;
                crate::math::prefetch(&self.sums[row + x0 as usize]);
                crate::math::prefetch(&self.sums[row + x1 as usize]);
            }
        }
    }

    /// Adds `value` to the pixel containing `film`; false (and nothing added)
    /// when the value is not finite, negative or too large to represent.
    pub(crate) fn add(&self, film: Vec2, value: Rgb) -> bool {
        if self.filter == PixelFilter::Box {
            return self.add_to_pixel(film, value);
        }
        // Every pixel whose filter reaches `film`, weighted by it.
        let r = self.filter.radius();
        let (x0, x1) = ((film.x - r - 0.5).ceil(), (film.x + r - 0.5).floor());
        let (y0, y1) = ((film.y - r - 0.5).ceil(), (film.y + r - 0.5).floor());
        let mut ok = true;
        let mut y = y0.max(0.0);
        while y <= y1.min(self.height as f32 - 1.0) {
            let mut x = x0.max(0.0);
            while x <= x1.min(self.width as f32 - 1.0) {
                let weight = self.filter.eval(film - Vec2::new(x + 0.5, y + 0.5));
                if weight > 0.0 {
                    ok &= self.add_to_pixel(Vec2::new(x + 0.5, y + 0.5), value * weight);
                }
                x += 1.0;
            }
            y += 1.0;
        }
        ok
    }

    /// Adds `value` to the pixel containing `film`; false as [`SplatBuffer::add`].
    pub(crate) fn add_to_pixel(&self, film: Vec2, value: Rgb) -> bool {
        let (x, y) = (film.x as u32, film.y as u32);
        if x >= self.width || y >= self.height {
            return true;
        }
        let mut fixed = [0u64; 3];
        for c in 0..3 {
            let v = f64::from(value[c]) * SPLAT_SCALE;
            if !(v >= 0.0 && v < 9.0e18) {
                return false;
            }
            fixed[c] = v.round() as u64;
        }
        if fixed == [0; 3] {
            return true;
        }
        let sums = &self.sums[(y * self.width + x) as usize];
        for c in 0..3 {
            sums[c].fetch_add(fixed[c], Ordering::Relaxed);
        }
        true
    }

    pub(crate) fn get(&self, index: u32) -> [f64; 3] {
        let sums = &self.sums[index as usize];
        [0, 1, 2].map(|c| sums[c].load(Ordering::Relaxed) as f64 / SPLAT_SCALE)
    }
}

/// A sample's splats held back until the sample is traced: each one's cache
/// line is fetched when it is made, and added once the rest of the sample's
/// work has hidden the fetch.
pub(crate) struct PendingSplats {
    /// Film position, value, and whether it goes through the filter.
    splats: [(Vec2, Rgb, bool); PENDING],
    len: usize,
    /// Splats that were not finite, negative or too large (not added).
    pub(crate) rejected: u64,
}

const PENDING: usize = 64;

impl PendingSplats {
    pub(crate) fn new() -> Self {
        PendingSplats {
            splats: [(Vec2::ZERO, Rgb::ZERO, true); PENDING],
            len: 0,
            rejected: 0,
        }
    }

    /// Holds a splat spread by the pixel filter ([`SplatBuffer::add`]), or
    /// with `filtered` false added to the pixel containing `film` alone.
    #[inline]
    pub(crate) fn push(&mut self, buffer: &SplatBuffer, film: Vec2, value: Rgb, filtered: bool) {
        if self.len == PENDING {
            self.flush(buffer);
        }
        buffer.prefetch(film, filtered);
        self.splats[self.len] = (film, value, filtered);
        self.len += 1;
    }

    pub(crate) fn flush(&mut self, buffer: &SplatBuffer) {
        for &(film, value, filtered) in &self.splats[..self.len] {
            let added = match filtered {
                true => buffer.add(film, value),
                false => buffer.add_to_pixel(film, value),
            };
            if !added {
                self.rejected += 1;
            }
        }
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A filtered splat's prefetch reads only pixels of the film, wherever
    /// the splat lands (edges, outside, not finite) and whatever the filter.
    #[test]
    fn prefetching_a_footprint_stays_on_the_film() {
        let wide = PixelFilter::Gaussian {
            stddev: 2.0,
            radius: 5.0,
        };
        for filter in [
            PixelFilter::Box,
            PixelFilter::tent(),
            PixelFilter::gaussian(),
            wide,
        ] {
            let buffer = SplatBuffer::with_filter(7, 5, filter);
            for (x, y) in [
                (0.0, 0.0),
                (6.99, 4.99),
                (7.0, 5.0),
                (-3.0, 2.0),
                (3.5, 40.0),
                (f32::NAN, 1.0),
                (f32::INFINITY, f32::NEG_INFINITY),
            ] {
                for filtered in [false, true] {
                    buffer.prefetch(Vec2::new(x, y), filtered);
                }
            }
        }
    }

    /// Held-back splats, more than the holder keeps at once, land exactly
    /// where and as direct adds do; rejected ones are counted, not added.
    #[test]
    fn pending_splats_sum_like_direct_adds() {
        let (direct, held) = (SplatBuffer::new(7, 5), SplatBuffer::new(7, 5));
        let mut pending = PendingSplats::new();
        let mut rejected = 0;
        for k in 0..3 * PENDING as u32 + 5 {
            let film = Vec2::new((k * 5 % 9) as f32 + 0.5, (k * 3 % 6) as f32 + 0.5);
            let value = if k % 17 == 3 {
                Rgb::splat(f32::NAN)
            } else {
                Rgb::new(0.25 * k as f32, 1.0, 1e-3)
            };
            if !direct.add(film, value) {
                rejected += 1;
            }
            pending.push(&held, film, value, true);
        }
        pending.flush(&held);
        assert_eq!(pending.rejected, rejected);
        assert!(rejected > 0);
        for index in 0..7 * 5 {
            assert_eq!(direct.get(index), held.get(index), "pixel {index}");
        }
    }
}
