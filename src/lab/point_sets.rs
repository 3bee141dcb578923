//! The renderer's 2D point sets: scatter, periodogram and its radial
//! average, L2 star discrepancy, and the error of integrating a smooth and a
//! discontinuous function, against N.

use super::report::{Cell, Figure, Heatmap, Report, Series, SeriesStyle, Table};
use super::stats::{PointSet, integrate, log_log_slope, sampler_color};
use super::{Cancelled, LabSettings, Progress, powers_of_two};
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use glam::Vec2;
use rayon::prelude::*;
use std::f64::consts::PI;

pub const TEXT: &str = "The same N points, four ways. Independent points clump and leave holes; \
jittered points fill the strata of a grid; multi-jittered points are also one per row and \
column (Latin hypercube); Sobol points are a (0,2)-net: every power-of-two prefix is \
stratified in every elementary box. The periodogram (averaged over runs) is flat at 1 for \
independent points (white noise); the stratified sets push power away from the low \
frequencies, the ones that alias into visible noise. The L2 star discrepancy measures how \
unevenly the points fill boxes anchored at the origin; its slope is about −0.5 for \
independent points and near −1 for the nets. The error of integrating the smooth Gaussian \
falls fastest with stratification; the disc's edge (a discontinuity, like a triangle's \
silhouette in a pixel) limits every stratified set to about N^(-3/4).";

/// Highest integer frequency of the periodogram along each axis.
const FREQUENCIES: i32 = 24;
/// Standard deviation of the Gaussian integrand.
const GAUSSIAN_SIGMA: f64 = 0.15;
/// Radius of the disc integrand, centred in the square.
const DISC_RADIUS: f64 = 0.4;

fn gaussian(p: Vec2) -> f64 {
    let (x, y) = (p.x as f64 - 0.5, p.y as f64 - 0.5);
    (-(x * x + y * y) / (2.0 * GAUSSIAN_SIGMA * GAUSSIAN_SIGMA)).exp()
}

fn disc(p: Vec2) -> f64 {
    let (x, y) = (p.x as f64 - 0.5, p.y as f64 - 0.5);
    if x * x + y * y < DISC_RADIUS * DISC_RADIUS {
        1.0
    } else {
        0.0
    }
}

fn points(kind: SamplerKind, seed: u64, run: u32, n: u32) -> Vec<Vec2> {
    let mut set = PointSet::new(kind, seed, run, n);
    (0..n).map(|i| set.point_2d(i)).collect()
}

/// The L2 star discrepancy by Warnock's formula (O(N²)).
pub fn l2_star_discrepancy(points: &[Vec2]) -> f64 {
    let n = points.len() as f64;
    let p: Vec<(f64, f64)> = points.iter().map(|p| (p.x as f64, p.y as f64)).collect();
    let single: f64 = p
        .iter()
        .map(|(x, y)| (1.0 - x * x) * (1.0 - y * y) / 4.0)
        .sum();
    let mut pairs = 0.0;
    for (i, a) in p.iter().enumerate() {
        pairs += (1.0 - a.0) * (1.0 - a.1);
        for b in &p[i + 1..] {
            pairs += 2.0 * (1.0 - a.0.max(b.0)) * (1.0 - a.1.max(b.1));
        }
    }
    (1.0 / 9.0 - 2.0 / n * single + pairs / (n * n))
        .max(0.0)
        .sqrt()
}

/// |Σ e^{−2πi k·x}|² / N for integer k in [−F, F]², row-major from (−F, −F).
/// The exponentials along each axis come from one per point by recurrence.
pub fn periodogram(points: &[Vec2]) -> Vec<f64> {
    let side = (2 * FREQUENCIES + 1) as usize;
    let mut re = vec![0.0; side * side];
    let mut im = vec![0.0; side * side];
    let (mut ex, mut ey) = (vec![(0.0, 0.0); side], vec![(0.0, 0.0); side]);
    for p in points {
        for (axis, e) in [(p.x as f64, &mut ex), (p.y as f64, &mut ey)] {
            let step = (-2.0 * PI * axis).sin_cos();
            let mut value = (-2.0 * PI * axis * -(FREQUENCIES as f64)).sin_cos();
            for slot in e.iter_mut() {
                *slot = (value.1, value.0);
                value = (
                    value.0 * step.1 + value.1 * step.0,
                    value.1 * step.1 - value.0 * step.0,
                );
            }
        }
        for (j, &(yr, yi)) in ey.iter().enumerate() {
            for (i, &(xr, xi)) in ex.iter().enumerate() {
                let k = j * side + i;
                re[k] += xr * yr - xi * yi;
                im[k] += xr * yi + xi * yr;
            }
        }
    }
    let n = points.len() as f64;
    re.iter()
        .zip(&im)
        .map(|(r, i)| (r * r + i * i) / n)
        .collect()
}

