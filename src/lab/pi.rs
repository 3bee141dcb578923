//! π by darts: N points in the unit square from the renderer's samplers,
//! π ≈ 4 · (points in the quarter disc) / N, and the RMSE of many runs.

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::stats::{PointSet, log_log_slope, sampler_color};
use super::{Cancelled, LabSettings, Progress, one_two_five};
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use rayon::prelude::*;
use std::f64::consts::PI;

pub const TEXT: &str = "Throw N darts at the unit square; the fraction that lands inside the \
quarter disc x² + y² < 1 estimates its area π/4. Each dart is a Bernoulli trial of variance \
p(1 − p) with p = π/4, so the RMSE of 4·inside/N is √(π(4 − π)/N): slope −1/2 on the log-log \
plot, whatever the dimension. Stratified, multi-jittered and Sobol points place the darts \
more evenly; only the strata the circle crosses contribute error, about √N of them, so \
their error falls as N^(-3/4) (slopes printed below). The renderer uses these very points \
for pixel positions, where edges play the role of the circle.";

/// The RMSE of one run's estimate with independent darts.
pub fn independent_rmse(n: u32) -> f64 {
    (PI * (4.0 - PI) / n as f64).sqrt()
}

/// 4 · (points of `points` in the quarter disc) / n.
fn estimate(points: &mut PointSet, n: u32) -> f64 {
    let inside = (0..n)
        .filter(|&i| points.point_2d(i).length_squared() < 1.0)
        .count();
    4.0 * inside as f64 / n as f64
}

/// Darts at N = 1, 2, 5, ... up to `settings.n`, `settings.runs` runs per N and sampler.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let counts = one_two_five(1, settings.n.max(1));
    let runs = settings.runs.max(2);
    progress.plan(
        counts.iter().map(|&n| n as u64).sum::<u64>() * runs as u64 * SamplerKind::ALL.len() as u64,
    );
    let mut table = Table {
        title: format!(
            "RMSE of 4 * inside / N over {runs} runs; estimate of one run ({})",
            settings.sampler.name()
        ),
        columns: ["N", "estimate"]
            .into_iter()
            .map(String::from)
            .chain(
                SamplerKind::ALL
                    .iter()
                    .map(|k| format!("RMSE {}", k.name())),
            )
            .chain(["sqrt(pi(4-pi)/N)", "independent / theory"].map(String::from))
            .collect(),
        rows: Vec::new(),
    };
    let mut curves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SamplerKind::ALL.len()];
    let mut theory = Vec::new();
    let mut report = Report {
        stages_planned: counts.len() as u32,
        ..Report::default()
    };
    for &n in &counts {
        let seed = hash_combine(settings.seed, n as u64);
        let mut row = vec![Cell::int(n as u64)];
        let mut one_run = PointSet::new(settings.sampler, seed, 0, n);
        row.push(Cell::fixed(estimate(&mut one_run, n), 6));
        for (k, &kind) in SamplerKind::ALL.iter().enumerate() {
            let squared_error: f64 = (0..runs)
                .into_par_iter()
                .map(|run| {
                    let mut points = PointSet::new(kind, seed, run, n);
                    let e = estimate(&mut points, n) - PI;
                    progress.advance(n as u64)?;
                    Ok(e * e)
                })
                .try_reduce(|| 0.0, |a, b| Ok(a + b))?;
            let rmse = (squared_error / runs as f64).sqrt();
            curves[k].push((n as f64, rmse));
            row.push(Cell::sci(rmse));
        }
        let expected = independent_rmse(n);
        theory.push((n as f64, expected));
        row.push(Cell::sci(expected));
        row.push(Cell::fixed(
            curves[0].last().map_or(0.0, |p| p.1) / expected,
            4,
        ));
        table.rows.push(row);

        report.stages_done += 1;
        report.tables = vec![table.clone(), slopes(&curves)];
        report.figures = vec![
            scatter(settings.sampler, seed, n),
            error_figure(&curves, &theory),
        ];
        progress.publish(&report);
    }
    if let Some(at) = counts.iter().position(|&n| n == 10_000) {
        let ratio = curves[0][at].1 / theory[at].1;
        report.checks.push(Check {
            statement: "independent RMSE at N = 10^4 within 5% of sqrt(pi(4-pi)/N)".into(),
            measured: format!(
                "{:.5} against {:.5} (ratio {ratio:.4})",
                curves[0][at].1, theory[at].1
            ),
            holds: (ratio - 1.0).abs() < 0.05,
        });
        for (k, kind) in SamplerKind::ALL.iter().enumerate().skip(1) {
            report.checks.push(Check {
                statement: format!("{} beats independent at N = 10^4", kind.name()),
                measured: format!(
                    "RMSE {:.3e} against {:.3e}",
                    curves[k][at].1, curves[0][at].1
                ),
                holds: curves[k][at].1 < curves[0][at].1,
            });
        }
    }
    Ok(report)
}

/// Fitted slopes of log RMSE against log N from N = 10 on.
fn slopes(curves: &[Vec<(f64, f64)>]) -> Table {
    Table {
        title: "Fitted slope of log RMSE against log N (N >= 10)".into(),
        columns: vec!["sampler".into(), "slope".into()],
        rows: SamplerKind::ALL
            .iter()
            .zip(curves)
            .map(|(kind, curve)| {
                let fit: Vec<(f64, f64)> = curve.iter().copied().filter(|p| p.0 >= 10.0).collect();
                vec![Cell::text(kind.name()), Cell::fixed(log_log_slope(&fit), 3)]
            })
            .collect(),
    }
}

/// Most darts a scatter plot shows (the first ones of the set).
const SHOWN: u32 = 20_000;

/// One run's darts, inside and outside, and the quarter circle.
fn scatter(kind: SamplerKind, seed: u64, n: u32) -> Figure {
    let mut points = PointSet::new(kind, seed, 0, n);
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for i in 0..n.min(SHOWN) {
        let p = points.point_2d(i);
        let xy = (p.x as f64, p.y as f64);
        if p.length_squared() < 1.0 {
            inside.push(xy);
        } else {
            outside.push(xy);
        }
    }
    let arc: Vec<(f64, f64)> = (0..=64)
        .map(|i| {
            let a = i as f64 / 64.0 * PI / 2.0;
            (a.cos(), a.sin())
        })
        .collect();
    Figure::linear(
        if n > SHOWN {
            format!("the first {SHOWN} of {n} darts ({})", kind.name())
        } else {
            format!("{n} darts ({})", kind.name())
        },
        ("x", "y"),
        (0.0, 1.0),
        (0.0, 1.0),
        vec![
            Series::new("inside", SeriesStyle::Points, 0, &inside),
            Series::new("outside", SeriesStyle::Points, 1, &outside),
            Series::new("x^2 + y^2 = 1", SeriesStyle::Guide, 7, &arc),
        ],
    )
}

fn error_figure(curves: &[Vec<(f64, f64)>], theory: &[(f64, f64)]) -> Figure {
    let mut series: Vec<Series> = SamplerKind::ALL
        .iter()
        .zip(curves)
        .map(|(kind, c)| Series::new(kind.name(), SeriesStyle::Line, sampler_color(*kind), c))
        .collect();
    series.push(Series::new(
        "sqrt(pi(4-pi)/N)",
        SeriesStyle::Guide,
        7,
        theory,
    ));
    Figure::log_log("RMSE of the estimate of pi", "N", "RMSE", series)
}
