//! Piecewise-constant densities on [0, 1) and [0, 1)², sampled by
//! inverting their CDFs (pbrt's Distribution1D / 2D): the environment
//! map's importance sampling.

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
        // The last cell whose cdf start is <= u, from the guide's start
        // (a step back where u * n rounded up into the next entry).
        let c = &self.cells;
        let n = self.len();
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
        let x = ((i as f32 + t) / n as f32).min(1.0 - f32::EPSILON);
        (x, c[i].func / self.integral, i)
    }

    /// Asks the cache for the guide entry that [`Piecewise1D::sample`]
    /// reads first for `u`: a hint, for a caller that knows u early.
    #[inline(always)]
    pub fn prefetch(&self, u: f32) {
        let n = self.len();
        let k = ((u * n as f32) as usize).min(n.saturating_sub(1));
        if let Some(cell) = self.cells.get(k) {
            crate::math::prefetch(cell);
        }
    }

    /// Asks the cache for the cells that [`Piecewise1D::sample`] reads
    /// after the guide entry for `u`, which must be cached by now (a
    /// [`Piecewise1D::prefetch`] some time before): where one cell holds
    /// much of the mass, the guide points far from its own entry.
    #[inline(always)]
    pub fn prefetch_guided(&self, u: f32) {
        let n = self.len();
        let k = ((u * n as f32) as usize).min(n.saturating_sub(1));
        if let Some(cell) = self.cells.get(k) {
            let i = cell.guide as usize;
            if let Some(first) = self.cells.get(i) {
                crate::math::prefetch(first);
            }
            if let Some(next) = self.cells.get(i + 1) {
                crate::math::prefetch(next);
            }
        }
    }

    /// The density at x.
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        let i = ((x * self.len() as f32) as usize).min(self.len() - 1);
        self.cells[i].func / self.integral
    }
}

/// A density over [0, 1)² proportional to `func` on a `width` × `height`
/// grid (rows top to bottom): a marginal over rows, a conditional per row.
#[derive(Clone, Debug)]
pub struct Piecewise2D {
    rows: Vec<Piecewise1D>,
    marginal: Piecewise1D,
}

impl Piecewise2D {
    pub fn new(func: &[f32], width: usize, height: usize) -> Piecewise2D {
        use rayon::prelude::*;
        // Rows in parallel (an environment map's thousand rows were a tenth
        // of a scene's load); collected in order, so the same table.
        let rows: Vec<Piecewise1D> = (0..height)
            .into_par_iter()
            .map(|y| Piecewise1D::new(&func[y * width..(y + 1) * width]))
            .collect();
        let marginal = Piecewise1D::new(&rows.iter().map(|r| r.integral).collect::<Vec<_>>());
        Piecewise2D { rows, marginal }
    }

    /// Bytes of the tables.
    pub fn memory_bytes(&self) -> usize {
        self.marginal.memory_bytes()
            + self
                .rows
                .iter()
                .map(Piecewise1D::memory_bytes)
                .sum::<usize>()
    }

    /// A point (x, y) and its density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pdf_y, row) = self.marginal.sample(u.y);
        let (x, pdf_x, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, y), pdf_x * pdf_y)
    }

    /// Asks the cache for the row entry that [`Piecewise2D::sample`] reads
    /// first for `u` (the marginal, small, stays cached).
    #[inline(always)]
    pub fn prefetch(&self, u: Vec2) {
        let (_, _, row) = self.marginal.sample(u.y);
        self.rows[row].prefetch(u.x);
    }

    /// The second step of [`Piecewise2D::prefetch`], some time after it:
    /// the cells its row's guide entry points at.
    #[inline(always)]
    pub fn prefetch_guided(&self, u: Vec2) {
        let (_, _, row) = self.marginal.sample(u.y);
        self.rows[row].prefetch_guided(u.x);
    }

    /// The density at `p`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let row = ((p.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        self.marginal.pdf(p.y) * self.rows[row].pdf(p.x)
    }
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
}
