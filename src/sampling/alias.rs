//! Walker's alias method (Vose's construction): O(1) sampling of a discrete
//! distribution, used to pick a light in proportion to its power.

/// One column of the table: keep `index` with probability `threshold`,
/// otherwise take `alias`.
#[derive(Clone, Copy, Debug)]
struct Bin {
    threshold: f32,
    alias: u32,
    pmf: f32,
}

/// Discrete distribution over `0..n` with O(1) sampling and pmf lookup.
#[derive(Clone, Debug, Default)]
pub struct AliasTable {
    bins: Vec<Bin>,
}

impl AliasTable {
    /// Builds the table from non-negative weights. Returns `None` when the
    /// weights are empty, contain a non-finite value or sum to zero.
    pub fn new(weights: &[f32]) -> Option<Self> {
        let total: f64 = weights.iter().map(|&w| w as f64).sum();
        if weights.is_empty()
            || !total.is_finite()
            || total <= 0.0
            || weights.iter().any(|&w| w < 0.0)
        {
            return None;
        }
        let n = weights.len();
        let mut scaled: Vec<f64> = weights
            .iter()
            .map(|&w| w as f64 / total * n as f64)
            .collect();
        let mut bins: Vec<Bin> = weights
            .iter()
            .enumerate()
            .map(|(i, &w)| Bin {
                threshold: 1.0,
                alias: i as u32,
                pmf: (w as f64 / total) as f32,
            })
            .collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
            bins[s].threshold = scaled[s] as f32;
            bins[s].alias = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Whatever is left holds probability one up to rounding.
        for i in small.into_iter().chain(large) {
            bins[i].threshold = 1.0;
        }
        Some(AliasTable { bins })
    }

    /// Number of outcomes.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// True when there are no outcomes.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Probability of outcome `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.bins[i].pmf
    }

    /// Picks an outcome from one uniform number in [0, 1); returns it with its probability.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.bins.len();
        let scaled = u * n as f32;
        let column = (scaled as usize).min(n - 1);
        let remainder = scaled - column as f32;
        let bin = self.bins[column];
        let i = if remainder < bin.threshold {
            column
        } else {
            bin.alias as usize
        };
        (i, self.bins[i].pmf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequencies_match_weights() {
        let weights = [1.0, 0.0, 3.0, 0.5, 5.5];
        let table = AliasTable::new(&weights).unwrap();
        let n = 200_000;
        let mut counts = [0u32; 5];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (i, p) = table.sample(u);
            assert_eq!(p, table.pmf(i));
            counts[i] += 1;
        }
        let total: f32 = weights.iter().sum();
        for i in 0..5 {
            let expected = weights[i] / total;
            assert!(
                (counts[i] as f32 / n as f32 - expected).abs() < 1e-3,
                "{counts:?}"
            );
            assert!((table.pmf(i) - expected).abs() < 1e-6);
        }
    }

    #[test]
    fn rejects_degenerate_weights() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, f32::NAN]).is_none());
    }
}
