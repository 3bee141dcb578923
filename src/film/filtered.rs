//! Camera samples splatted through the pixel filter, as Mitsuba's film
//! does ([`crate::filter::FilterSampling::Splat`]): a sample taken
//! uniformly in its pixel adds to every pixel whose filter covers it,
//! with the filter's weight, and a pixel is the weighted mean of what it
//! received, Σ w L / Σ w. Where the image is smooth a pixel so averages
//! the samples of (∫f)² / ∫f² pixels' area instead of its own (2.25 for
//! the tent, π for Mitsuba's Gaussian), at the price of correlation
//! between neighbours. Dividing by the weights received, not by their
//! expectation, keeps the weights' own noise out of the estimate.
//!
//! A tile's samples land in its own [`Apron`] (the tile and the filter's
//! reach around it), without locks. Once every tile of the pass is done,
//! [`fold`] gives each pixel the cells of the aprons that cover it, summed
//! in tile order, so the film does not depend on the schedule, and merges
//! them into the pixel as one weighted group, which keeps its running mean
//! and its error term exact whatever the grouping (as Chan et al.'s merge
//! does for plain samples). A pixel's standard error is the delta method's
//! for a ratio, Σ w² (L − R)² / W²: it weighs a sample by w², so the
//! far samples of a neighbour, which see a little of another image, count
//! for little in it.

use super::{PixelSums, Tile};
use crate::filter::PixelFilter;
use crate::math::Rgb;
use glam::Vec2;

/// The weights a pixel received: their sum, the sum of their squares, and
/// Σ w² (L − mean) at the current mean, which moves the pixel's
/// `m2` (here Σ w² (L − mean)², the weighted mean's error times W²) along
/// with the mean.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WeightSums {
    pub sum: f32,
    pub sum_sq: f32,
    pub moment: [f32; 3],
}

/// What one pixel received in one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SplatCell {
    /// Σ w L.
    pub sum: [f32; 3],
    /// Σ w² L².
    pub sum_sq: [f32; 3],
    /// Σ w² L.
    pub moment: [f32; 3],
    /// Σ w.
    pub weight: f32,
    /// Σ w².
    pub weight_sq: f32,
}

impl SplatCell {
    /// One sample of value `value` with weight `w`.
    #[inline]
    pub fn sample(value: Rgb, w: f32) -> SplatCell {
        let w2 = w * w;
        SplatCell {
            sum: [0, 1, 2].map(|c| w * value[c]),
            sum_sq: [0, 1, 2].map(|c| w2 * value[c] * value[c]),
            moment: [0, 1, 2].map(|c| w2 * value[c]),
            weight: w,
            weight_sq: w2,
        }
    }

    #[inline]
    pub fn add(&mut self, other: &SplatCell) {
        for c in 0..3 {
            self.sum[c] += other.sum[c];
            self.sum_sq[c] += other.sum_sq[c];
            self.moment[c] += other.moment[c];
        }
        self.weight += other.weight;
        self.weight_sq += other.weight_sq;
    }
}

/// How many pixels beyond its own a sample inside a pixel reaches: pixel
/// centres within the radius of a point of [x, x + 1) lie in
/// [x − ⌊r + ½⌋, x + ⌊r + ½⌋].
pub fn reach(filter: PixelFilter) -> u32 {
    (filter.radius() + 0.5).floor() as u32
}

/// Pixels a sample may reach in a row, at most: filters wider than
/// this (a radius of 7.5 pixels and more) are importance-sampled.
pub const MAX_SIDE: usize = 16;

/// Whether camera samples can be splatted through `filter` (a box is
/// exact and cheaper importance-sampled: each sample counts for its pixel).
pub fn can_splat(filter: PixelFilter) -> bool {
    filter != PixelFilter::Box && (2 * reach(filter) + 1) as usize <= MAX_SIDE
}

/// The splats of one tile's samples in one pass: the tile's pixels and
/// [`reach`] pixels around them.
pub struct Apron {
    /// Film position of the first cell (the tile's corner less the reach).
    x0: i64,
    y0: i64,
    width: u32,
    height: u32,
    filter: PixelFilter,
    /// Pixels a sample can reach in a row: 2 [`reach`] + 1.
    side: usize,
    cells: Vec<SplatCell>,
}

