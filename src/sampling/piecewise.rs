//! Piecewise-constant densities on [0, 1) and [0, 1)², sampled by
//! inverting their CDFs (pbrt's Distribution1D / 2D; the 2D one in two
//! steps, a block of cells and then a cell): the environment map's
//! importance sampling.

use glam::Vec2;

/// One cell of a [`Piecewise1D`].
#[derive(Clone, Copy, Debug, Default)]
struct Cell {
    /// ∫_0^{i/n} f / ∫_0^1 f.
    cdf: f32,
    func: f32,
    /// The last cell whose cdf start is <= i / n (a guide table, Chen and
    /// Asau 1974): where the search for u in [i/n, (i+1)/n) starts.
    guide: u32,
}

/// A density proportional to `func` over n equal cells of [0, 1).
#[derive(Clone, Debug)]
pub struct Piecewise1D {
    /// n + 1 entries, the last holding only the cdf's end. Interleaved, so
    /// that a sample's guide entry, cdf and value share cache lines: a
    /// binary search over a random row of a 2048-wide environment map
    /// missed the cache at every step (31% of path tracing's time on
    /// Bitterli's living room, docs/performance.md).
    cells: Vec<Cell>,
    /// ∫_0^1 func.
    pub integral: f32,
}

impl Piecewise1D {
    /// The density of `func` (non-negative; all zero gives the uniform one).
    pub fn new(func: &[f32]) -> Piecewise1D {
        let n = func.len().max(1);
        let mut cdf = vec![0.0f64; n + 1];
        for i in 0..n {
            cdf[i + 1] = cdf[i] + func.get(i).copied().unwrap_or(0.0).max(0.0) as f64 / n as f64;
        }
        let integral = cdf[n];
        let cdf: Vec<f32> = if integral > 0.0 {
            cdf.iter().map(|c| (c / integral) as f32).collect()
        } else {
            (0..=n).map(|i| i as f32 / n as f32).collect()
        };
        let func: Vec<f32> = if integral > 0.0 {
            func.iter().map(|f| f.max(0.0)).collect()
        } else {
            vec![1.0; n]
        };
        let mut guide = Vec::with_capacity(n);
        let mut i = 0;
        for k in 0..n {
            let t = k as f32 / n as f32;
            while i + 1 < n && cdf[i + 1] <= t {
                i += 1;
            }
            guide.push(i as u32);
        }
        let mut cells: Vec<Cell> = (0..=n)
            .map(|i| Cell {
                cdf: cdf[i],
                func: func.get(i).copied().unwrap_or(0.0),
                guide: guide.get(i).copied().unwrap_or(0),
            })
            .collect();
        cells[n].func = 0.0;
        Piecewise1D {
            cells,
            integral: if integral > 0.0 { integral as f32 } else { 1.0 },
        }
    }

    /// Cells.
    pub fn len(&self) -> usize {
        self.cells.len() - 1
    }

    /// True for no cells (never: `new` makes at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes of the table.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.cells[..])
    }

    /// A point x with its density and cell.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let (i, t) = self.sample_cell(u);
        let x = ((i as f32 + t) / self.len() as f32).min(1.0 - f32::EPSILON);
        (x, self.cells[i].func / self.integral, i)
    }

    /// The cell of [`Piecewise1D::sample`] and where in it the point lies,
    /// as a fraction of its width: uniform there, so a second step can
    /// take it as its own number.
    #[inline]
    fn sample_cell(&self, u: f32) -> (usize, f32) {
        sample_cell(&self.cells, u)
    }

    /// The density at x.
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        let i = ((x * self.len() as f32) as usize).min(self.len() - 1);
        self.cells[i].func / self.integral
    }
}

/// [`Piecewise1D::sample_cell`] over a table's cells (n + 1 of them).
#[inline]
fn sample_cell(c: &[Cell], u: f32) -> (usize, f32) {
    // The last cell whose cdf start is <= u, from the guide's start (a step
    // back where u * n rounded up into the next entry).
    let n = c.len() - 1;
    let k = ((u * n as f32) as usize).min(n - 1);
    let mut i = c[k].guide as usize;
    while i > 0 && c[i].cdf > u {
        i -= 1;
    }
    while i + 1 < n && c[i + 1].cdf <= u {
        i += 1;
    }
    let width = c[i + 1].cdf - c[i].cdf;
    let t = if width > 0.0 {
        ((u - c[i].cdf) / width).clamp(0.0, 1.0)
    } else {
        0.5
    };
    (i, t)
}

