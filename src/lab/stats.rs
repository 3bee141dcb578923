//! Statistics the lab (and the chi-square tests in `tests/chi2.rs`) need:
//! running moments, log-log slopes, quadrature, the χ² goodness-of-fit test,
//! and point sets drawn from the renderer's samplers.

use crate::sampling::{Sampler, SamplerKind};
use glam::Vec2;
use std::f64::consts::PI;

/// Mean and variance by Welford's update, in f64.
#[derive(Clone, Copy, Debug, Default)]
pub struct Moments {
    pub count: u64,
    pub mean: f64,
    m2: f64,
}

impl Moments {
    #[inline]
    pub fn add(&mut self, x: f64) {
        self.count += 1;
        let delta = x - self.mean;
        self.mean += delta / self.count as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// Merges another accumulator (Chan et al.), for parallel runs.
    pub fn merge(mut self, other: Moments) -> Moments {
        if other.count == 0 {
            return self;
        }
        if self.count == 0 {
            return other;
        }
        let n = (self.count + other.count) as f64;
        let delta = other.mean - self.mean;
        self.m2 += other.m2 + delta * delta * self.count as f64 * other.count as f64 / n;
        self.mean += delta * other.count as f64 / n;
        self.count += other.count;
        self
    }

    /// Unbiased sample variance.
    pub fn variance(&self) -> f64 {
        if self.count < 2 {
            0.0
        } else {
            self.m2 / (self.count - 1) as f64
        }
    }

    /// Standard error of the mean.
    pub fn standard_error(&self) -> f64 {
        (self.variance() / self.count.max(1) as f64).sqrt()
    }
}

/// Least-squares slope of log y against log x (points with x, y > 0).
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// ∫ₐᵇ f by composite Gauss–Legendre (5 points on each of `panels` panels):
/// exact for polynomials of degree 9 per panel, so smooth integrands reach
/// f64 precision with a few thousand panels.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    const NODES: [f64; 5] = [
        0.0,
        -0.538_469_310_105_683,
        0.538_469_310_105_683,
        -0.906_179_845_938_664,
        0.906_179_845_938_664,
    ];
    const WEIGHTS: [f64; 5] = [
        0.568_888_888_888_889,
        0.478_628_670_499_366,
        0.478_628_670_499_366,
        0.236_926_885_056_189,
        0.236_926_885_056_189,
    ];
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for i in 0..panels {
        let mid = a + (i as f64 + 0.5) * h;
        for (x, w) in NODES.iter().zip(WEIGHTS) {
            sum += w * f(mid + 0.5 * h * x);
        }
    }
    sum * 0.5 * h
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x): the χ² survival function is
/// Q(dof / 2, χ² / 2). Series for x < a + 1, else Lentz's continued fraction.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (1.0 - sum * prefactor).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        prefactor * h
    }
}

/// The outcome of a χ² goodness-of-fit test.
#[derive(Clone, Copy, Debug)]
pub struct ChiSquare {
    pub chi2: f64,
    pub dof: usize,
    /// Probability of a χ² this large if the samples follow the pdf.
    pub p_value: f64,
    /// Samples in cells the pdf gives (almost) nothing: more than a few is
    /// a failure whatever the p-value (a sampler that leaves its domain).
    pub stray: f64,
    pub stray_expected: f64,
}

impl ChiSquare {
    /// Pearson's test of `observed` against `expected` counts. Cells expecting
    /// fewer than 5 samples are pooled into one (Nori's and Mitsuba's rule).
    pub fn test(observed: &[f64], expected: &[f64]) -> ChiSquare {
        let mut cells: Vec<(f64, f64)> = observed
            .iter()
            .copied()
            .zip(expected.iter().copied())
            .collect();
        cells.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (mut chi2, mut dof) = (0.0, 0usize);
        let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
        for (o, e) in cells {
            if e < 5.0 {
                pooled_obs += o;
                pooled_exp += e;
                continue;
            }
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
        let (mut stray, mut stray_expected) = (0.0, 0.0);
        if pooled_exp >= 5.0 {
            chi2 += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
            dof += 1;
        } else {
            stray = pooled_obs;
            stray_expected = pooled_exp;
        }
        let dof = dof.saturating_sub(1).max(1);
        ChiSquare {
            chi2,
            dof,
            p_value: gamma_q(dof as f64 / 2.0, chi2 / 2.0),
            stray,
            stray_expected,
        }
    }

    /// Whether the test accepts at significance `alpha`.
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value > alpha && self.stray <= 2.0 + 3.0 * self.stray_expected
    }
}

/// The per-test significance that keeps the chance of any false rejection
/// among `tests` independent tests at `alpha` (Šidák).
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// Point `i` of the `n`-point set number `run` of the renderer's sampler
/// `kind`: exactly the numbers a pixel (`run`) gets for its sample `i` in
/// dimension 0 when rendering `n` samples per pixel.
pub struct PointSet {
    sampler: Sampler,
    run: u32,
}

impl PointSet {
    /// The point set of `n` points for `run` (a different pixel per run).
    pub fn new(kind: SamplerKind, seed: u64, run: u32, n: u32) -> PointSet {
        PointSet {
            sampler: Sampler::new(kind, seed, n),
            run,
        }
    }

    /// The 2D point `i` (the sampler's first pair).
    #[inline]
    pub fn point_2d(&mut self, i: u32) -> Vec2 {
        self.sampler.start(self.run, i);
        self.sampler.next_2d()
    }

    /// The 1D number `i` (the sampler's first dimension).
    #[inline]
    pub fn number_1d(&mut self, i: u32) -> f32 {
        self.sampler.start(self.run, i);
        self.sampler.next_1d()
    }
}

/// The colour index a sampler has in every lab figure.
pub fn sampler_color(kind: SamplerKind) -> usize {
    SamplerKind::ALL
        .iter()
        .position(|k| *k == kind)
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_slope_and_gamma_are_right() {
        let i = integrate(|x| x.exp(), 0.0, 1.0, 8);
        assert!((i - (1f64.exp() - 1.0)).abs() < 1e-13, "{i}");
        let points: Vec<(f64, f64)> = (1..6).map(|k| (k as f64, (k as f64).powf(-1.5))).collect();
        assert!((log_log_slope(&points) + 1.5).abs() < 1e-12);
        // χ² with 2 dof: Q(1, x/2) = exp(-x/2).
        assert!((gamma_q(1.0, 3.0) - (-3f64).exp()).abs() < 1e-12);
        assert!((gamma_q(1.0, 0.2) - (-0.2f64).exp()).abs() < 1e-12);
        let mut a = Moments::default();
        let mut b = Moments::default();
        for x in [1.0, 2.0, 4.0] {
            a.add(x);
        }
        for x in [8.0, 16.0] {
            b.add(x);
        }
        let m = a.merge(b);
        assert!((m.mean - 6.2).abs() < 1e-12 && (m.variance() - 37.2).abs() < 1e-9);
    }
}
