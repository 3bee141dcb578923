//! Samplers: the source of every random number a path consumes.
//!
//! A path asks for numbers one dimension at a time (pixel position, lens, light
//! choice, light point, BSDF lobe, BSDF direction, Russian roulette, ...). The
//! sampler decides how the numbers of different samples of the same pixel
//! relate in each dimension. All of them are functions of
//! (seed, pixel, sample index, dimension) only.

pub use super::domain::{Domain, Domains};
use super::hash::{hash_combine, mix64, permute, to_unit_float};
use super::sobol::{
    PARTICLE_MATRICES, laine_karras, owen_scramble, sobol_by_matrix, sobol_dimension_0,
    sobol_dimension_1,
};
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
    /// Correlated multi-jittered (Kensler 2013): 2D pairs are jittered on an
    /// m x n grid *and* Latin hypercube in each axis (one sample per 1/N
    /// column and row); 1D dimensions are Latin hypercube samples.
    #[serde(alias = "cmj")]
    MultiJittered,
    /// Sobol (0,2)-sequence, Owen-scrambled with Laine-Karras hashing and
    /// shuffled per dimension pair (Burley 2020, pbrt-v4's padded Sobol):
    /// every power-of-two prefix is a stratified (0,m,2)-net in each pair.
    /// Path tracing draws from it up to [`SOBOL_PATH_VERTICES`] vertices.
    Sobol,
}

impl SamplerKind {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
            SamplerKind::MultiJittered => "multijitter",
            SamplerKind::Sobol => "sobol",
        }
    }

    pub const ALL: [SamplerKind; 4] = [
        SamplerKind::Independent,
        SamplerKind::Stratified,
        SamplerKind::MultiJittered,
        SamplerKind::Sobol,
    ];
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
    /// Key of (seed, pixel): seeds the Sobol scrambles of each dimension.
    pixel_key: u64,
    /// Key of (seed, pixel, batch): seeds the per-dimension strata permutations.
    batch_key: u64,
    sample_key: u64,
    sample_index: u32,
    /// `sample_index` with its bits mirrored: where every Sobol request's
    /// index scramble starts.
    reversed_index: u32,
    dimension: u32,
    /// Samples stratified together. Sample `i` belongs to batch `i / batch`;
    /// rendering past a planned count simply starts another stratified batch,
    /// so unlimited progressive rendering never degrades below independent.
    batch: u32,
    /// 2D strata grid, `grid_x * grid_y == batch` exactly so that every
    /// stratum is used (an unused stratum would bias the estimate).
    grid_x: u32,
    grid_y: u32,
    /// Domains that use `kind`; the rest are independent.
    domains: Domains,
    /// Dimensions from this one on are independent (see
    /// [`Sampler::enter_path_vertex`]).
    independent_from: u32,
    /// The pixel of the current sample and its camera sample's index (a
    /// particle's number reads them).
    pixel: u32,
    camera_index: u32,
    /// Sobol: the current sample is a particle whose first three requests
    /// come from one five-dimensional net over all the render's particles
    /// (see [`Sampler::start_particle`]).
    particle: bool,
}