/// Point sets of N = 16, 32, ... up to `settings.n`.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let counts = powers_of_two(16, settings.n.max(16));
    let runs = settings.runs.max(2);
    let discrepancy_runs = runs.min(8);
    let spectrum_runs = runs.min(16);
    let samplers = SamplerKind::ALL;
    progress.plan(
        counts.iter().map(|&n| n as u64).sum::<u64>()
            * (samplers.len() as u64 * (runs + discrepancy_runs) as u64 + spectrum_runs as u64),
    );
    let g_axis = integrate(
        |x| (-(x - 0.5) * (x - 0.5) / (2.0 * GAUSSIAN_SIGMA * GAUSSIAN_SIGMA)).exp(),
        0.0,
        1.0,
        1024,
    );
    let gaussian_exact = g_axis * g_axis;
    let disc_exact = PI * DISC_RADIUS * DISC_RADIUS;
    let k = samplers.len();
    let (mut discrepancy, mut smooth, mut edge) =
        (vec![vec![]; k], vec![vec![]; k], vec![vec![]; k]);
    let mut report = Report {
        stages_planned: counts.len() as u32,
        ..Report::default()
    };
    for &n in &counts {
        let seed = hash_combine(settings.seed, n as u64);
        for (s, &kind) in samplers.iter().enumerate() {
            let d2: f64 = (0..discrepancy_runs)
                .into_par_iter()
                .map(|run| {
                    let d = l2_star_discrepancy(&points(kind, seed, run, n));
                    progress.advance(n as u64)?;
                    Ok(d * d)
                })
                .try_reduce(|| 0.0, |a, b| Ok(a + b))?;
            discrepancy[s].push((n as f64, (d2 / discrepancy_runs as f64).sqrt()));
            let (g2, e2): (f64, f64) = (0..runs)
                .into_par_iter()
                .map(|run| {
                    let set = points(kind, seed, run, n);
                    let g =
                        set.iter().map(|&p| gaussian(p)).sum::<f64>() / n as f64 - gaussian_exact;
                    let e = set.iter().map(|&p| disc(p)).sum::<f64>() / n as f64 - disc_exact;
                    progress.advance(n as u64)?;
                    Ok((g * g, e * e))
                })
                .try_reduce(|| (0.0, 0.0), |a, b| Ok((a.0 + b.0, a.1 + b.1)))?;
            smooth[s].push((n as f64, (g2 / runs as f64).sqrt()));
            edge[s].push((n as f64, (e2 / runs as f64).sqrt()));
        }
        let spectrum = (0..spectrum_runs)
            .into_par_iter()
            .map(|run| {
                let p = periodogram(&points(settings.sampler, seed, run, n));
                progress.advance(n as u64)?;
                Ok(p)
            })
            .try_reduce(Vec::new, |a: Vec<f64>, b: Vec<f64>| {
                Ok(if a.is_empty() {
                    b
                } else {
                    a.iter().zip(&b).map(|(x, y)| x + y).collect()
                })
            })?;
        let spectrum: Vec<f64> = spectrum.iter().map(|v| v / spectrum_runs as f64).collect();

        report.stages_done += 1;
        let done = &counts[..report.stages_done as usize];
        report.tables = vec![
            measure_table(
                &format!("L2 star discrepancy (RMS over {discrepancy_runs} runs)"),
                done,
                &discrepancy,
            ),
            measure_table(
                &format!("RMSE integrating a Gaussian over {runs} runs"),
                done,
                &smooth,
            ),
            measure_table(
                &format!("RMSE integrating a disc over {runs} runs"),
                done,
                &edge,
            ),
            slopes(&discrepancy, &smooth, &edge),
        ];
        let curves = |title: &str, y: &str, data: &[Vec<(f64, f64)>]| {
            Figure::log_log(
                title,
                "N",
                y,
                samplers
                    .iter()
                    .zip(data)
                    .map(|(kind, c)| {
                        Series::new(kind.name(), SeriesStyle::Line, sampler_color(*kind), c)
                    })
                    .collect(),
            )
        };
        let scatter: Vec<(f64, f64)> = points(settings.sampler, seed, 0, n)
            .iter()
            .map(|p| (p.x as f64, p.y as f64))
            .collect();
        report.figures = vec![
            Figure::linear(
                format!("{n} {} points", settings.sampler.name()),
                ("x", "y"),
                (0.0, 1.0),
                (0.0, 1.0),
                vec![Series::new(
                    settings.sampler.name(),
                    SeriesStyle::Points,
                    sampler_color(settings.sampler),
                    &scatter,
                )],
            ),
            spectrum_figure(&spectrum, settings.sampler, n, spectrum_runs),
            radial_figure(&spectrum, settings.sampler),
            curves("L2 star discrepancy", "discrepancy", &discrepancy),
            curves("RMSE integrating a Gaussian", "RMSE", &smooth),
            curves("RMSE integrating a disc", "RMSE", &edge),
        ];
        progress.publish(&report);
    }
    Ok(report)
}

