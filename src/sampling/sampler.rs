//! Samplers: the source of every random number a path consumes.
//!
//! A path asks for numbers one dimension at a time (pixel position, lens, light
//! choice, light point, BSDF lobe, BSDF direction, Russian roulette, ...). The
//! sampler decides how the numbers of different samples of the same pixel
//! relate in each dimension. All of them are functions of
//! (seed, pixel, sample index, dimension) only.

use super::hash::{hash_combine, mix64, permute, to_unit_float};
use glam::Vec2;

/// Which sampler to use; selected on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Every number independent and uniform.
    #[default]
    Independent,
    /// Jittered: each dimension (or 2D pair) of a batch of samples is split into
    /// as many strata as the batch has samples, one sample per stratum. Strata are
    /// shuffled independently per dimension (pbrt's padding), so every dimension
    /// stays stratified without the curse of dimensionality of a full grid.
    Stratified,
}

impl SamplerKind {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
        }
    }
}

/// Default number of samples stratified together when a render has no planned
/// sample count (time-limited or unlimited progressive rendering).
pub const DEFAULT_BATCH: u32 = 64;

/// Per-thread sampler state. Cheap to create; reset with [`Sampler::start`]
/// for every (pixel, sample index).
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    seed_key: u64,
    /// Key of (seed, pixel, batch): seeds the per-dimension strata permutations.
    batch_key: u64,
    sample_key: u64,
    sample_index: u32,
    dimension: u32,
    /// Samples stratified together. Sample `i` belongs to batch `i / batch`;
    /// rendering past a planned count simply starts another stratified batch,
    /// so unlimited progressive rendering never degrades below independent.
    batch: u32,
    /// 2D strata grid, `grid_x * grid_y == batch` exactly so that every
    /// stratum is used (an unused stratum would bias the estimate).
    grid_x: u32,
    grid_y: u32,
}

impl Sampler {
    /// A sampler for a render with `planned_spp` samples per pixel (0 = unknown).
    pub fn new(kind: SamplerKind, seed: u64, planned_spp: u32) -> Self {
        let batch = if planned_spp == 0 {
            DEFAULT_BATCH
        } else {
            planned_spp.min(1 << 20)
        };
        // The most square factorisation batch = grid_x * grid_y.
        let mut grid_x = (batch as f64).sqrt() as u32;
        while batch % grid_x != 0 {
            grid_x -= 1;
        }
        Sampler {
            kind,
            seed_key: mix64(seed ^ 0x5851_f42d_4c95_7f2d),
            batch_key: 0,
            sample_key: 0,
            sample_index: 0,
            dimension: 0,
            batch,
            grid_x,
            grid_y: batch / grid_x,
        }
    }

    /// The kind of this sampler.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// Positions the sampler at dimension 0 of sample `sample_index` of `pixel`.
    #[inline]
    pub fn start(&mut self, pixel: u32, sample_index: u32) {
        let pixel_key = hash_combine(self.seed_key, pixel as u64);
        self.sample_key = hash_combine(pixel_key, sample_index as u64);
        self.batch_key = hash_combine(
            pixel_key,
            0x8000_0000_0000_0000 | (sample_index / self.batch) as u64,
        );
        self.sample_index = sample_index;
        self.dimension = 0;
    }

    /// The dimension the next request will use (for replaying a sample).
    pub fn dimension(&self) -> u32 {
        self.dimension
    }

    #[inline]
    fn next_hash(&mut self) -> (u64, u32) {
        let dim = self.dimension;
        self.dimension += 1;
        (hash_combine(self.sample_key, dim as u64), dim)
    }

    /// Permutation seed shared by all samples of one batch in one dimension.
    #[inline]
    fn stratum(&self, dim: u32) -> u32 {
        let key = hash_combine(self.batch_key, dim as u64);
        permute(self.sample_index % self.batch, self.batch, key as u32)
    }

    /// One number in [0, 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        let (h, dim) = self.next_hash();
        let u = to_unit_float(h);
        match self.kind {
            SamplerKind::Independent => u,
            SamplerKind::Stratified => {
                let s = self.stratum(dim);
                ((s as f32 + u) / self.batch as f32).min(ONE_MINUS_EPSILON)
            }
        }
    }

    /// Two numbers in [0, 1)², stratified together as a pair.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let (h, dim) = self.next_hash();
        let u = to_unit_float(h);
        let v = to_unit_float(h << 24);
        match self.kind {
            SamplerKind::Independent => Vec2::new(u, v),
            SamplerKind::Stratified => {
                let s = self.stratum(dim);
                let (sx, sy) = (s % self.grid_x, s / self.grid_x);
                Vec2::new(
                    ((sx as f32 + u) / self.grid_x as f32).min(ONE_MINUS_EPSILON),
                    ((sy as f32 + v) / self.grid_y as f32).min(ONE_MINUS_EPSILON),
                )
            }
        }
    }
}

/// The largest float below one.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_coordinates_give_same_numbers() {
        let mut a = Sampler::new(SamplerKind::Independent, 7, 16);
        let mut b = Sampler::new(SamplerKind::Independent, 7, 16);
        a.start(123, 5);
        let x = (a.next_1d(), a.next_2d());
        b.start(9, 0);
        b.next_1d();
        b.start(123, 5);
        assert_eq!(x, (b.next_1d(), b.next_2d()));
    }

    #[test]
    fn stratified_puts_one_sample_in_each_stratum() {
        let spp = 16;
        let mut s = Sampler::new(SamplerKind::Stratified, 1, spp);
        for dim in 0..6 {
            let mut cells_2d = vec![0; 16];
            let mut cells_1d = vec![0; 16];
            for i in 0..spp {
                s.start(77, i);
                for _ in 0..dim {
                    s.next_1d();
                }
                let u = s.next_1d();
                cells_1d[(u * 16.0) as usize] += 1;
                s.start(77, i);
                for _ in 0..dim {
                    s.next_1d();
                }
                let p = s.next_2d();
                cells_2d[(p.x * 4.0) as usize + 4 * (p.y * 4.0) as usize] += 1;
            }
            assert!(cells_1d.iter().all(|&c| c == 1), "dim {dim}: {cells_1d:?}");
            assert!(cells_2d.iter().all(|&c| c == 1), "dim {dim}: {cells_2d:?}");
        }
    }

    #[test]
    fn stratification_extends_past_the_planned_count() {
        // Samples 16..32 form a second complete stratified batch.
        let mut s = Sampler::new(SamplerKind::Stratified, 3, 16);
        let mut cells = vec![0; 16];
        for i in 16..32 {
            s.start(5, i);
            cells[(s.next_1d() * 16.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
    }

    #[test]
    fn non_square_counts_factor_exactly() {
        let s = Sampler::new(SamplerKind::Stratified, 0, 24);
        assert_eq!((s.grid_x, s.grid_y), (4, 6));
        let s = Sampler::new(SamplerKind::Stratified, 0, 7);
        assert_eq!(s.grid_x * s.grid_y, 7);
    }
}