/// Path vertices (the camera ray's hit is vertex 0) whose numbers the Sobol
/// sampler takes from its sequence; deeper vertices get independent numbers.
/// A 2D Sobol point costs an index scramble, two Owen scrambles and Sobol's
/// second dimension where an independent pair costs one hash, and deep
/// bounces, already averaged over the earlier vertices' directions, gain
/// next to nothing from stratification. Cornell box, path tracing spread by
/// noise, seeds 1 and 2, 2 threads: RMSE at 64 spp +0.4% (0.00492 ->
/// 0.00494), render time -7% (1.11 -> 1.04 s), MSE x time -6%; with one
/// vertex +1% RMSE for -8% time; with all vertices (pbrt-v4's padded Sobol)
/// the slowest.
pub const SOBOL_PATH_VERTICES: u32 = 2;

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
            pixel_key: 0,
            batch_key: 0,
            sample_key: 0,
            sample_index: 0,
            reversed_index: 0,
            dimension: 0,
            batch,
            grid_x,
            grid_y: batch / grid_x,
            domains: Domains::ALL,
            independent_from: u32::MAX,
            pixel: 0,
            camera_index: 0,
            particle: false,
        }
    }

    /// The same sampler applied only to `domains`.
    pub fn with_domains(mut self, domains: Domains) -> Self {
        self.domains = domains;
        self
    }

    /// One number in [0, 1) for `domain`: from this sampler where the domain
    /// is selected, independent otherwise. Consumes one dimension either way.
    #[inline]
    pub fn next_1d_for(&mut self, domain: Domain) -> f32 {
        let dim = self.skip();
        self.get_1d_for(dim, domain)
    }

    /// Consumes a dimension without computing its numbers, for a request a
    /// path makes only sometimes (Russian roulette, a lobe choice, a lens
    /// point): later requests keep their dimensions either way, and the
    /// numbers are computed, by [`Sampler::get_1d_for`], only when needed.
    #[inline]
    pub fn skip(&mut self) -> u32 {
        self.reserve(1)
    }

    /// Consumes `n` dimensions at once; returns the first.
    #[inline]
    pub fn reserve(&mut self, n: u32) -> u32 {
        self.dimension += n;
        self.dimension - n
    }

    /// The number of dimension `dim` (one [`Sampler::skip`] returned) of
    /// the current sample: what [`Sampler::next_1d_for`] would have drawn.
    #[inline(always)]
    pub fn get_1d_for(&self, dim: u32, domain: Domain) -> f32 {
        if dim < self.independent_from && self.domains.contains(domain) {
            self.get_1d(dim)
        } else {
            to_unit_float(self.hash(dim))
        }
    }

    /// Two numbers in [0, 1)² for `domain` (see [`Sampler::next_1d_for`]).
    #[inline(always)]
    pub fn next_2d_for(&mut self, domain: Domain) -> Vec2 {
        let dim = self.skip();
        self.get_2d_for(dim, domain)
    }

    /// The pair of dimension `dim` (see [`Sampler::get_1d_for`]).
    #[inline(always)]
    pub fn get_2d_for(&self, dim: u32, domain: Domain) -> Vec2 {
        if dim < self.independent_from && self.domains.contains(domain) {
            self.get_2d(dim)
        } else {
            let h = self.hash(dim);
            Vec2::new(to_unit_float(h), to_unit_float(h << 24))
        }
    }

    /// Tells the sampler that a path reached its vertex `vertex` (0 for the
    /// camera ray's hit): from vertex [`SOBOL_PATH_VERTICES`] on, the Sobol
    /// sampler's numbers are independent ones.
    #[inline(always)]
    pub fn enter_path_vertex(&mut self, vertex: u32) {
        if vertex == SOBOL_PATH_VERTICES && self.kind == SamplerKind::Sobol {
            self.independent_from = self.dimension;
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
        self.pixel_key = pixel_key;
        self.sample_key = hash_combine(pixel_key, sample_index as u64);
        // Only the strata permutations read the batch key (a hash and a
        // division per camera sample that Sobol and independent skip).
        if matches!(
            self.kind,
            SamplerKind::Stratified | SamplerKind::MultiJittered
        ) {
            self.batch_key = hash_combine(
                pixel_key,
                0x8000_0000_0000_0000 | (sample_index / self.batch) as u64,
            );
        }
        self.sample_index = sample_index;
        self.reversed_index = sample_index.reverse_bits();
        self.dimension = 0;
        self.independent_from = u32::MAX;
        self.pixel = pixel;
        self.camera_index = sample_index;
        self.particle = false;
    }

    /// Starts the light path of the current camera sample, the render's
    /// particle number sample index × `pixels` + the pixel's slot (the
    /// pixels shuffled per sample index). Sobol draws its
    /// light choice, point and direction from one five-dimensional Sobol
    /// net over all particles, Owen-scrambled by the seed alone, and its
    /// later numbers from the padded sequence over particles: a pixel's
    /// own sequence stratifies only its 2^k camera samples, where the
    /// particles that land in a pixel come from every pixel's samples and
    /// were drawn independently of each other (light tracing's count noise
    /// in a lit pixel). The other samplers go on with the camera sample's
    /// numbers.
    pub fn start_particle(&mut self, pixels: u32) {
        self.start_particle_of(pixels, 0, 1);
    }

    /// Starts particle `j` of the `n` that the current camera sample
    /// traces (BDPT's extra light-tracing particles): number (sample index
    /// × n + j) × `pixels` + slot, so that the pass's particles j are a block
    /// of the sequence, a net of their own (numbered sample index × n × pixels
    /// + slot × n + j, the particles j = 0 would all lie in one half of the
    /// first dimension: an even index's radical inverse is below 1/2).
    pub fn start_particle_of(&mut self, pixels: u32, j: u32, n: u32) {
        if self.kind != SamplerKind::Sobol {
            return;
        }
        // The pass's particles are a block of the sequence, handed to its
        // pixels in an order shuffled per sample index: a particle number
        // that followed the pixel's would tie a column's light paths to
        // one half of the net (the sequence's low bits), a pattern that
        // BDPT's connections printed as stripes.
        let block = u64::from(self.camera_index) * u64::from(n) + u64::from(j);
        let key = hash_combine(self.seed_key, block);
        let slot = permute(self.pixel.min(pixels - 1), pixels, key as u32);
        let number = block * u64::from(pixels) + u64::from(slot);
        // One sequence per 2^32 particles, each scrambled afresh.
        let key = hash_combine(self.seed_key, 0x4000_0000_0000_0000 | (number >> 32));
        self.pixel_key = key;
        self.sample_key = hash_combine(key, number);
        self.sample_index = number as u32;
        self.reversed_index = self.sample_index.reverse_bits();
        self.dimension = 0;
        self.independent_from = u32::MAX;
        self.particle = true;
    }

    /// Coordinate `j` of the particles' five-dimensional net at the
    /// current particle, Owen-scrambled.
    #[inline]
    fn particle_coordinate(&self, j: usize) -> f32 {
        let seed = hash_combine(self.pixel_key, 0x100 + j as u64) as u32;
        let index = self.sample_index;
        bits_to_unit_float(match j {
            0 => sobol_dimension_0(index, seed),
            1 => sobol_dimension_1(index, seed),
            _ => owen_scramble(sobol_by_matrix(index, &PARTICLE_MATRICES[j - 2]), seed),
        })
    }

    /// The dimension the next request will use (for replaying a sample).
    pub fn dimension(&self) -> u32 {
        self.dimension
    }

    #[inline]
    fn hash(&self, dim: u32) -> u64 {
        hash_combine(self.sample_key, dim as u64)
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
        let dim = self.skip();
        self.get_1d(dim)
    }

    /// Two numbers in [0, 1)², stratified together as a pair.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let dim = self.skip();
        self.get_2d(dim)
    }

    /// The sample's index in the Sobol sequence of one dimension (pair):
    /// Owen's nested uniform scramble of the index (Burley 2020: mirrored,
    /// each digit flipped by a hash of the digits above it), which shuffles
    /// the samples differently per dimension (padding) while mapping every
    /// aligned power-of-two block onto another, so prefixes of 2^k samples
    /// stay nets.
    #[inline]
    fn sobol_index(&self, seed: u32) -> u32 {
        laine_karras(self.reversed_index, seed).reverse_bits()
    }

    #[inline(always)]
    fn get_1d(&self, dim: u32) -> f32 {
        if self.kind == SamplerKind::Sobol {
            if self.particle && dim == 0 {
                return self.particle_coordinate(0);
            }
            let key = hash_combine(self.pixel_key, dim as u64);
            let index = self.sobol_index(key as u32);
            return bits_to_unit_float(sobol_dimension_0(index, (key >> 32) as u32));
        }
        let u = to_unit_float(self.hash(dim));
        match self.kind {
            SamplerKind::Stratified | SamplerKind::MultiJittered => {
                let s = self.stratum(dim);
                ((s as f32 + u) / self.batch as f32).min(ONE_MINUS_EPSILON)
            }
            _ => u,
        }
    }

    #[inline(always)]
    fn get_2d(&self, dim: u32) -> Vec2 {
        if self.kind == SamplerKind::Sobol {
            if self.particle && (dim == 1 || dim == 2) {
                let j = 2 * dim as usize - 1;
                return Vec2::new(self.particle_coordinate(j), self.particle_coordinate(j + 1));
            }
            let key = hash_combine(self.pixel_key, dim as u64);
            let index = self.sobol_index(key as u32);
            let x = sobol_dimension_0(index, (key >> 32) as u32);
            let y = sobol_dimension_1(index, mix64(key) as u32);
            return Vec2::new(bits_to_unit_float(x), bits_to_unit_float(y));
        }
        let h = self.hash(dim);
        let u = to_unit_float(h);
        let v = to_unit_float(h << 24);
        match self.kind {
            SamplerKind::Independent => Vec2::new(u, v),
            SamplerKind::MultiJittered => {
                // Kensler's cmj: a shuffled sample index picks a cell of the
                // m x n grid; within it, the sub-cell offsets are permutations
                // of the other axis, so the columns and rows of the fine
                // N x N grid are each hit once.
                let (m, n) = (self.grid_x, self.grid_y);
                let key = hash_combine(self.batch_key, dim as u64);
                let s = permute(self.sample_index % self.batch, self.batch, key as u32);
                let (cx, cy) = (s % m, s / m);
                // Seeds from a fresh hash: seeds that differ by a constant
                // XOR gave correlated small permutations (chi-square test).
                let axes_key = mix64(key);
                let sx = permute(cx, m, axes_key as u32);
                let sy = permute(cy, n, (axes_key >> 32) as u32);
                Vec2::new(
                    ((cx as f32 + (sy as f32 + u) / n as f32) / m as f32).min(ONE_MINUS_EPSILON),
                    ((cy as f32 + (sx as f32 + v) / m as f32) / n as f32).min(ONE_MINUS_EPSILON),
                )
            }
            SamplerKind::Stratified | SamplerKind::Sobol => {
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

/// The top 24 bits of a 32-bit fixed-point fraction as a float in [0, 1).
#[inline]
fn bits_to_unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_paths_turn_independent_at_their_deep_vertices() {
        // The numbers a path draws at vertex v, with the vertex announced.
        let draw = |kind: SamplerKind, vertex: u32| {
            let mut s = Sampler::new(kind, 3, 64);
            s.start(77, 5);
            s.reserve(2);
            for v in 0..=vertex {
                s.enter_path_vertex(v);
                s.reserve(5);
            }
            let dim = s.dimension() - 5;
            (
                s.get_2d_for(dim + 1, Domain::Light),
                s.get_1d_for(dim + 4, Domain::Other),
            )
        };
        for vertex in 0..5 {
            let (sobol, independent) = (
                draw(SamplerKind::Sobol, vertex),
                draw(SamplerKind::Independent, vertex),
            );
            assert_eq!(
                sobol == independent,
                vertex >= SOBOL_PATH_VERTICES,
                "{vertex}"
            );
            // Other samplers keep stratifying every vertex.
            assert_ne!(draw(SamplerKind::Stratified, vertex), independent);
        }
        // A new sample starts on the sequence again.
        let mut s = Sampler::new(SamplerKind::Sobol, 3, 64);
        s.start(77, 5);
        s.enter_path_vertex(SOBOL_PATH_VERTICES);
        s.start(77, 6);
        assert_ne!(s.get_2d_for(0, Domain::Pixel), {
            let mut i = Sampler::new(SamplerKind::Independent, 3, 64);
            i.start(77, 6);
            i.get_2d_for(0, Domain::Pixel)
        });
    }

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

    /// Points of `kind` for samples 0..n of one pixel, from one 2D request
    /// after `skip` 1D requests.
    fn points(kind: SamplerKind, n: u32, skip: u32, first: u32) -> Vec<Vec2> {
        let mut s = Sampler::new(kind, 11, n);
        (first..first + n)
            .map(|i| {
                s.start(42, i);
                for _ in 0..skip {
                    s.next_1d();
                }
                s.next_2d()
            })
            .collect()
    }

    fn counts(points: &[Vec2], nx: u32, ny: u32) -> Vec<u32> {
        let mut c = vec![0; (nx * ny) as usize];
        for p in points {
            c[(p.x * nx as f32) as usize + nx as usize * (p.y * ny as f32) as usize] += 1;
        }
        c
    }

    #[test]
    fn a_passs_particles_are_a_five_dimensional_net() {
        // A pass of 256 pixels at one sample: its 256 particles' light
        // choice, point and direction are Sobol's first five dimensions,
        // which at 256 points form a (3, 8, 5)-net (computed from the
        // matrices; Niederreiter's bound is 5): every box of volume 2^-5
        // of every shape holds exactly 8 of them. A dimension repeated,
        // a polynomial mistaken for another, or a pass that is not one
        // block of the sequence breaks some box; and each coordinate alone
        // is a (0, 8, 1)-net, one point per 1/256.
        for (sample, seed) in [(0, 1), (3, 2)] {
            let mut s = Sampler::new(SamplerKind::Sobol, seed, 0);
            let points: Vec<[f32; 5]> = (0..256)
                .map(|pixel| {
                    s.start(pixel, sample);
                    s.next_2d(); // the camera path's numbers come first
                    s.start_particle(256);
                    let select = s.next_1d();
                    let (a, b) = (s.next_2d(), s.next_2d());
                    [select, a.x, a.y, b.x, b.y]
                })
                .collect();
            for j in 0..5 {
                let mut cells = [0; 256];
                for p in &points {
                    cells[(p[j] * 256.0) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "coordinate {j}");
            }
            for shape in 0..6u32.pow(5) {
                let digits: Vec<u32> = (0..5).map(|j| shape / 6u32.pow(j) % 6).collect();
                if digits.iter().sum::<u32>() != 5 {
                    continue;
                }
                let mut boxes = [0; 32];
                for p in &points {
                    let mut index = 0;
                    for j in 0..5 {
                        index = (index << digits[j]) | (p[j] * (1 << digits[j]) as f32) as usize;
                    }
                    boxes[index] += 1;
                }
                assert!(
                    boxes.iter().all(|&c| c == 8),
                    "sample {sample}, shape {digits:?}: {boxes:?}"
                );
            }
        }
        // With four particles per camera sample, the pass's particles j
        // are a block of their own: each coordinate one point per 1/256
        // (numbered so that j followed the pixel, particle 0's first
        // coordinate would stay below 1/2).
        let mut s = Sampler::new(SamplerKind::Sobol, 3, 0);
        for j in [0, 3] {
            let mut cells = [[0; 256]; 2];
            for pixel in 0..256 {
                s.start(pixel, 5);
                s.start_particle_of(256, j, 4);
                let select = s.next_1d();
                let point = s.next_2d();
                cells[0][(select * 256.0) as usize] += 1;
                cells[1][(point.x * 256.0) as usize] += 1;
            }
            assert!(cells.iter().flatten().all(|&c| c == 1), "particle {j}");
        }
        // The other samplers go on with the camera sample's numbers.
        let mut a = Sampler::new(SamplerKind::Independent, 7, 0);
        let mut b = a.clone();
        a.start(5, 2);
        b.start(5, 2);
        a.next_2d();
        b.next_2d();
        b.start_particle(64);
        assert_eq!(a.next_2d(), b.next_2d());
    }

    #[test]
    fn sobol_prefixes_are_nets_in_every_elementary_interval_shape() {
        // 256 points of a (0,8,2)-net: every 2^a x 2^b box with a + b = 8
        // holds exactly one, for every dimension pair and every aligned block
        // of 256 samples (progressive rendering past any power of two).
        for skip in [0, 1, 5] {
            for first in [0, 256, 768] {
                let p = points(SamplerKind::Sobol, 256, skip, first);
                for a in 0..=8 {
                    let c = counts(&p, 1 << a, 1 << (8 - a));
                    assert!(
                        c.iter().all(|&c| c == 1),
                        "skip {skip} first {first} 2^{a}: {c:?}"
                    );
                }
            }
        }
        // 1D requests: one point per 1/256 interval.
        let mut s = Sampler::new(SamplerKind::Sobol, 3, 0);
        let mut cells = vec![0; 256];
        for i in 0..256 {
            s.start(9, i);
            s.next_2d();
            cells[(s.next_1d() * 256.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
    }

    #[test]
    fn multi_jittered_is_jittered_and_latin_hypercube() {
        for (n, m) in [(256, 16), (24, 4)] {
            let p = points(SamplerKind::MultiJittered, n, 3, 0);
            let grid = counts(&p, m, n / m);
            assert!(grid.iter().all(|&c| c == 1), "grid {grid:?}");
            assert!(counts(&p, n, 1).iter().all(|&c| c == 1), "columns");
            assert!(counts(&p, 1, n).iter().all(|&c| c == 1), "rows");
        }
    }

    #[test]
    fn different_pixels_and_dimensions_get_different_scrambles() {
        for kind in [SamplerKind::Sobol, SamplerKind::MultiJittered] {
            let a = points(kind, 16, 0, 0);
            let b = points(kind, 16, 1, 0);
            assert_ne!(a, b, "{kind:?}");
        }
    }

    #[test]
    fn non_square_counts_factor_exactly() {
        let s = Sampler::new(SamplerKind::Stratified, 0, 24);
        assert_eq!((s.grid_x, s.grid_y), (4, 6));
        let s = Sampler::new(SamplerKind::Stratified, 0, 7);
        assert_eq!(s.grid_x * s.grid_y, 7);
    }
}