/// Side of the square blocks of cells that [`Piecewise2D`] samples in
/// two steps.
const BLOCK: usize = 8;
const BLOCK_CELLS: usize = BLOCK * BLOCK;

/// One block's cells, row by row, as fractions of its largest in 16 bits
/// (rounded up: no positive cell becomes zero): two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(128))]
struct Block([u16; BLOCK_CELLS]);

/// A density over [0, 1)² proportional to `func` on a `width` × `height`
/// grid (rows top to bottom), sampled in two steps: a block of 8 × 8 cells
/// by its sum (a marginal over rows of blocks, a conditional per row),
/// then a cell of the block. The blocks' table is a sixty-fourth of the
/// grid, so it stays cached, and a sample then reads two lines of the
/// grid, which a caller can prefetch: for a 2048 × 1024 environment map,
/// 0.4 and 4 MB, where one table over the cells took 25 MB and two
/// dependent misses a sample. The density is that of the cells' values
/// as stored, a cell below 1/65 535 of its block's largest raised to it.
#[derive(Clone, Debug)]
pub struct Piecewise2D {
    /// The marginal over rows of blocks.
    marginal: Piecewise1D,
    /// Per row of blocks, the conditional over its blocks' sums: the
    /// [`Piecewise1D`] tables' cells, row after row in one array (one
    /// dependent load fewer than a table per row).
    conditionals: Vec<Cell>,
    /// The cells, block by block, row by row of blocks.
    blocks: Vec<Block>,
    /// Per block, the value of a stored 1 times width × height / the sum of
    /// the stored values: a cell's density over [0, 1)².
    scales: Vec<f32>,
    blocks_wide: usize,
    width: usize,
    height: usize,
}

impl Piecewise2D {
    /// The density of `func` (non-negative; all zero gives the uniform one).
    pub fn new(func: &[f32], width: usize, height: usize) -> Piecewise2D {
        use rayon::prelude::*;
        let (width, height) = (width.max(1), height.max(1));
        let uniform = !func.iter().any(|&f| f > 0.0);
        let value = |x: usize, y: usize| {
            if uniform {
                1.0
            } else {
                func.get(y * width + x).copied().unwrap_or(0.0).max(0.0)
            }
        };
        let (blocks_wide, blocks_high) = (width.div_ceil(BLOCK), height.div_ceil(BLOCK));
        // Blocks in parallel (an environment map's thousand rows were a
        // tenth of a scene's load); collected in order, so the same table.
        let (blocks, mut scales): (Vec<Block>, Vec<f32>) = (0..blocks_wide * blocks_high)
            .into_par_iter()
            .map(|b| {
                let (x0, y0) = (b % blocks_wide * BLOCK, b / blocks_wide * BLOCK);
                let cell = |k: usize| {
                    let (x, y) = (x0 + k % BLOCK, y0 + k / BLOCK);
                    if x < width && y < height {
                        value(x, y)
                    } else {
                        0.0
                    }
                };
                let largest = (0..BLOCK_CELLS).map(cell).fold(0.0f32, f32::max);
                let unit = largest / f32::from(u16::MAX);
                let block = Block(std::array::from_fn(|k| {
                    if largest > 0.0 {
                        (cell(k) / unit).ceil().min(f32::from(u16::MAX)) as u16
                    } else {
                        0
                    }
                }));
                (block, unit)
            })
            .unzip();
        let sums: Vec<f32> = blocks
            .iter()
            .zip(&scales)
            .map(|(b, unit)| block_total(b) as f32 * unit)
            .collect();
        let rows: Vec<Piecewise1D> = sums.par_chunks(blocks_wide).map(Piecewise1D::new).collect();
        let marginal = Piecewise1D::new(&rows.iter().map(|r| r.integral).collect::<Vec<_>>());
        let conditionals = rows.into_iter().flat_map(|r| r.cells).collect();
        let total: f64 = sums.iter().map(|&s| s as f64).sum();
        // (Zero where every block's unit underflowed: no density, no NaN.)
        let per_cell = if total > 0.0 {
            (width * height) as f64 / total
        } else {
            0.0
        };
        for unit in &mut scales {
            *unit = (*unit as f64 * per_cell) as f32;
        }
        Piecewise2D {
            marginal,
            conditionals,
            blocks,
            scales,
            blocks_wide,
            width,
            height,
        }
    }

