//! The splat buffer of splatting estimators: per-pixel sums whose value does
//! not depend on the order in which threads add to them.

use crate::film::filtered::MAX_SIDE;
use crate::filter::PixelFilter;
use crate::math::Rgb;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Per-pixel sums of light-tracing splats in 32.32 fixed point: integer
/// additions commute, so the sums are the same in any thread order.
///
/// Each render thread adds to a copy of the film of its own (a shard) where
/// memory allows: splats land anywhere, and two threads writing one shared
/// film pass its cache lines back and forth (half of the splats' time, 5%
/// of BDPT's, on two threads). A thread alone on its shard adds by a plain
/// load and store; threads that share one (past [`SHARD_BUDGET`]) add
/// atomically, and so do threads outside the pool, to a film of their own
/// made when one first adds. Reading a pixel sums its shards.
pub(crate) struct SplatBuffer {
    width: u32,
    height: u32,
    filter: PixelFilter,
    /// `shards` films one after the other.
    sums: Vec<[AtomicU64; 3]>,
    shards: usize,
    /// Whether pool thread i (below `shards`) is the only one to write
    /// shard i: the pool has no more threads than shards.
    exclusive: bool,
    /// The film of threads outside the pool (none in a render's pass).
    outside: std::sync::OnceLock<Vec<[AtomicU64; 3]>>,
}

/// 2^32: resolution 2.3e-10 per splat, overflow past 4e9 per pixel and pass.
const SPLAT_SCALE: f64 = 4294967296.0;

/// The most bytes of shards past the first: a 512 x 512 film gets one per
/// thread up to 11 threads, a 1920 x 1080 film two (the rest share). Every
/// pass makes and fills its shards anew, so at many threads a larger budget
/// would cost each pass page faults and writes of hundreds of megabytes.
pub(crate) const SHARD_BUDGET: u64 = 64 << 20;

/// Bytes of one shard per pixel.
pub(crate) const SPLAT_BYTES: u64 = 24;

/// How many shards a film of `pixels` gets among `threads` threads.
pub(crate) fn shard_count(pixels: u64, threads: usize) -> usize {
    let extra = SHARD_BUDGET / (pixels * SPLAT_BYTES).max(1);
    (threads.max(1) as u64).min(1 + extra) as usize
}

impl SplatBuffer {
    #[cfg(test)]
    pub(crate) fn new(width: u32, height: u32) -> Self {
        Self::with_filter(width, height, PixelFilter::Box)
    }

    /// A buffer whose splats spread over the pixels `filter` covers, with a
    /// shard per thread of the pool it is made in, as memory allows: it is
    /// to be filled from that pool's threads (others add atomically, to a
    /// film of their own).
    pub(crate) fn with_filter(width: u32, height: u32, filter: PixelFilter) -> Self {
        let pixels = u64::from(width) * u64::from(height);
        let shards = shard_count(pixels, rayon::current_num_threads());
        Self::with_shards(width, height, filter, shards)
    }

    fn with_shards(width: u32, height: u32, filter: PixelFilter, shards: usize) -> Self {
        let pixels = width as usize * height as usize;
        let threads = rayon::current_num_threads();
        SplatBuffer {
            width,
            height,
            filter,
            sums: zeroed(shards * pixels),
            shards,
            exclusive: threads <= shards,
            outside: std::sync::OnceLock::new(),
        }
    }