impl Apron {
    /// An empty apron around `tile`.
    pub fn new(tile: &Tile, filter: PixelFilter) -> Apron {
        let r = reach(filter);
        let (width, height) = (tile.width + 2 * r, tile.height + 2 * r);
        Apron {
            x0: i64::from(tile.x0) - i64::from(r),
            y0: i64::from(tile.y0) - i64::from(r),
            width,
            height,
            filter,
            side: (2 * r + 1) as usize,
            cells: vec![SplatCell::default(); (width * height) as usize],
        }
    }

    /// Adds a sample of value `value` at film position `film`, which lies in
    /// one of the tile's pixels, to every pixel its filter covers.
    #[inline]
    pub fn splat(&mut self, film: Vec2, value: Rgb) {
        let r = self.filter.radius();
        let first = |f: f32, origin: i64| ((f - r - 0.5).ceil() as i64 - origin).max(0);
        let (fx, fy) = (first(film.x, self.x0), first(film.y, self.y0));
        let (mut wx, mut wy) = ([0.0f32; MAX_SIDE], [0.0f32; MAX_SIDE]);
        let side = self.side as i64;
        let side_x = (self.width as i64 - fx).clamp(0, side) as usize;
        let side_y = (self.height as i64 - fy).clamp(0, side) as usize;
        let centre = |i: usize, f: i64, origin: i64| (origin + f + i as i64) as f32 + 0.5;
        for (i, w) in wx.iter_mut().enumerate().take(side_x) {
            *w = self.filter.shape_1d(centre(i, fx, self.x0) - film.x);
        }
        for (j, w) in wy.iter_mut().enumerate().take(side_y) {
            *w = self.filter.shape_1d(centre(j, fy, self.y0) - film.y);
        }
        for (j, &w_y) in wy.iter().enumerate().take(side_y) {
            if w_y == 0.0 {
                continue;
            }
            let row = (fy as usize + j) * self.width as usize + fx as usize;
            for (i, &w_x) in wx.iter().enumerate().take(side_x) {
                let w = w_x * w_y;
                if w == 0.0 {
                    continue;
                }
                self.cells[row + i].add(&SplatCell::sample(value, w));
            }
        }
    }
}

/// The aprons of one pass, a slot per film tile, filled by the tiles' jobs.
pub struct PassAprons(Vec<std::sync::Mutex<Option<Apron>>>);

impl PassAprons {
    /// Empty slots for `tiles` tiles (none at all when `splatting` is off).
    pub fn new(tiles: usize, splatting: bool) -> PassAprons {
        let tiles = if splatting { tiles } else { 0 };
        PassAprons((0..tiles).map(|_| std::sync::Mutex::new(None)).collect())
    }

    /// Keeps tile `index`'s apron.
    pub fn put(&self, index: usize, apron: Apron) {
        *self.0[index].lock().unwrap_or_else(|e| e.into_inner()) = Some(apron);
    }

    /// The aprons in the film's tile order, `None` for a tile not rendered.
    pub fn into_aprons(self) -> Vec<Option<Apron>> {
        self.0
            .into_iter()
            .map(|a| a.into_inner().unwrap_or_else(|e| e.into_inner()))
            .collect()
    }
}

/// Merges into `tile` what the pass's aprons gave its pixels. `aprons`
/// holds one entry per film tile, in the film's order (rows of
/// `tiles_across` tiles), `None` for a tile not rendered in this part of
/// the pass; a pixel sums the cells covering it in that order.
pub fn fold(tile: &mut Tile, aprons: &[Option<Apron>], tiles_across: u32) {
    fold_shifted(tile, aprons, tiles_across, |_| [0.0; 3]);
}

