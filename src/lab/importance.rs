//! Importance sampling: (1/N) Σ f(xᵢ)/p(xᵢ) with several densities p, in 1D
//! and for the irradiance under a sky on the hemisphere; the variance per
//! sample computed exactly (quadrature) and measured.

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::stats::{Moments, PointSet, integrate};
use super::stratified::integrand;
use super::{Cancelled, LabSettings, Progress};
use crate::sampling::AliasTable;
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use crate::sampling::warp::{
    cosine_hemisphere_pdf, square_to_cosine_hemisphere, square_to_uniform_cone, uniform_cone_pdf,
};
use glam::{Vec2, Vec3A};
use std::f64::consts::PI;

pub const TEXT: &str = "The estimator (1/N) Σ f(x)/p(x) is unbiased for any density p that is \
positive wherever f is, and its variance per sample is ∫ f²/p − I². The flatter f/p, the \
smaller it is: the ramp follows f a little and gains a little, the histogram shaped like f \
(sampled with the renderer's alias table) makes f/p nearly constant. A p that is zero where \
f is not never sees that part of f: its estimate converges, with small error bars, to the \
wrong value. On the hemisphere, the irradiance under the sky L = 1 + cos θ is ∫ L cos θ dω \
= 5π/3: cosine sampling (what a diffuse surface uses) cancels the cosine and wins; \
sky-shaped sampling cancels L, which only varies from 1 to 2, and leaves the cosine, which \
goes from 0 to 1: it does worse. Shape p after what varies most; sampling the product L cos θ \
would give zero variance.";

/// Bins of the density shaped like f.
const BINS: usize = 32;

/// A density on [0, 1] and how to draw from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Density1d {
    Uniform,
    Ramp,
    ShapedLikeF,
    /// p = 2 on [0, 1/2), zero where f is not.
    HalfSupport,
}

impl Density1d {
    const ALL: [Density1d; 4] = [
        Density1d::Uniform,
        Density1d::Ramp,
        Density1d::ShapedLikeF,
        Density1d::HalfSupport,
    ];

    fn name(self) -> &'static str {
        match self {
            Density1d::Uniform => "uniform p = 1",
            Density1d::Ramp => "ramp p = 1/2 + x",
            Density1d::ShapedLikeF => "histogram of f (32 bins)",
            Density1d::HalfSupport => "p = 2 on [0, 1/2), 0 elsewhere",
        }
    }

    fn pdf(self, x: f64, table: &AliasTable) -> f64 {
        match self {
            Density1d::Uniform => 1.0,
            Density1d::Ramp => 0.5 + x,
            Density1d::ShapedLikeF => {
                table.pmf(((x * BINS as f64) as usize).min(BINS - 1)) as f64 * BINS as f64
            }
            Density1d::HalfSupport => {
                if x < 0.5 {
                    2.0
                } else {
                    0.0
                }
            }
        }
    }

    /// A point from two uniform numbers, with its density.
    fn sample(self, u: Vec2, table: &AliasTable) -> (f64, f64) {
        let x = match self {
            Density1d::Uniform => u.x as f64,
            // CDF x/2 + x²/2 = u.
            Density1d::Ramp => -0.5 + (0.25 + 2.0 * u.x as f64).sqrt(),
            Density1d::ShapedLikeF => {
                let (bin, _) = table.sample(u.x);
                (bin as f64 + u.y as f64) / BINS as f64
            }
            Density1d::HalfSupport => 0.5 * u.x as f64,
        };
        (x, self.pdf(x, table))
    }
}

/// Densities on the +z hemisphere for E = ∫ (1 + cos θ) cos θ dω.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DensityHemisphere {
    Uniform,
    Cosine,
    Sky,
}

impl DensityHemisphere {
    const ALL: [DensityHemisphere; 3] = [
        DensityHemisphere::Uniform,
        DensityHemisphere::Cosine,
        DensityHemisphere::Sky,
    ];

