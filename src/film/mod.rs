//! The progressive film: per-pixel running sums of samples and of their
//! squares, and sample counts, in tiles that passes fill one at a time.
//!
//! Each tile has its own lock, held only while a pass adds that tile's
//! samples, so a snapshot can be taken at any time while passes run and waits
//! at most for one tile. A pixel is the plain mean of its samples, taken
//! inside it (the box) or drawn from the pixel filter; or, where samples
//! are splatted through the filter ([`filtered`]), their weighted mean.

pub mod filtered;
pub mod splats;

use crate::allocation::PixelNoise;
use crate::image::Image;
use crate::math::Rgb;
use std::sync::Mutex;

/// Side of a square tile in pixels.
pub const TILE_SIZE: u32 = 16;

/// The running statistics of one pixel: the mean and the sum of squared
/// deviations of its finite samples, updated one sample at a time (Welford).
/// 28 bytes: in f32, as Mitsuba's film accumulates; Welford's updates keep
/// the variance from the cancellation that sums of squares suffer in f32,
/// and after 10^5 samples the mean's rounding (about 2e-5 relative, a
/// random walk of 6e-8 steps) is far below the noise. Rare events (non-finite
/// and extreme samples) are kept apart, per tile ([`FlaggedPixel`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Mean of the finite samples.
    pub mean: [f32; 3],
    /// Sum of squared deviations from the mean (Welford's M2).
    pub m2: [f32; 3],
    /// Finite samples.
    pub count: u32,
}

/// A pixel that had non-finite or extreme samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FlaggedPixel {
    /// Index of the pixel within its tile.
    pub pixel: u32,
    /// Samples that were NaN or infinite and were left out.
    pub non_finite: u32,
    /// Samples brighter than [`EXTREME_LUMINANCE`] (kept, or clamped).
    pub extreme: u32,
    /// Index of the first non-finite or extreme sample, for replaying it
    /// (`tracelab render --debug-sample`).
    pub first_flagged: u32,
}

/// `first_flagged` of a pixel without non-finite or extreme samples.
pub const NOT_FLAGGED: u32 = u32::MAX;

/// Luminance above which a sample counts as extreme (a firefly candidate):
/// a thousand times a white surface under unit irradiance / pi.
pub const EXTREME_LUMINANCE: f32 = 1000.0;

/// What a sample is, for the film's bookkeeping.
#[inline]
pub fn classify(value: Rgb) -> (bool, bool) {
    let finite = value.is_finite();
    (
        finite,
        finite && crate::math::luminance(value) > EXTREME_LUMINANCE,
    )
}

/// Notes sample `index` of pixel `pixel` (within a tile) in `flags` when it
/// is non-finite or extreme.
#[cold]
pub fn note_flagged(flags: &mut Vec<FlaggedPixel>, pixel: u32, index: u32, finite: bool) {
    let entry = match flags.iter().position(|f| f.pixel == pixel) {
        Some(i) => &mut flags[i],
        None => {
            flags.push(FlaggedPixel {
                pixel,
                non_finite: 0,
                extreme: 0,
                first_flagged: index,
            });
            flags.last_mut().expect("just pushed")
        }
    };
    if finite {
        entry.extreme += 1;
    } else {
        entry.non_finite += 1;
    }
}

/// Non-finite samples of `pixel` (within a tile) in `flags`.
#[inline]
pub fn non_finite_of(flags: &[FlaggedPixel], pixel: u32) -> u32 {
    flags
        .iter()
        .find(|f| f.pixel == pixel)
        .map_or(0, |f| f.non_finite)
}

impl PixelSums {
    /// Adds one finite sample.
    #[inline]
    pub fn add(&mut self, value: Rgb) {
        self.count += 1;
        let inverse = 1.0 / self.count as f32;
        for c in 0..3 {
            let v = value[c];
            let delta = v - self.mean[c];
            self.mean[c] += delta * inverse;
            self.m2[c] += delta * (v - self.mean[c]);
        }
    }

    /// Adds `n` samples that all have the value `value` (a pass estimate of
    /// light tracing counted as the `n` samples it was made of): Chan et
    /// al.'s merge of two groups, the second of variance zero.
    pub fn add_repeated(&mut self, value: [f64; 3], n: u32) {
        if n == 0 {
            return;
        }
        let (old, added) = (f64::from(self.count), f64::from(n));
        let total = old + added;
        for c in 0..3 {
            let delta = value[c] - f64::from(self.mean[c]);
            self.mean[c] = (f64::from(self.mean[c]) + delta * added / total) as f32;
            self.m2[c] = (f64::from(self.m2[c]) + delta * delta * old * added / total) as f32;
        }
        self.count += n;
    }