/// [`fold`], each sample's value a pixel received raised by `shift(i)`
/// for the tile's pixel `i` (a splatting technique's light image of the
/// pass, which every one of the pass's samples of the pixel then carries).
pub fn fold_shifted(
    tile: &mut Tile,
    aprons: &[Option<Apron>],
    tiles_across: u32,
    shift: impl Fn(usize) -> [f64; 3],
) {
    const SIZE: usize = super::TILE_SIZE as usize;
    // A reach below a tile's side: only the eight neighbours' aprons overlap.
    const _: () = assert!(MAX_SIDE / 2 < SIZE);
    let tile_size = super::TILE_SIZE;
    let tiles_down = aprons.len() as u32 / tiles_across.max(1);
    if tile.weights.len() != tile.pixels.len() {
        tile.weights = vec![WeightSums::default(); tile.pixels.len()];
    }
    let (x0, y0, width) = (i64::from(tile.x0), i64::from(tile.y0), tile.width as usize);
    let (x1, y1) = (x0 + i64::from(tile.width), y0 + i64::from(tile.height));
    let mut groups = [SplatCell::default(); SIZE * SIZE];
    let (column, row) = (tile.x0 / tile_size, tile.y0 / tile_size);
    for r in row.saturating_sub(1)..=(row + 1).min(tiles_down.saturating_sub(1)) {
        for c in column.saturating_sub(1)..=(column + 1).min(tiles_across - 1) {
            let Some(apron) = &aprons[(r * tiles_across + c) as usize] else {
                continue;
            };
            // The rectangle where the apron overlaps this tile.
            let (ax1, ay1) = (
                apron.x0 + i64::from(apron.width),
                apron.y0 + i64::from(apron.height),
            );
            let (left, right) = (x0.max(apron.x0), x1.min(ax1));
            let (top, bottom) = (y0.max(apron.y0), y1.min(ay1));
            for y in top..bottom {
                let cells = (y - apron.y0) * i64::from(apron.width) - apron.x0;
                let pixels = (y - y0) as usize * width;
                for x in left..right {
                    groups[pixels + (x - x0) as usize].add(&apron.cells[(cells + x) as usize]);
                }
            }
        }
    }
    let pixels = tile.pixels.iter_mut().zip(&mut tile.weights);
    for (i, ((pixel, weights), group)) in pixels.zip(&mut groups).enumerate() {
        let e = shift(i);
        if e != [0.0; 3] {
            // Σ w (L + e), Σ w² (L + e)² and Σ w² (L + e) from the sums.
            for c in 0..3 {
                let (sum, sq, moment) = (
                    f64::from(group.sum[c]),
                    f64::from(group.sum_sq[c]),
                    f64::from(group.moment[c]),
                );
                let (w, w2) = (f64::from(group.weight), f64::from(group.weight_sq));
                group.sum[c] = (sum + e[c] * w) as f32;
                group.sum_sq[c] = (sq + 2.0 * e[c] * moment + e[c] * e[c] * w2) as f32;
                group.moment[c] = (moment + e[c] * w2) as f32;
            }
        }
        merge(pixel, weights, group);
    }
}

/// Adds a weighted group of samples to a pixel's weighted running mean
/// and its error (`pixel.m2` holds Σ w² (L − mean)² about the current
/// mean, moved with it through [`WeightSums::moment`]); its count is the
/// caller's.
pub fn merge(pixel: &mut PixelSums, weights: &mut WeightSums, group: &SplatCell) {
    if !(group.weight > 0.0) {
        return;
    }
    let (old, added) = (f64::from(weights.sum), f64::from(group.weight));
    let (old_sq, added_sq) = (f64::from(weights.sum_sq), f64::from(group.weight_sq));
    let total = old + added;
    for c in 0..3 {
        let mean = f64::from(pixel.mean[c]);
        let new_mean = mean + (f64::from(group.sum[c]) - mean * added) / total;
        let shift = new_mean - mean;
        // The old samples' Σ w² (L − m)² and Σ w² (L − m), moved to the new mean.
        let moment = f64::from(weights.moment[c]);
        let spread = f64::from(pixel.m2[c]) - 2.0 * shift * moment + shift * shift * old_sq;
        let moment = moment - shift * old_sq;
        // The group's about the new mean.
        let (sum_sq, group_moment) = (f64::from(group.sum_sq[c]), f64::from(group.moment[c]));
        let group_spread = sum_sq - 2.0 * new_mean * group_moment + new_mean * new_mean * added_sq;
        pixel.mean[c] = new_mean as f32;
        pixel.m2[c] = (spread + group_spread).max(0.0) as f32;
        weights.moment[c] = (moment + group_moment - new_mean * added_sq) as f32;
    }
    weights.sum = total as f32;
    weights.sum_sq = (old_sq + added_sq) as f32;
}