    fn name(self) -> &'static str {
        match self {
            DensityHemisphere::Uniform => "hemisphere: uniform (cone of 90 deg)",
            DensityHemisphere::Cosine => "hemisphere: cosine",
            DensityHemisphere::Sky => "hemisphere: shaped like the sky",
        }
    }

    /// Density wrt. solid angle at cos θ = μ.
    fn pdf(self, mu: f64) -> f64 {
        match self {
            DensityHemisphere::Uniform => uniform_cone_pdf(0.0) as f64,
            DensityHemisphere::Cosine => {
                cosine_hemisphere_pdf(Vec3A::new(0.0, 0.0, mu as f32)) as f64
            }
            // (1 + μ) / (3π): ∫ (1 + μ) dω = 2π (1 + 1/2).
            DensityHemisphere::Sky => (1.0 + mu) / (3.0 * PI),
        }
    }

    /// cos θ of a direction drawn with the renderer's warps (the sky's own
    /// inverts its CDF μ + μ²/2 = 3u/2), and its density.
    fn sample(self, u: Vec2) -> (f64, f64) {
        match self {
            DensityHemisphere::Uniform => {
                let w = square_to_uniform_cone(u, 0.0);
                (w.z as f64, uniform_cone_pdf(0.0) as f64)
            }
            DensityHemisphere::Cosine => {
                let w = square_to_cosine_hemisphere(u);
                (w.z as f64, cosine_hemisphere_pdf(w) as f64)
            }
            DensityHemisphere::Sky => {
                let mu = -1.0 + (1.0 + 3.0 * u.x as f64).sqrt();
                (mu, self.pdf(mu))
            }
        }
    }
}

/// The sky's radiance times the cosine: the hemisphere integrand.
fn sky_integrand(mu: f64) -> f64 {
    (1.0 + mu) * mu
}

/// One row: the exact mean and variance per sample, the measured ones.
struct Row {
    name: &'static str,
    /// The integral the estimator is meant to give.
    target: f64,
    exact_mean: f64,
    exact_variance: f64,
    measured: Moments,
}

/// `settings.n` samples per density (independent numbers: the variance of one sample).
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let n = settings.n.max(2);
    let stages = (Density1d::ALL.len() + DensityHemisphere::ALL.len()) as u32;
    progress.plan(n as u64 * stages as u64);
    let exact = integrate(integrand, 0.0, 1.0, 4096);
    let table = shaped_like_f();
    let mut rows: Vec<Row> = Vec::new();
    let mut report = Report {
        stages_planned: stages,
        ..Report::default()
    };
    for (k, density) in Density1d::ALL.into_iter().enumerate() {
        // Exact moments per bin, so that the histogram density's jumps fall
        // on panel boundaries and the quadrature stays exact.
        let (mut mean, mut second) = (0.0, 0.0);
        for bin in 0..BINS {
            let (a, b) = (bin as f64 / BINS as f64, (bin + 1) as f64 / BINS as f64);
            let p = |x: f64| density.pdf(x, &table);
            mean += integrate(|x| if p(x) > 0.0 { integrand(x) } else { 0.0 }, a, b, 64);
            second += integrate(
                |x| {
                    if p(x) > 0.0 {
                        integrand(x).powi(2) / p(x)
                    } else {
                        0.0
                    }
                },
                a,
                b,
                64,
            );
        }
        let measured = measure(hash_combine(settings.seed, k as u64), n, progress, |u| {
            let (x, p) = density.sample(u, &table);
            integrand(x) / p
        })?;
        rows.push(Row {
            name: density.name(),
            target: exact,
            exact_mean: mean,
            exact_variance: second - mean * mean,
            measured,
        });
        publish(&mut report, &rows, exact, &table, progress);
    }
    let sky_exact = 5.0 * PI / 3.0;
    for (k, density) in DensityHemisphere::ALL.into_iter().enumerate() {
        // E[g²] = ∫ (Lμ)²/p dω = 2π ∫₀¹ (Lμ)²/p(μ) dμ.
        let second = 2.0
            * PI
            * integrate(
                |mu| sky_integrand(mu).powi(2) / density.pdf(mu),
                0.0,
                1.0,
                256,
            );
        let seed = hash_combine(settings.seed, 100 + k as u64);
        let measured = measure(seed, n, progress, |u| {
            let (mu, p) = density.sample(u);
            sky_integrand(mu) / p
        })?;
        rows.push(Row {
            name: density.name(),
            target: sky_exact,
            exact_mean: sky_exact,
            exact_variance: second - sky_exact * sky_exact,
            measured,
        });
        publish(&mut report, &rows, exact, &table, progress);
    }
    for row in &rows {
        let relative = row.measured.variance() / row.exact_variance - 1.0;
        report.checks.push(Check {
            statement: format!("{}: measured variance within 5% of the exact", row.name),
            measured: format!(
                "{:.5e} against {:.5e} ({:+.2}%)",
                row.measured.variance(),
                row.exact_variance,
                100.0 * relative
            ),
            holds: relative.abs() < 0.05,
        });
    }
    let truncated = &rows[3];
    let z =
        (truncated.measured.mean - truncated.target).abs() / truncated.measured.standard_error();
    report.checks.push(Check {
        statement:
            "p = 0 where f is not: the mean misses the integral by more than 10 standard errors"
                .into(),
        measured: format!(
            "mean {:.6} against {exact:.6}: {z:.0} standard errors",
            truncated.measured.mean
        ),
        holds: z > 10.0,
    });
    Ok(report)
}

