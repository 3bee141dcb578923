//! The progressive film: per-pixel running sums of samples and of their
//! squares, and sample counts, in tiles that passes fill one at a time.
//!
//! Each tile has its own lock, held only while a pass adds that tile's
//! samples, so a snapshot can be taken at any time while passes run and waits
//! at most for one tile. The reconstruction filter is a box of one pixel:
//! a pixel is the plain mean of the samples taken inside it (Mitsuba's `box`).

use crate::allocation::PixelNoise;
use crate::image::Image;
use crate::math::Rgb;
use std::sync::Mutex;

/// Side of a square tile in pixels.
pub const TILE_SIZE: u32 = 16;

/// Running sums of one pixel. f64 keeps long renders (10^5 spp) exact enough
/// for the variance estimate.
#[derive(Clone, Copy, Debug)]
pub struct PixelSums {
    pub sum: [f64; 3],
    pub sum_sq: [f64; 3],
    pub count: u32,
    /// Samples that were NaN or infinite and were left out.
    pub non_finite: u32,
    /// Samples brighter than [`EXTREME_LUMINANCE`] (kept, or clamped).
    pub extreme: u32,
    /// Index of the first non-finite or extreme sample, for replaying it
    /// (`tracelab render --debug-sample`); [`NOT_FLAGGED`] if none.
    pub first_flagged: u32,
}

/// `first_flagged` of a pixel without non-finite or extreme samples.
pub const NOT_FLAGGED: u32 = u32::MAX;

/// Luminance above which a sample counts as extreme (a firefly candidate):
/// a thousand times a white surface under unit irradiance / pi.
pub const EXTREME_LUMINANCE: f32 = 1000.0;

impl Default for PixelSums {
    fn default() -> Self {
        PixelSums {
            sum: [0.0; 3],
            sum_sq: [0.0; 3],
            count: 0,
            non_finite: 0,
            extreme: 0,
            first_flagged: NOT_FLAGGED,
        }
    }
}

impl PixelSums {
    /// Notes sample `index` as non-finite or extreme when it is; returns
    /// true when it is extreme (finite but brighter than [`EXTREME_LUMINANCE`]).
    #[inline]
    pub fn flag(&mut self, value: Rgb, index: u32) -> bool {
        let non_finite = !value.is_finite();
        let extreme = !non_finite && crate::math::luminance(value) > EXTREME_LUMINANCE;
        if (non_finite || extreme) && self.first_flagged == NOT_FLAGGED {
            self.first_flagged = index;
        }
        self.extreme += u32::from(extreme);
        extreme
    }

    /// Adds one sample, or counts it as non-finite and leaves it out.
    #[inline]
    pub fn add(&mut self, value: Rgb) {
        if !value.is_finite() {
            self.non_finite += 1;
            return;
        }
        for c in 0..3 {
            let v = value[c] as f64;
            self.sum[c] += v;
            self.sum_sq[c] += v * v;
        }
        self.count += 1;
    }

    /// Adds `n` samples that all have the value `value` (a pass estimate of
    /// light tracing counted as the `n` samples it was made of).
    pub fn add_repeated(&mut self, value: [f64; 3], n: u32) {
        let weight = f64::from(n);
        for c in 0..3 {
            self.sum[c] += value[c] * weight;
            self.sum_sq[c] += value[c] * value[c] * weight;
        }
        self.count += n;
    }

    /// Samples taken, finite or not: the index of the pixel's next sample.
    #[inline]
    pub fn taken(&self) -> u32 {
        self.count + self.non_finite
    }

    /// Unbiased per-sample variance, mean over the channels (0 with fewer
    /// than two samples).
    pub fn variance(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let n = f64::from(self.count);
        (0..3)
            .map(|c| ((self.sum_sq[c] - self.sum[c] * self.sum[c] / n) / (n - 1.0)).max(0.0))
            .sum::<f64>()
            / 3.0
    }

    /// Mean of the samples (zero without samples).
    pub fn mean(&self) -> [f32; 3] {
        if self.count == 0 {
            return [0.0; 3];
        }
        let n = self.count as f64;
        [
            (self.sum[0] / n) as f32,
            (self.sum[1] / n) as f32,
            (self.sum[2] / n) as f32,
        ]
    }

    /// Standard error of the luminance mean over the luminance mean (infinite
    /// with fewer than two samples or a black pixel): the adaptive-sampling test.
    pub fn relative_standard_error(&self) -> f32 {
        let weights = [0.2126, 0.7152, 0.0722];
        if self.count < 2 {
            return f32::INFINITY;
        }
        let n = self.count as f64;
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for c in 0..3 {
            for d in 0..3 {
                // Luminance sums from channel sums; the cross terms of the
                // square are unknown, so bound them with Cauchy-Schwarz.
                sum_sq += weights[c] * weights[d] * (self.sum_sq[c] * self.sum_sq[d]).sqrt();
            }
            sum += weights[c] * self.sum[c];
        }
        let mean = sum / n;
        if mean <= 0.0 {
            return f32::INFINITY;
        }
        let variance = ((sum_sq - sum * sum / n) / (n - 1.0)).max(0.0);
        ((variance / n).sqrt() / mean) as f32
    }

    /// Standard error of the mean from the unbiased sample variance
    /// s^2 = (sum_sq - sum^2 / n) / (n - 1); infinite with fewer than two samples.
    pub fn standard_error(&self) -> [f32; 3] {
        if self.count < 2 {
            return [f32::INFINITY; 3];
        }
        let n = self.count as f64;
        let mut se = [0.0f32; 3];
        for c in 0..3 {
            let variance = ((self.sum_sq[c] - self.sum[c] * self.sum[c] / n) / (n - 1.0)).max(0.0);
            se[c] = (variance / n).sqrt() as f32;
        }
        se
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
}

/// The whole film.
#[derive(Debug)]
pub struct Film {
    width: u32,
    height: u32,
    tiles: Vec<Mutex<Tile>>,
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
        }
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
                    taken: p.taken(),
                    variance: p.variance(),
                };
            }
        }
        out
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
        for tile in &self.tiles {
            // A poisoned lock only means a pass panicked; the sums are still valid.
            let tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            for ty in 0..tile.height {
                for tx in 0..tile.width {
                    let p = &tile.pixels[(ty * tile.width + tx) as usize];
                    let i = ((tile.y0 + ty) * self.width + tile.x0 + tx) as usize;
                    image.pixels[i] = p.mean();
                    standard_error.pixels[i] = p.standard_error();
                    samples[i] = p.count;
                    non_finite_pixels[i] = p.non_finite;
                    extreme_pixels[i] = p.extreme;
                    first_flagged[i] = p.first_flagged;
                    non_finite += p.non_finite as u64;
                }
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
        p.add(Rgb::new(f32::NAN, 0.0, 0.0));
        p.add(Rgb::splat(f32::INFINITY));
        assert_eq!(p.count, 4);
        assert_eq!(p.non_finite, 2);
        assert_eq!(p.mean(), [2.5; 3]);
        // s^2 = 5/3, se = sqrt(5/3 / 4).
        let se = (5.0f64 / 3.0 / 4.0).sqrt() as f32;
        assert!((p.standard_error()[0] - se).abs() < 1e-6);
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