    /// Bytes of the tables.
    pub fn memory_bytes(&self) -> usize {
        self.marginal.memory_bytes()
            + std::mem::size_of_val(&self.conditionals[..])
            + std::mem::size_of_val(&self.blocks[..])
            + std::mem::size_of_val(&self.scales[..])
    }

    /// The block of a sample for `u`, and where in it the point lies.
    #[inline]
    fn sample_block(&self, u: Vec2) -> (usize, Vec2) {
        let (row, ty) = self.marginal.sample_cell(u.y);
        let stride = self.blocks_wide + 1;
        let (column, tx) = sample_cell(&self.conditionals[row * stride..(row + 1) * stride], u.x);
        (row * self.blocks_wide + column, Vec2::new(tx, ty))
    }

    /// A point (x, y) and its density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (b, t) = self.sample_block(u);
        let cells = &self.blocks[b].0;
        let row_sums: [u32; BLOCK] =
            std::array::from_fn(|r| row_of(cells, r).iter().map(|&q| u32::from(q)).sum());
        let (r, ty) = pick(&row_sums, t.y);
        let row: [u32; BLOCK] = std::array::from_fn(|c| u32::from(row_of(cells, r)[c]));
        let (c, tx) = pick(&row, t.x);
        let x = (b % self.blocks_wide * BLOCK + c) as f32 + tx;
        let y = (b / self.blocks_wide * BLOCK + r) as f32 + ty;
        let p = Vec2::new(
            (x / self.width as f32).min(1.0 - f32::EPSILON),
            (y / self.height as f32).min(1.0 - f32::EPSILON),
        );
        (p, f32::from(cells[r * BLOCK + c]) * self.scales[b])
    }

    /// Asks the cache for the block that [`Piecewise2D::sample`] reads for
    /// `u` (the blocks' table, small, stays cached).
    #[inline(always)]
    pub fn prefetch(&self, u: Vec2) {
        let (b, _) = self.sample_block(u);
        let cells = &self.blocks[b].0;
        crate::math::prefetch(&cells[0]);
        crate::math::prefetch(&cells[BLOCK_CELLS / 2]);
        crate::math::prefetch(&self.scales[b]);
    }

    /// The density at `p`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let x = ((p.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((p.y * self.height as f32) as usize).min(self.height - 1);
        let b = y / BLOCK * self.blocks_wide + x / BLOCK;
        f32::from(self.blocks[b].0[y % BLOCK * BLOCK + x % BLOCK]) * self.scales[b]
    }
}

#[inline(always)]
fn row_of(cells: &[u16; BLOCK_CELLS], r: usize) -> &[u16] {
    &cells[r * BLOCK..(r + 1) * BLOCK]
}

fn block_total(block: &Block) -> u32 {
    block.0.iter().map(|&q| u32::from(q)).sum()
}