/// Mean and variance of `estimate` over `n` independent points (seed `seed`).
fn measure(
    seed: u64,
    n: u32,
    progress: &Progress,
    estimate: impl Fn(Vec2) -> f64,
) -> Result<Moments, Cancelled> {
    let mut set = PointSet::new(SamplerKind::Independent, seed, 0, n);
    let mut measured = Moments::default();
    for i in 0..n {
        measured.add(estimate(set.point_2d(i)));
        if i % 65_536 == 0 {
            progress.advance(65_536.min(n - i) as u64)?;
        }
    }
    Ok(measured)
}

/// The alias table of f's integrals over `BINS` equal bins.
fn shaped_like_f() -> AliasTable {
    let weights: Vec<f32> = (0..BINS)
        .map(|b| {
            integrate(
                integrand,
                b as f64 / BINS as f64,
                (b + 1) as f64 / BINS as f64,
                16,
            ) as f32
        })
        .collect();
    AliasTable::new(&weights).expect("f is positive on [0, 1]")
}

fn publish(
    report: &mut Report,
    rows: &[Row],
    integral: f64,
    table: &AliasTable,
    progress: &Progress,
) {
    report.stages_done = rows.len() as u32;
    report.tables = vec![Table {
        title: format!(
            "Per-sample mean and variance of f/p; the 1D integral is {integral:.10}, the irradiance 5pi/3 = {:.10}",
            5.0 * PI / 3.0
        ),
        columns: [
            "density p",
            "exact mean",
            "measured mean",
            "(mean - I) / s.e.",
            "exact variance",
            "measured variance",
            "measured / exact",
        ]
        .map(String::from)
        .to_vec(),
        rows: rows
            .iter()
            .map(|r| {
                vec![
                    Cell::text(r.name),
                    Cell::fixed(r.exact_mean, 6),
                    Cell::fixed(r.measured.mean, 6),
                    Cell::fixed(
                        (r.measured.mean - r.target) / r.measured.standard_error(),
                        1,
                    ),
                    Cell::sci(r.exact_variance),
                    Cell::sci(r.measured.variance()),
                    Cell::fixed(r.measured.variance() / r.exact_variance, 4),
                ]
            })
            .collect(),
    }];
    let xs: Vec<f64> = (0..=400).map(|i| i as f64 / 400.0).collect();
    let curve = |g: &dyn Fn(f64) -> Option<f64>| -> Vec<(f64, f64)> {
        xs.iter().filter_map(|&x| g(x).map(|y| (x, y))).collect()
    };
    let mut densities = vec![Series::new(
        "f",
        SeriesStyle::Guide,
        7,
        &curve(&|x| Some(integrand(x))),
    )];
    let mut ratios = Vec::new();
    for (k, d) in Density1d::ALL.into_iter().enumerate() {
        densities.push(Series::new(
            d.name(),
            SeriesStyle::Line,
            k,
            &curve(&|x| Some(d.pdf(x, table))),
        ));
        ratios.push(Series::new(
            d.name(),
            SeriesStyle::Line,
            k,
            &curve(&|x| {
                let p = d.pdf(x, table);
                (p > 0.0).then(|| integrand(x) / p)
            }),
        ));
    }
    report.figures = vec![
        Figure::linear(
            "f and the densities p",
            ("x", "f, p"),
            (0.0, 1.0),
            (0.0, 3.0),
            densities,
        ),
        Figure::linear(
            "f/p: what each sample contributes",
            ("x", "f/p"),
            (0.0, 1.0),
            (0.0, 3.0),
            ratios,
        ),
    ];
    progress.publish(report);
}