/// Standard error of a weighted mean R = Σ w L / W by the delta method:
/// Σ w² (L − R)² / W², over 1 − W₂ / W² for the mean estimated from the
/// same samples (with unit weights, s² / n). Infinite until the weights
/// make more than one sample's worth.
pub fn standard_error(pixel: &PixelSums, weights: &WeightSums) -> [f32; 3] {
    let (w, w2) = (f64::from(weights.sum), f64::from(weights.sum_sq));
    let denominator = w * w - w2;
    if !(w > 0.0) || !(denominator > 1e-6 * w * w) {
        return [f32::INFINITY; 3];
    }
    pixel
        .m2
        .map(|m| (f64::from(m).max(0.0) / denominator).sqrt() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Film;
    use crate::sampling::hash::{hash_combine, to_unit_float};

    /// With unit weights the merge and the standard error are Welford's:
    /// groups merged give the mean, spread and error of the samples added
    /// one by one.
    #[test]
    fn unit_weights_merge_as_plain_samples() {
        let values = [0.5f32, 2.0, 0.25, 7.0, 1.0, 3.0, 0.0];
        let mut plain = PixelSums::default();
        for &v in &values {
            plain.add(Rgb::splat(v));
        }
        let (mut merged, mut weights) = (PixelSums::default(), WeightSums::default());
        for chunk in values.chunks(3) {
            let mut group = SplatCell::default();
            for &v in chunk {
                group.add(&SplatCell::sample(Rgb::splat(v), 1.0));
            }
            merge(&mut merged, &mut weights, &group);
        }
        assert!((merged.mean[0] - plain.mean[0]).abs() < 1e-6);
        assert!((merged.m2[0] - plain.m2[0]).abs() < 1e-4);
        let (se, plain_se) = (standard_error(&merged, &weights), plain.standard_error());
        assert!((se[0] - plain_se[0]).abs() < 1e-6, "{se:?} vs {plain_se:?}");
    }

    /// A weighted group's mean is Σ w L / Σ w, and its error term
    /// Σ w² (L − mean)², merged in any grouping.
    #[test]
    fn weighted_groups_merge_to_the_weighted_mean() {
        let samples: Vec<(f32, f32)> = (0..50u64)
            .map(|i| {
                let u = to_unit_float(hash_combine(3, i));
                let w = to_unit_float(hash_combine(4, i));
                (4.0 * u, w)
            })
            .collect();
        let w_sum: f64 = samples.iter().map(|&(_, w)| f64::from(w)).sum();
        let mean: f64 = samples.iter().map(|&(l, w)| f64::from(w * l)).sum::<f64>() / w_sum;
        let m2: f64 = samples
            .iter()
            .map(|&(l, w)| f64::from(w * w) * (f64::from(l) - mean).powi(2))
            .sum();
        for size in [1, 7, 50] {
            let (mut pixel, mut weights) = (PixelSums::default(), WeightSums::default());
            for chunk in samples.chunks(size) {
                let mut group = SplatCell::default();
                for &(l, w) in chunk {
                    group.add(&SplatCell::sample(Rgb::splat(l), w));
                }
                merge(&mut pixel, &mut weights, &group);
            }
            assert!(
                (f64::from(pixel.mean[1]) - mean).abs() < 1e-5,
                "groups of {size}"
            );
            assert!(
                (f64::from(pixel.m2[1]) / m2 - 1.0).abs() < 1e-4,
                "groups of {size}"
            );
        }
    }

    /// A sample's weights over the pixels it reaches are the filter's at
    /// their centres, and land in the aprons of the tiles that own them:
    /// a sample near a tile's corner reaches its three neighbours.
    #[test]
    fn a_splat_reaches_the_pixels_its_filter_covers_across_tiles() {
        let film = Film::new(40, 40);
        let filter = PixelFilter::tent();
        let across = 3;
        let mut aprons: Vec<Option<Apron>> = film
            .tiles()
            .iter()
            .map(|t| Some(Apron::new(&t.lock().unwrap(), filter)))
            .collect();
        // In pixel (15, 15), the last of tile 0, near its corner.
        let point = Vec2::new(15.8, 15.9);
        aprons[0].as_mut().unwrap().splat(point, Rgb::splat(2.0));
        let mut total = 0.0;
        for (index, tile) in film.tiles().iter().enumerate() {
            let mut tile = tile.lock().unwrap();
            fold(&mut tile, &aprons, across);
            for (i, w) in tile.weights.iter().enumerate() {
                let (x, y) = (
                    tile.x0 + i as u32 % tile.width,
                    tile.y0 + i as u32 / tile.width,
                );
                let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let expected =
                    filter.shape_1d(centre.x - point.x) * filter.shape_1d(centre.y - point.y);
                assert!(
                    (w.sum - expected).abs() < 1e-6,
                    "tile {index}, pixel ({x}, {y})"
                );
                if expected > 0.0 {
                    assert_eq!(tile.pixels[i].mean, [2.0; 3]);
                }
                total += w.sum;
            }
        }
        // Pixels 15 and 16 in x (centres 0.3 and 0.7 away) and in y (0.4, 0.6).
        assert!((total - (0.7 + 0.3) * (0.6 + 0.4)).abs() < 1e-6);
    }
}
