//! Stratified against unstratified: ∫₀¹ e^{sin 3x²} dx with the renderer's
//! samplers in one dimension, the lecture's table and the RMSE of many runs.

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::stats::{PointSet, integrate, log_log_slope, sampler_color};
use super::{Cancelled, LabSettings, Progress};
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use rayon::prelude::*;

pub const TEXT: &str = "Estimate ∫₀¹ e^{sin 3x²} dx = 1.7760990452 by the average of f at N \
points. Independent points give an RMSE of σ/√N (σ = 0.600215 for one sample): slope −0.5. \
Jittered points, one in each of N equal strata, leave in each stratum only the variation of \
f across it, about f'·(1/N); N such errors of size 1/N² in variance add up to 1/N³, so the \
RMSE falls as N^(-1.5) on this smooth integrand. The lecture's O(1/N) is the bound for an \
integrand with jumps, where the strata the jump crosses dominate. In one dimension a Latin \
hypercube and a jittered set are the same thing (one point per stratum): the multi-jittered \
sampler gives the stratified sampler's numbers here, number for number. Owen-scrambled Sobol reaches N^(-1.5) at powers of two and is slower at N = 10^k, where its \
prefix is not a complete net.";

/// The integral the lecture quotes.
pub const INTEGRAL: f64 = 1.776_099_045_2;

/// The integrand.
#[inline]
pub fn integrand(x: f64) -> f64 {
    (3.0 * x * x).sin().exp()
}

/// The samplers compared, with the names the lab gives them in 1D.
const SAMPLERS: [(SamplerKind, &str); 4] = [
    (SamplerKind::Independent, "independent"),
    (SamplerKind::Stratified, "jittered"),
    (SamplerKind::MultiJittered, "Latin hypercube"),
    (SamplerKind::Sobol, "Owen-scrambled Sobol"),
];

/// (1/N) Σ f(xᵢ) over the N-point set of `run`.
fn estimate(kind: SamplerKind, seed: u64, run: u32, n: u32) -> f64 {
    let mut points = PointSet::new(kind, seed, run, n);
    (0..n)
        .map(|i| integrand(points.number_1d(i) as f64))
        .sum::<f64>()
        / n as f64
}