    /// Unbiased per-sample variance, mean over the channels (0 with fewer
    /// than two samples).
    pub fn variance(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let n = f64::from(self.count);
        self.m2
            .iter()
            .map(|&m| f64::from(m).max(0.0) / (n - 1.0))
            .sum::<f64>()
            / 3.0
    }

    /// Mean of the samples (zero without samples).
    pub fn mean(&self) -> [f32; 3] {
        self.mean
    }

    /// Standard error of the luminance mean over the luminance mean (infinite
    /// with fewer than two samples or a black pixel): the adaptive-sampling test.
    pub fn relative_standard_error(&self) -> f32 {
        let weights = [0.2126f64, 0.7152, 0.0722];
        if self.count < 2 {
            return f32::INFINITY;
        }
        let n = f64::from(self.count);
        let mut mean = 0.0;
        let mut sigma = 0.0;
        for c in 0..3 {
            mean += weights[c] * f64::from(self.mean[c]);
            // The channels' covariances are unknown: bound the luminance's
            // standard deviation by Cauchy-Schwarz, sum of w_c sigma_c.
            sigma += weights[c] * (f64::from(self.m2[c]).max(0.0) / (n - 1.0)).sqrt();
        }
        if mean <= 0.0 {
            return f32::INFINITY;
        }
        (sigma / n.sqrt() / mean) as f32
    }

    /// Standard error of the mean from the unbiased sample variance
    /// s^2 = M2 / (n - 1); infinite with fewer than two samples.
    pub fn standard_error(&self) -> [f32; 3] {
        if self.count < 2 {
            return [f32::INFINITY; 3];
        }
        let n = f64::from(self.count);
        self.m2
            .map(|m| ((f64::from(m).max(0.0) / (n - 1.0)) / n).sqrt() as f32)
    }
}

/// A rectangle of the film with its sums, in row-major order.
#[derive(Debug)]
pub struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<PixelSums>,
    /// The tile's pixels that had non-finite or extreme samples (few).
    pub flags: Vec<FlaggedPixel>,
    /// The weights each pixel received where samples are splatted through
    /// the filter ([`filtered`]); empty where each sample counts once for
    /// its own pixel.
    pub weights: Vec<filtered::WeightSums>,
}

/// The whole film.
#[derive(Debug)]
pub struct Film {
    width: u32,
    height: u32,
    tiles: Vec<Mutex<Tile>>,
}

/// What a finished render leaves ([`Film::into_final`]).
#[derive(Clone, Debug)]
pub struct FinalImage {
    /// Per-pixel mean radiance.
    pub image: Image,
    /// Pixels with non-finite or extreme samples, `pixel` being the index in
    /// the image, in raster order.
    pub flagged: Vec<FlaggedPixel>,
}

/// A consistent-enough copy of the film for display and export.
#[derive(Clone, Debug)]
pub struct FilmSnapshot {
    /// Per-pixel mean radiance.
    pub image: Image,
    /// Per-pixel standard error of the mean.
    pub standard_error: Image,
    /// Per-pixel sample counts.
    pub samples: Vec<u32>,
    /// Per-pixel counts of non-finite samples left out.
    pub non_finite_pixels: Vec<u32>,
    /// Per-pixel counts of extreme samples.
    pub extreme_pixels: Vec<u32>,
    /// Per-pixel index of the first non-finite or extreme sample ([`NOT_FLAGGED`]).
    pub first_flagged: Vec<u32>,
    /// Total non-finite samples left out.
    pub non_finite: u64,
    /// How many pixels' worth of samples a pixel averages, per sample it
    /// took: 1 where each sample counts for its own pixel, about
    /// (∫f)² / ∫f² where samples are splatted through a filter f (the mean
    /// over pixels of W² / (W₂ n)). A mean over many pixels then has about
    /// this many times the variance that its pixels' standard errors,
    /// summed as independent, say: each sample still counts once in it.
    pub correlation: f64,
}

impl FilmSnapshot {
    /// The RMSE the film expects against the truth: sqrt of the mean over
    /// pixels and channels of the squared standard error. Each s^2 / n is
    /// an unbiased estimate of its pixel's squared error, so the mean is
    /// unbiased at any sample count (a mean of per-pixel *relative* errors
    /// is not: ratios and square roots of few samples are biased low). It
    /// assumes independent samples, so it overstates the error of
    /// stratified and Sobol sampling. NaN while no pixel has two samples.
    pub fn estimated_rmse(&self) -> f64 {
        let mut sum = 0.0f64;
        let mut n = 0usize;
        for se in &self.standard_error.pixels {
            for &v in se {
                if v.is_finite() {
                    sum += f64::from(v) * f64::from(v);
                    n += 1;
                }
            }
        }
        if n == 0 {
            f64::NAN
        } else {
            (sum / n as f64).sqrt()
        }
    }
}