/// One table per measure: N down, samplers across.
fn measure_table(title: &str, counts: &[u32], data: &[Vec<(f64, f64)>]) -> Table {
    Table {
        title: title.into(),
        columns: std::iter::once("N".to_string())
            .chain(SamplerKind::ALL.iter().map(|k| k.name().to_string()))
            .collect(),
        rows: counts
            .iter()
            .enumerate()
            .map(|(i, &n)| {
                std::iter::once(Cell::int(n as u64))
                    .chain(data.iter().map(|c| Cell::sci(c[i].1)))
                    .collect()
            })
            .collect(),
    }
}

fn slopes(
    discrepancy: &[Vec<(f64, f64)>],
    smooth: &[Vec<(f64, f64)>],
    edge: &[Vec<(f64, f64)>],
) -> Table {
    Table {
        title: "Fitted slopes of log error against log N".into(),
        columns: ["sampler", "discrepancy", "Gaussian", "disc"]
            .map(String::from)
            .to_vec(),
        rows: SamplerKind::ALL
            .iter()
            .enumerate()
            .map(|(s, kind)| {
                vec![
                    Cell::text(kind.name()),
                    Cell::fixed(log_log_slope(&discrepancy[s]), 3),
                    Cell::fixed(log_log_slope(&smooth[s]), 3),
                    Cell::fixed(log_log_slope(&edge[s]), 3),
                ]
            })
            .collect(),
    }
}

fn spectrum_figure(spectrum: &[f64], kind: SamplerKind, n: u32, runs: u32) -> Figure {
    let side = (2 * FREQUENCIES + 1) as usize;
    let mut values = spectrum.to_vec();
    // The DC term is N: it says nothing about the arrangement.
    values[side * side / 2] = 0.0;
    let f = FREQUENCIES as f64 + 0.5;
    Figure {
        heatmap: Some(Heatmap {
            width: side,
            height: side,
            values: values.iter().map(|v| (v / 2.0).min(1.0)).collect(),
        }),
        ..Figure::linear(
            format!(
                "Periodogram of {n} {} points (mean of {runs}; white = 2)",
                kind.name()
            ),
            ("frequency x", "frequency y"),
            (-f, f),
            (-f, f),
            vec![],
        )
    }
}

fn radial_figure(spectrum: &[f64], kind: SamplerKind) -> Figure {
    let side = 2 * FREQUENCIES + 1;
    let mut sums = vec![(0.0, 0u32); FREQUENCIES as usize + 1];
    for j in 0..side {
        for i in 0..side {
            let (x, y) = ((i - FREQUENCIES) as f64, (j - FREQUENCIES) as f64);
            let r = (x * x + y * y).sqrt().round() as usize;
            if r >= 1 && r < sums.len() {
                sums[r].0 += spectrum[(j * side + i) as usize];
                sums[r].1 += 1;
            }
        }
    }
    let radial: Vec<(f64, f64)> = sums
        .iter()
        .enumerate()
        .skip(1)
        .map(|(r, (s, c))| (r as f64, s / (*c).max(1) as f64))
        .collect();
    let white: Vec<(f64, f64)> = vec![(1.0, 1.0), (FREQUENCIES as f64, 1.0)];
    Figure::linear(
        format!("Radial average of the periodogram ({})", kind.name()),
        ("|frequency|", "power"),
        (0.0, FREQUENCIES as f64),
        (0.0, 2.0),
        vec![
            Series::new(kind.name(), SeriesStyle::Line, sampler_color(kind), &radial),
            Series::new("white noise", SeriesStyle::Guide, 7, &white),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrepancy_and_periodogram_of_known_sets() {
        // One point at (a, b): T² = 1/9 - (1-a²)(1-b²)/2 + (1-a)(1-b) (Warnock, N = 1).
        let (a, b) = (0.3f32, 0.6f32);
        let (af, bf) = (a as f64, b as f64);
        let expected =
            (1.0 / 9.0 - (1.0 - af * af) * (1.0 - bf * bf) / 2.0 + (1.0 - af) * (1.0 - bf)).sqrt();
        assert!((l2_star_discrepancy(&[Vec2::new(a, b)]) - expected).abs() < 1e-12);
        // A single point has power 1 at every frequency; its DC term is N = 1.
        let p = periodogram(&[Vec2::new(a, b)]);
        assert!(p.iter().all(|v| (v - 1.0).abs() < 1e-9));
        // Two points half a period apart in x cancel at odd x frequencies.
        let p = periodogram(&[Vec2::new(0.0, 0.0), Vec2::new(0.5, 0.0)]);
        let side = (2 * FREQUENCIES + 1) as usize;
        let at =
            |kx: i32, ky: i32| p[(ky + FREQUENCIES) as usize * side + (kx + FREQUENCIES) as usize];
        assert!(at(1, 0) < 1e-9 && (at(2, 3) - 2.0).abs() < 1e-9);
    }
}
