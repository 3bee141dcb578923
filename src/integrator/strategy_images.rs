//! The images of BDPT's strategies kept apart: Veach's (s, t) pyramid, for
//! `render --strategies` and the viewer's strategy window. Each strategy
//! accumulates its own image, MIS-weighted (they sum to the image) and
//! unweighted (each an estimate of the light its strategy can find).

use super::RayCounts;
use super::bdpt::{Bdpt, MAX_BOUNCES};
use crate::sampling::Sampler;
use crate::scene::Scene;

/// The images of every strategy (s, t) of one render: Veach's pyramid.
/// Index `strategy_index(s, t)`; each image is linear RGB, row-major.
pub struct StrategyImages {
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    /// MIS-weighted contributions: they sum to the image.
    pub weighted: Vec<Vec<[f32; 3]>>,
    /// The same paths without weights: each alone estimates its share of
    /// the light (where its strategy can make the paths at all).
    pub unweighted: Vec<Vec<[f32; 3]>>,
}

/// Where strategy (s, t) is stored in [`StrategyImages`]: row by row of
/// bounces k = s + t - 2, then by s.
pub fn strategy_index(s: u32, t: u32) -> usize {
    let k = (s + t - 2) as usize;
    k * (k + 3) / 2 + s as usize
}

/// Number of strategies of paths up to `max_depth` bounces (t >= 1).
pub fn strategy_count(max_depth: u32) -> usize {
    strategy_index(max_depth + 1, 1) + 1
}

impl StrategyImages {
    /// Bytes the images of a render at `width` x `height` up to `max_depth`
    /// take, to refuse a request before allocating.
    pub fn memory_estimate(width: u32, height: u32, max_depth: u32) -> u64 {
        2 * strategy_count(max_depth) as u64 * u64::from(width) * u64::from(height) * 12
    }

    /// Renders `spp` samples per pixel of `scene` with `bdpt` on one thread
    /// per row band (`threads` bands), keeping every strategy apart.
    pub fn render(
        scene: &Scene,
        bdpt: &Bdpt,
        sampler: &Sampler,
        spp: u32,
    ) -> (StrategyImages, RayCounts) {
        let (width, height) = (scene.camera.width, scene.camera.height);
        let max_depth = bdpt.max_depth.min(MAX_BOUNCES);
        let count = strategy_count(max_depth);
        let pixels = (width * height) as usize;
        let mut weighted = vec![vec![[0.0f64; 3]; pixels]; count];
        let mut unweighted = vec![vec![[0.0f64; 3]; pixels]; count];
        let mut counts = RayCounts::default();
        let mut sampler = sampler.clone();
        for y in 0..height {
            for x in 0..width {
                for sample in 0..spp {
                    sampler.start(y * width + x, sample);
                    let filter = scene.camera.filter;
                    bdpt.trace_strategies(scene, (x, y), filter, &mut sampler, &mut counts, |c| {
                        let (px, py) = (c.film.x as u32, c.film.y as u32);
                        if px >= width || py >= height {
                            return;
                        }
                        let i = strategy_index(c.s, c.t);
                        let p = (py * width + px) as usize;
                        for k in 0..3 {
                            weighted[i][p][k] += f64::from(c.weighted[k]);
                            unweighted[i][p][k] += f64::from(c.unweighted[k]);
                        }
                    });
                }
            }
        }
        let n = f64::from(width) * f64::from(height) * f64::from(spp);
        let finish = |images: Vec<Vec<[f64; 3]>>| -> Vec<Vec<[f32; 3]>> {
            images
                .into_iter()
                .map(|image| {
                    image
                        .into_iter()
                        .map(|p| p.map(|v| (v / n) as f32))
                        .collect()
                })
                .collect()
        };
        (
            StrategyImages {
                width,
                height,
                max_depth,
                weighted: finish(weighted),
                unweighted: finish(unweighted),
            },
            counts,
        )
    }
}

impl StrategyImages {
    /// Veach's pyramid as one image: row k holds the strategies of paths of
    /// k bounces (k = 0 ..= `rows` - 1), s = 0 .. k + 1 from the left.
    pub fn sheet(&self, weighted: bool, rows: u32) -> crate::image::Image {
        let tiles = if weighted {
            &self.weighted
        } else {
            &self.unweighted
        };
        let rows = rows.min(self.max_depth + 1).max(1);
        let (w, h) = (self.width, self.height);
        let mut sheet = crate::image::Image::new(w * (rows + 1), h * rows);
        for k in 0..rows {
            for s in 0..=k + 1 {
                let tile = &tiles[strategy_index(s, k + 2 - s)];
                for y in 0..h {
                    let to = ((k * h + y) * sheet.width + s * w) as usize;
                    let from = (y * w) as usize;
                    sheet.pixels[to..to + w as usize]
                        .copy_from_slice(&tile[from..from + w as usize]);
                }
            }
        }
        sheet
    }

    /// Folds `batch` (of the same size and depth) into a running mean of
    /// which `self` holds `batches` batches so far.
    pub fn accumulate(&mut self, batch: &StrategyImages, batches: u32) {
        let t = 1.0 / (batches + 1) as f32;
        for (mine, theirs) in self
            .weighted
            .iter_mut()
            .chain(self.unweighted.iter_mut())
            .zip(batch.weighted.iter().chain(&batch.unweighted))
        {
            for (a, b) in mine.iter_mut().zip(theirs) {
                for c in 0..3 {
                    a[c] += (b[c] - a[c]) * t;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strategy_indices_are_dense() {
        let mut seen = vec![false; strategy_count(4)];
        for k in 0..=4u32 {
            for s in 0..=k + 1 {
                let i = strategy_index(s, k + 2 - s);
                assert!(!seen[i]);
                seen[i] = true;
            }
        }
        assert!(seen.iter().all(|&b| b));
    }
}