/// An entry of `weights` chosen with probability proportional to its
/// weight by inverting their sum at `u`, and where u fell inside it (a
/// fraction, uniform). Zero weights are never chosen while any is not.
/// The sums stay below 2^24, so exact in f32.
#[inline(always)]
fn pick(weights: &[u32; BLOCK], u: f32) -> (usize, f32) {
    let total: u32 = weights.iter().sum();
    let target = u * total as f32;
    let mut start = 0u32;
    let mut last = 0;
    for (i, &w) in weights.iter().enumerate() {
        if w > 0 {
            if target < (start + w) as f32 {
                return (i, ((target - start as f32) / w as f32).clamp(0.0, 1.0));
            }
            last = i;
        }
        start += w;
    }
    // Rounding left u * total at or past the sum: the last positive entry.
    (last, 1.0 - f32::EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_guide_finds_the_cell_a_binary_search_finds() {
        // Zero cells, a spike, and u at every cell boundary and between.
        let func: Vec<f32> = (0..97)
            .map(|i| match i % 7 {
                0 => 0.0,
                3 => 50.0,
                _ => (i as f32).sin().abs(),
            })
            .collect();
        let d = Piecewise1D::new(&func);
        let cdf: Vec<f32> = d.cells.iter().map(|c| c.cdf).collect();
        let mut us: Vec<f32> = cdf.clone();
        us.extend((0..10_000).map(|j| j as f32 / 10_000.0));
        us.push(1.0 - f32::EPSILON);
        for u in us.into_iter().filter(|u| *u < 1.0) {
            let expected = cdf.partition_point(|&c| c <= u).clamp(1, func.len()) - 1;
            assert_eq!(d.sample(u).2, expected, "u {u}");
        }
    }

    #[test]
    fn samples_follow_the_density() {
        let d = Piecewise1D::new(&[1.0, 0.0, 3.0, 4.0]);
        assert_eq!(d.pdf(0.3), 0.0);
        assert!((d.pdf(0.9) - 4.0 / 2.0).abs() < 1e-6);
        let (x, pdf, i) = d.sample(0.4);
        assert_eq!(i, 2);
        assert!((x - (0.5 + 0.25 * (0.4 - 0.125) / 0.375)).abs() < 1e-5);
        assert!((pdf - 1.5).abs() < 1e-6);
        // A 2D density integrates to one over its cells.
        let f = [1.0, 2.0, 0.0, 5.0, 1.0, 1.0];
        let d2 = Piecewise2D::new(&f, 3, 2);
        let mut total = 0.0;
        for y in 0..2 {
            for x in 0..3 {
                total += d2.pdf(Vec2::new((x as f32 + 0.5) / 3.0, (y as f32 + 0.5) / 2.0)) / 6.0;
            }
        }
        assert!((total - 1.0).abs() < 1e-5);
        let (p, pdf) = d2.sample(Vec2::new(0.3, 0.7));
        assert!((pdf - d2.pdf(p)).abs() < 1e-5);
    }

    /// The two steps (a block, then a cell in it) sample each cell of a
    /// grid that is no multiple of the block, with zeros and a spike 10^5
    /// times the rest, with the density `pdf` gives, and that density is
    /// the function's to its 16-bit rounding.
    #[test]
    fn blocks_then_cells_follow_the_density() {
        use crate::lab::stats::ChiSquare;
        use crate::sampling::hash::{hash_combine, to_unit_float};
        let (w, h) = (13, 11);
        let func: Vec<f32> = (0..w * h)
            .map(|i| match i {
                40 => 1e5,
                _ if i % 5 == 0 => 0.0,
                _ => 1.0 + (i as f32 * 0.37).sin(),
            })
            .collect();
        let d = Piecewise2D::new(&func, w, h);
        let total: f64 = func.iter().map(|&f| f as f64).sum();
        let center = |i: usize| {
            Vec2::new(
                ((i % w) as f32 + 0.5) / w as f32,
                ((i / w) as f32 + 0.5) / h as f32,
            )
        };
        let mut mass = 0.0;
        for (i, &f) in func.iter().enumerate() {
            let pdf = d.pdf(center(i)) as f64;
            mass += pdf / (w * h) as f64;
            // A cell's stored value is its own rounded up, by at most
            // 1/65 535 of its block's largest (the spike's), which raises
            // the total by at most a block of such steps.
            let exact = f as f64 * (w * h) as f64 / total;
            let step = 1e5 / 65_535.0;
            let low = exact * total / (total + 64.0 * step);
            let high = exact + step * (w * h) as f64 / total;
            assert!(
                pdf >= low * (1.0 - 1e-5) && pdf <= high * (1.0 + 1e-5),
                "cell {i}: {pdf} against {exact}"
            );
        }
        assert!((mass - 1.0).abs() < 1e-4, "mass {mass}");
        // 400 000 samples; at a 0.1% significance a correct sampler fails
        // with probability 0.001, and with the seed fixed never once it
        // passes.
        let n = 400_000u64;
        let mut observed = vec![0.0; w * h];
        for k in 0..n {
            let key = hash_combine(11, k);
            let u = Vec2::new(to_unit_float(key), to_unit_float(hash_combine(key, 1)));
            let (p, pdf) = d.sample(u);
            assert_eq!(pdf, d.pdf(p), "u {u}");
            let cell = ((p.y * h as f32) as usize) * w + (p.x * w as f32) as usize;
            assert!(func[cell] > 0.0, "a zero cell sampled at u {u}");
            observed[cell] += 1.0;
        }
        let expected: Vec<f64> = (0..w * h)
            .map(|i| d.pdf(center(i)) as f64 / (w * h) as f64 * n as f64)
            .collect();
        let test = ChiSquare::test(&observed, &expected);
        assert!(
            test.passes(1e-3),
            "chi2 {} with {} dof, p {}",
            test.chi2,
            test.dof,
            test.p_value
        );
    }
}
