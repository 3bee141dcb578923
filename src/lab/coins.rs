//! Coin flips: the mean absolute error of the average of n fair flips,
//! exact (by enumerating the binomial) and simulated with the renderer's
//! independent sampler (a flip is heads when its number is below 1/2).

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::stats::{Moments, PointSet};
use super::{Cancelled, LabSettings, Progress, powers_of_two};
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use rayon::prelude::*;

pub const TEXT: &str = "Flip n fair coins and take the fraction of heads: how far is it from 1/2 \
on average? The exact column enumerates all 2^n outcomes; the simulated one averages many runs \
of flips drawn from the renderer's independent sampler. From n = 1 to 2 the error halves \
(0.5 to 0.25), but from 2 to 4 it only drops to 0.1875, and after that each doubling divides \
it by about √2 = 1.41 (last column, 0.707): the error of an average falls as 1/√n, tending \
to √(1/(2πn)) ≈ 0.3989/√n. To halve the noise of a render you need four times the samples.";

/// The limit √(1/(2π)) of √n E|mean − 1/2| (the mean absolute deviation of
/// a normal of standard deviation 1/2 is (1/2)√(2/π)).
pub const LIMIT: f64 = 0.398_942_280_401_432_7;

/// E|k/n − 1/2| for k ~ Binomial(n, 1/2), summed over k with the pmf built
/// by its ratio pmf(k+1)/pmf(k) = (n−k)/(k+1) in log space (no overflow at n = 1024).
pub fn exact_mean_absolute_error(n: u32) -> f64 {
    let n_f = n as f64;
    let mut ln_pmf = -n_f * std::f64::consts::LN_2;
    let mut sum = 0.0;
    for k in 0..=n {
        sum += ln_pmf.exp() * (k as f64 / n_f - 0.5).abs();
        ln_pmf += ((n - k) as f64 / (k + 1) as f64).ln();
    }
    sum
}

/// Runs `runs` simulations for every n = 1, 2, 4, ... up to `settings.n`.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let counts = powers_of_two(1, settings.n.max(1));
    let runs = settings.runs.max(2);
    progress.plan(counts.iter().map(|&n| n as u64 * runs as u64).sum());
    let mut table = Table {
        title: format!("Mean absolute error of the average of n fair flips ({runs} runs)"),
        columns: [
            "n",
            "exact",
            "simulated",
            "std. error",
            "|sim - exact| / s.e.",
            "0.3989/sqrt(n)",
            "exact * sqrt(n)",
            "err(n)/err(n/2)",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let (mut exact_curve, mut simulated_curve, mut limit_curve) = (vec![], vec![], vec![]);
    let mut report = Report {
        stages_planned: counts.len() as u32,
        ..Report::default()
    };
    let mut previous_exact = None;
    let mut worst_deviation: f64 = 0.0;
    for &n in &counts {
        let seed = hash_combine(settings.seed, n as u64);
        let moments = (0..runs)
            .into_par_iter()
            .map(|run| {
                let mut flips = PointSet::new(SamplerKind::Independent, seed, run, n);
                let heads = (0..n).filter(|&i| flips.number_1d(i) < 0.5).count();
                progress.advance(n as u64)?;
                Ok((heads as f64 / n as f64 - 0.5).abs())
            })
            .try_fold(Moments::default, |mut m, e: Result<f64, Cancelled>| {
                m.add(e?);
                Ok(m)
            })
            .try_reduce(Moments::default, |a, b| Ok(a.merge(b)))?;
        let exact = exact_mean_absolute_error(n);
        let se = moments.standard_error();
        let deviation = (moments.mean - exact).abs() / se.max(1e-300);
        worst_deviation = worst_deviation.max(deviation);
        let limit = LIMIT / (n as f64).sqrt();
        table.rows.push(vec![
            Cell::int(n as u64),
            Cell::fixed(exact, 6),
            Cell::fixed(moments.mean, 6),
            Cell::fixed(se, 6),
            Cell::fixed(deviation, 2),
            Cell::fixed(limit, 6),
            Cell::fixed(exact * (n as f64).sqrt(), 6),
            match previous_exact {
                Some(p) => Cell::fixed(exact / p, 4),
                None => Cell::text("-"),
            },
        ]);
        previous_exact = Some(exact);
        exact_curve.push((n as f64, exact));
        simulated_curve.push((n as f64, moments.mean));
        limit_curve.push((n as f64, limit));
        report.stages_done += 1;
        report.tables = vec![table.clone()];
        report.figures = vec![Figure::log_log(
            "Error of the average of n coin flips",
            "n",
            "mean absolute error",
            vec![
                Series::new("exact", SeriesStyle::Line, 0, &exact_curve),
                Series::new("simulated", SeriesStyle::Points, 1, &simulated_curve),
                Series::new("0.3989/sqrt(n)", SeriesStyle::Guide, 7, &limit_curve),
            ],
        )];
        progress.publish(&report);
    }
    let first: Vec<f64> = [1, 2, 4]
        .into_iter()
        .map(exact_mean_absolute_error)
        .collect();
    report.checks.push(Check {
        statement: "exact error at n = 1, 2, 4 is 0.5, 0.25, 0.1875".into(),
        measured: format!("{:.6}, {:.6}, {:.6}", first[0], first[1], first[2]),
        holds: (first[0] - 0.5).abs() < 1e-12
            && (first[1] - 0.25).abs() < 1e-12
            && (first[2] - 0.1875).abs() < 1e-12,
    });
    report.checks.push(Check {
        statement: "every simulated value lies within 3 standard errors of the exact one".into(),
        measured: format!("largest deviation {worst_deviation:.2} standard errors"),
        holds: worst_deviation <= 3.0,
    });
    if let Some(&n) = counts.last() {
        let ratio = exact_mean_absolute_error(n) * (n as f64).sqrt() / LIMIT;
        report.checks.push(Check {
            statement: format!("exact error at n = {n} is within 1% of 0.3989/sqrt(n)"),
            measured: format!("ratio {ratio:.5}"),
            holds: n >= 1024 && (ratio - 1.0).abs() < 0.01,
        });
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_values_match_hand_counts() {
        assert_eq!(exact_mean_absolute_error(1), 0.5);
        assert_eq!(exact_mean_absolute_error(2), 0.25);
        assert_eq!(exact_mean_absolute_error(4), 0.1875);
        // n = 3: 0..3 heads with pmf 1/8, 3/8, 3/8, 1/8 and |k/3 - 1/2| =
        // 1/2, 1/6, 1/6, 1/2: 2 (1/16 + 1/16) = 1/4.
        assert!((exact_mean_absolute_error(3) - 0.25).abs() < 1e-15);
    }
}