/// N = 1, 10, 100, ... up to `settings.n`, `settings.runs` runs per sampler.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let counts: Vec<u32> = (0..10)
        .map(|k| 10u32.pow(k))
        .filter(|&n| n <= settings.n.max(1))
        .collect();
    let runs = settings.runs.max(2);
    progress
        .plan(counts.iter().map(|&n| n as u64).sum::<u64>() * runs as u64 * SAMPLERS.len() as u64);
    let exact = integrate(integrand, 0.0, 1.0, 4096);
    let sigma = (integrate(|x| integrand(x).powi(2), 0.0, 1.0, 4096) - exact * exact).sqrt();
    let mut lecture = Table {
        title: format!("The lecture's table: one run each (the integral is {exact:.10})"),
        columns: [
            "N",
            "unstratified",
            "stratified",
            "|error| unstratified",
            "|error| stratified",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let mut rmse_table = Table {
        title: format!("RMSE over {runs} runs (sigma of one uniform sample {sigma:.6})"),
        columns: std::iter::once("N".to_string())
            .chain(SAMPLERS.iter().map(|(_, name)| name.to_string()))
            .chain(["sigma/sqrt(N)".to_string(), "mean jittered - I".to_string()])
            .collect(),
        rows: Vec::new(),
    };
    let mut curves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SAMPLERS.len()];
    let mut guide = Vec::new();
    let mut jittered_mean_error = f64::NAN;
    let mut report = Report {
        stages_planned: counts.len() as u32,
        ..Report::default()
    };
    for &n in &counts {
        let seed = hash_combine(settings.seed, n as u64);
        let unstratified = estimate(SamplerKind::Independent, seed, 0, n);
        let stratified = estimate(SamplerKind::Stratified, seed, 0, n);
        lecture.rows.push(vec![
            Cell::int(n as u64),
            Cell::fixed(unstratified, 10),
            Cell::fixed(stratified, 10),
            Cell::sci((unstratified - exact).abs()),
            Cell::sci((stratified - exact).abs()),
        ]);
        let mut row = vec![Cell::int(n as u64)];
        for (k, &(kind, _)) in SAMPLERS.iter().enumerate() {
            let (sum, squared): (f64, f64) = (0..runs)
                .into_par_iter()
                .map(|run| {
                    let e = estimate(kind, seed, run, n) - exact;
                    progress.advance(n as u64)?;
                    Ok((e, e * e))
                })
                .try_reduce(|| (0.0, 0.0), |a, b| Ok((a.0 + b.0, a.1 + b.1)))?;
            let rmse = (squared / runs as f64).sqrt();
            curves[k].push((n as f64, rmse));
            row.push(Cell::sci(rmse));
            if kind == SamplerKind::Stratified {
                jittered_mean_error = sum / runs as f64;
            }
        }
        guide.push((n as f64, sigma / (n as f64).sqrt()));
        row.push(Cell::sci(sigma / (n as f64).sqrt()));
        row.push(Cell::sci(jittered_mean_error));
        rmse_table.rows.push(row);

        report.stages_done += 1;
        report.tables = vec![lecture.clone(), rmse_table.clone(), slopes(&curves)];
        report.figures = vec![
            error_figure(&curves, &guide),
            points_figure(settings.sampler, seed, n.min(64)),
        ];
        progress.publish(&report);
    }
    if counts.last() == Some(&100_000) {
        let slope = |k: usize| {
            let fit: Vec<(f64, f64)> = curves[k].iter().copied().filter(|p| p.0 >= 10.0).collect();
            log_log_slope(&fit)
        };
        let (independent, jittered) = (slope(0), slope(1));
        report.checks.push(Check {
            statement: "independent: slope over N = 10..10^5 within -0.5 +- 0.05".into(),
            measured: format!("{independent:.3}"),
            holds: (independent + 0.5).abs() <= 0.05,
        });
        report.checks.push(Check {
            statement: "jittered: slope over N = 10..10^5 within -1.5 +- 0.1".into(),
            measured: format!("{jittered:.3}"),
            holds: (jittered + 1.5).abs() <= 0.1,
        });
        report.checks.push(Check {
            statement: "jittered at N = 10^5: the mean over runs reaches 1.7760990452 to 1e-6"
                .into(),
            measured: format!("mean - I = {jittered_mean_error:.2e}"),
            holds: jittered_mean_error.abs() < 1e-6,
        });
    }
    report.checks.push(Check {
        statement: "quadrature gives the lecture's integral 1.7760990452 and sigma 0.600215".into(),
        measured: format!("{exact:.10}, {sigma:.6}"),
        holds: (exact - INTEGRAL).abs() < 1e-10 && (sigma - 0.600_215).abs() < 1e-6,
    });
    Ok(report)
}

fn slopes(curves: &[Vec<(f64, f64)>]) -> Table {
    Table {
        title: "Fitted slope of log RMSE against log N (N >= 10)".into(),
        columns: vec!["points".into(), "slope".into()],
        rows: SAMPLERS
            .iter()
            .zip(curves)
            .map(|((_, name), curve)| {
                let fit: Vec<(f64, f64)> = curve.iter().copied().filter(|p| p.0 >= 10.0).collect();
                vec![Cell::text(*name), Cell::fixed(log_log_slope(&fit), 3)]
            })
            .collect(),
    }
}

fn error_figure(curves: &[Vec<(f64, f64)>], guide: &[(f64, f64)]) -> Figure {
    let mut series: Vec<Series> = SAMPLERS
        .iter()
        .zip(curves)
        .map(|((kind, name), c)| Series::new(name, SeriesStyle::Line, sampler_color(*kind), c))
        .collect();
    series.push(Series::new("sigma/sqrt(N)", SeriesStyle::Guide, 7, guide));
    Figure::log_log("RMSE of the integral of exp(sin 3x^2)", "N", "RMSE", series)
}

/// The integrand and the points of one run, at their f values.
fn points_figure(kind: SamplerKind, seed: u64, n: u32) -> Figure {
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|i| {
            let x = i as f64 / 200.0;
            (x, integrand(x))
        })
        .collect();
    let mut set = PointSet::new(kind, seed, 0, n);
    let points: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let x = set.number_1d(i) as f64;
            (x, integrand(x))
        })
        .collect();
    Figure::linear(
        format!("f(x) = exp(sin 3x^2) and {n} {} points", kind.name()),
        ("x", "f(x)"),
        (0.0, 1.0),
        (0.0, 3.0),
        vec![
            Series::new("f", SeriesStyle::Guide, 7, &curve),
            Series::new("samples", SeriesStyle::Points, sampler_color(kind), &points),
        ],
    )
}