    /// The calling thread's shard, and whether the thread is its only
    /// writer.
    #[inline]
    fn shard(&self) -> (&[[AtomicU64; 3]], bool) {
        let pixels = (self.width * self.height) as usize;
        match rayon::current_thread_index() {
            Some(i) => {
                let first = i % self.shards * pixels;
                (&self.sums[first..first + pixels], self.exclusive)
            }
            None => (self.outside.get_or_init(|| zeroed(pixels)), false),
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
        let sums = self.shard().0;
        let r = if filtered { self.filter.radius() } else { 0.0 };
        if r == 0.0 || self.filter == PixelFilter::Box {
            let (x, y) = (film.x as u32, film.y as u32);
            if x < self.width && y < self.height {
                crate::math::prefetch(&sums[(y * self.width + x) as usize]);
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
                crate::math::prefetch(&sums[row + x0 as usize]);
                crate::math::prefetch(&sums[row + x1 as usize]);
            }
        }
    }

    /// Adds `value` to the pixel containing `film`; false (and nothing added)
    /// when the value is not finite, negative or too large to represent.
    pub(crate) fn add(&self, film: Vec2, value: Rgb) -> bool {
        let shard = self.shard();
        if self.filter == PixelFilter::Box {
            return self.add_in(shard, film, value);
        }
        // Every pixel whose filter reaches `film`, weighted by it: the
        // filter is a product of 1D ones, so a column's weight is computed
        // once (a Gaussian's are an erf and an exponential each).
        let r = self.filter.radius();
        // The footprint's first pixel and count along an axis of `size` pixels.
        let span = |f: f32, size: u32| {
            let first = (f - r - 0.5).ceil().max(0.0);
            let last = (f + r - 0.5).floor().min(size as f32 - 1.0);
            (first, (last - first + 1.0).max(0.0) as usize)
        };
        let ((x0, columns), (y0, rows)) = (span(film.x, self.width), span(film.y, self.height));
        let filter = self.filter.one_dimensional();
        let mut column_weights = [0.0f32; MAX_SIDE];
        let stored = columns <= MAX_SIDE;
        if stored {
            for (i, w) in column_weights.iter_mut().enumerate().take(columns) {
                *w = filter.eval(film.x - (x0 + i as f32 + 0.5));
            }
        }
        let mut ok = true;
        for j in 0..rows {
            let y = y0 + j as f32;
            let row_weight = filter.eval(film.y - (y + 0.5));
            if !(row_weight > 0.0) {
                continue;
            }
            for i in 0..columns {
                let x = x0 + i as f32;
                let column_weight = match stored {
                    true => column_weights[i],
                    false => filter.eval(film.x - (x + 0.5)),
                };
                let weight = column_weight * row_weight;
                if weight > 0.0 {
                    ok &= self.add_in(shard, Vec2::new(x + 0.5, y + 0.5), value * weight);
                }
            }
        }
        ok
    }

    /// Adds `value` to the pixel containing `film`; false as [`SplatBuffer::add`].
    pub(crate) fn add_to_pixel(&self, film: Vec2, value: Rgb) -> bool {
        self.add_in(self.shard(), film, value)
    }

    /// [`SplatBuffer::add_to_pixel`] in the shard [`SplatBuffer::shard`] chose.
    #[inline]
    fn add_in(&self, (shard, alone): (&[[AtomicU64; 3]], bool), film: Vec2, value: Rgb) -> bool {
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
        let sums = &shard[(y * self.width + x) as usize];
        for c in 0..3 {
            if alone {
                // No other thread writes this shard: no lock needed.
                let sum = sums[c].load(Ordering::Relaxed);
                sums[c].store(sum.wrapping_add(fixed[c]), Ordering::Relaxed);
            } else {
                sums[c].fetch_add(fixed[c], Ordering::Relaxed);
            }
        }
        true
    }

    /// The sums of pixel `index` over every shard.
    pub(crate) fn get(&self, index: u32) -> [f64; 3] {
        let pixels = (self.width * self.height) as usize;
        let mut total = [0u64; 3];
        let shards = (0..self.shards).map(|shard| &self.sums[shard * pixels + index as usize]);
        for sums in shards.chain(self.outside.get().map(|film| &film[index as usize])) {
            for c in 0..3 {
                total[c] = total[c].wrapping_add(sums[c].load(Ordering::Relaxed));
            }
        }
        total.map(|t| t as f64 / SPLAT_SCALE)
    }
}

/// `count` pixels' sums at zero, filled in parallel: a pass makes its
/// buffer before any thread can start.
fn zeroed(count: usize) -> Vec<[AtomicU64; 3]> {
    (0..count)
        .into_par_iter()
        .map(|_| [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)])
        .collect()
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

    /// Splats added from many threads, each on a shard of its own or
    /// sharing one, sum exactly as one thread's adds to one buffer.
    #[test]
    fn shards_sum_like_one_thread() {
        let splat = |k: u32| {
            let film = Vec2::new((k * 7 % 23) as f32 * 0.37, (k * 5 % 11) as f32 * 0.41);
            (
                film,
                Rgb::new(0.1 * (k % 13) as f32, 1.0 / (1 + k) as f32, 3.0),
            )
        };
        let single = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let expected = single.install(|| {
            let buffer = SplatBuffer::with_filter(9, 5, PixelFilter::tent());
            assert_eq!(buffer.shards, 1);
            for k in 0..5000 {
                let (film, value) = splat(k);
                assert!(buffer.add(film, value));
            }
            (0..45).map(|i| buffer.get(i)).collect::<Vec<_>>()
        });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        for shards in [4, 2, 1] {
            let sums = pool.install(|| {
                let buffer = SplatBuffer::with_shards(9, 5, PixelFilter::tent(), shards);
                assert_eq!(buffer.exclusive, shards == 4);
                (0..5000u32).into_par_iter().with_max_len(7).for_each(|k| {
                    let (film, value) = splat(k);
                    assert!(buffer.add(film, value));
                });
                // A thread outside the pool adds to a film of its own.
                let (film, value) = splat(5000);
                std::thread::scope(|s| {
                    s.spawn(|| assert!(buffer.add(film, value)));
                });
                (0..45).map(|i| buffer.get(i)).collect::<Vec<_>>()
            });
            let extra = single.install(|| {
                let buffer = SplatBuffer::with_filter(9, 5, PixelFilter::tent());
                buffer.add(splat(5000).0, splat(5000).1);
                (0..45).map(|i| buffer.get(i)).collect::<Vec<_>>()
            });
            for i in 0..45 {
                let want: [f64; 3] = std::array::from_fn(|c| expected[i][c] + extra[i][c]);
                for c in 0..3 {
                    // Fixed point: the sums are exact, up to the one rounding
                    // of adding two f64 read-backs here.
                    assert!(
                        (sums[i][c] - want[c]).abs() <= 1e-9 * want[c].max(1.0),
                        "{shards} shards, pixel {i}"
                    );
                }
            }
        }
        assert_eq!(shard_count(1 << 20, 64), 3);
        assert_eq!(shard_count(512 * 512, 64), 11);
        assert_eq!(shard_count(100, 64), 64);
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