impl Film {
    /// An empty film of `width` x `height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        let mut tiles = Vec::new();
        for y0 in (0..height).step_by(TILE_SIZE as usize) {
            for x0 in (0..width).step_by(TILE_SIZE as usize) {
                let (w, h) = (TILE_SIZE.min(width - x0), TILE_SIZE.min(height - y0));
                tiles.push(Mutex::new(Tile {
                    x0,
                    y0,
                    width: w,
                    height: h,
                    pixels: vec![PixelSums::default(); (w * h) as usize],
                    flags: Vec::new(),
                    weights: Vec::new(),
                }));
            }
        }
        Film {
            width,
            height,
            tiles,
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Empties every pixel (a solver's new image replaces the old one).
    pub fn clear(&self) {
        for tile in &self.tiles {
            let mut tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            tile.pixels.fill(PixelSums::default());
            tile.flags.clear();
            tile.weights = Vec::new();
        }
    }

    /// Tiles in a row of the film ([`Film::tiles`] is rows of them).
    pub fn tiles_across(&self) -> u32 {
        self.width.div_ceil(TILE_SIZE)
    }

    /// The tiles, for passes to fill in parallel.
    pub fn tiles(&self) -> &[Mutex<Tile>] {
        &self.tiles
    }

    /// Samples taken and per-sample variance of every pixel, row-major: what
    /// [`crate::allocation::plan`] needs.
    pub fn noise(&self) -> Vec<PixelNoise> {
        let mut out = vec![PixelNoise::default(); (self.width * self.height) as usize];
        for tile in &self.tiles {
            let tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            for (i, p) in tile.pixels.iter().enumerate() {
                let (tx, ty) = (i as u32 % tile.width, i as u32 / tile.width);
                out[((tile.y0 + ty) * self.width + tile.x0 + tx) as usize] = PixelNoise {
                    taken: p.count + non_finite_of(&tile.flags, i as u32),
                    variance: p.variance(),
                };
            }
        }
        out
    }

    /// The fewest and the most samples any pixel has.
    pub fn sample_count_range(&self) -> (u32, u32) {
        let mut range = (u32::MAX, 0);
        for tile in &self.tiles {
            let tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            for p in &tile.pixels {
                range = (range.0.min(p.count), range.1.max(p.count));
            }
        }
        if range.0 > range.1 { (0, 0) } else { range }
    }

    /// The means as an image, and the flagged pixels (by image index) in
    /// raster order, taking the film apart tile by tile: for the end of a
    /// render, where a full snapshot (40 bytes per pixel) would be more than
    /// the film itself.
    pub fn into_final(self) -> FinalImage {
        let mut image = Image::new(self.width, self.height);
        let mut flagged = Vec::new();
        for tile in self.tiles {
            let tile = tile.into_inner().unwrap_or_else(|e| e.into_inner());
            for (i, p) in tile.pixels.iter().enumerate() {
                let (tx, ty) = (i as u32 % tile.width, i as u32 / tile.width);
                image.pixels[((tile.y0 + ty) * self.width + tile.x0 + tx) as usize] = p.mean();
            }
            for f in &tile.flags {
                let (tx, ty) = (f.pixel % tile.width, f.pixel / tile.width);
                flagged.push(FlaggedPixel {
                    pixel: (tile.y0 + ty) * self.width + tile.x0 + tx,
                    ..*f
                });
            }
        }
        flagged.sort_by_key(|f| f.pixel);
        FinalImage { image, flagged }
    }

    /// Copies the current means, standard errors and counts.
    pub fn snapshot(&self) -> FilmSnapshot {
        let n = (self.width * self.height) as usize;
        let mut image = Image::new(self.width, self.height);
        let mut standard_error = Image::new(self.width, self.height);
        let mut samples = vec![0u32; n];
        let mut non_finite_pixels = vec![0u32; n];
        let mut extreme_pixels = vec![0u32; n];
        let mut first_flagged = vec![NOT_FLAGGED; n];
        let mut non_finite = 0u64;
        let (mut correlation, mut weighted_pixels) = (0.0f64, 0u64);
        for tile in &self.tiles {
            // A poisoned lock only means a pass panicked; the sums are still valid.
            let tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            for ty in 0..tile.height {
                for tx in 0..tile.width {
                    let p = &tile.pixels[(ty * tile.width + tx) as usize];
                    let i = ((tile.y0 + ty) * self.width + tile.x0 + tx) as usize;
                    image.pixels[i] = p.mean();
                    standard_error.pixels[i] =
                        match tile.weights.get((ty * tile.width + tx) as usize) {
                            Some(w) => filtered::standard_error(p, w),
                            None => p.standard_error(),
                        };
                    samples[i] = p.count;
                }
            }
            for (p, w) in tile.pixels.iter().zip(&tile.weights) {
                if w.sum_sq > 0.0 && p.count > 0 {
                    let (sum, sum_sq) = (f64::from(w.sum), f64::from(w.sum_sq));
                    correlation += sum * sum / (sum_sq * f64::from(p.count));
                    weighted_pixels += 1;
                }
            }
            for f in &tile.flags {
                let (tx, ty) = (f.pixel % tile.width, f.pixel / tile.width);
                let i = ((tile.y0 + ty) * self.width + tile.x0 + tx) as usize;
                non_finite_pixels[i] = f.non_finite;
                extreme_pixels[i] = f.extreme;
                first_flagged[i] = f.first_flagged;
                non_finite += u64::from(f.non_finite);
            }
        }
        FilmSnapshot {
            image,
            standard_error,
            samples,
            non_finite_pixels,
            extreme_pixels,
            first_flagged,
            non_finite,
            correlation: match weighted_pixels {
                0 => 1.0,
                n => (correlation / n as f64).max(1.0),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_standard_error_match_the_textbook() {
        let mut p = PixelSums::default();
        for v in [1.0, 2.0, 3.0, 4.0] {
            p.add(Rgb::splat(v));
        }
        assert_eq!(p.count, 4);
        assert_eq!(p.mean(), [2.5; 3]);
        // s^2 = 5/3, se = sqrt(5/3 / 4).
        let se = (5.0f64 / 3.0 / 4.0).sqrt() as f32;
        assert!((p.standard_error()[0] - se).abs() < 1e-6);
    }

    #[test]
    fn welford_agrees_with_two_pass_statistics() {
        // 10^5 samples of mean 0.5 and a wide spread: the f32 running mean
        // and M2 against f64 two-pass sums.
        let values: Vec<f32> = (0..100_000u64)
            .map(|i| {
                crate::sampling::hash::to_unit_float(crate::sampling::hash::hash_combine(9, i))
                    * 3.0
                    - 1.0
            })
            .collect();
        let mut p = PixelSums::default();
        for &v in &values {
            p.add(Rgb::splat(v));
        }
        let n = values.len() as f64;
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let variance = values
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        assert!(
            (f64::from(p.mean()[0]) - mean).abs() < 1e-5,
            "{} vs {mean}",
            p.mean()[0]
        );
        assert!(
            (p.variance() / variance - 1.0).abs() < 1e-4,
            "{} vs {variance}",
            p.variance()
        );
    }

    #[test]
    fn repeated_samples_merge_like_single_ones() {
        let (mut one_by_one, mut merged) = (PixelSums::default(), PixelSums::default());
        for v in [0.25f32, 2.0] {
            for _ in 0..3 {
                one_by_one.add(Rgb::splat(v));
            }
            merged.add_repeated([f64::from(v); 3], 3);
        }
        assert_eq!(merged.count, 6);
        assert!((merged.mean()[0] - one_by_one.mean()[0]).abs() < 1e-6);
        assert!((merged.variance() - one_by_one.variance()).abs() < 1e-6);
    }

    #[test]
    fn flags_are_kept_per_pixel() {
        let mut flags = Vec::new();
        note_flagged(&mut flags, 3, 7, false);
        note_flagged(&mut flags, 3, 9, true);
        note_flagged(&mut flags, 5, 2, true);
        assert_eq!(non_finite_of(&flags, 3), 1);
        assert_eq!(flags[0].first_flagged, 7);
        assert_eq!(flags[0].extreme, 1);
        assert_eq!(non_finite_of(&flags, 4), 0);
    }

    #[test]
    fn tiles_cover_odd_sizes_exactly() {
        let film = Film::new(37, 20);
        let area: u32 = film
            .tiles()
            .iter()
            .map(|t| {
                let t = t.lock().unwrap();
                t.width * t.height
            })
            .sum();
        assert_eq!(area, 37 * 20);
        assert_eq!(film.snapshot().samples.len(), 37 * 20);
    }
}
