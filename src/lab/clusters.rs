//! "The form factor between two cows": two tessellated spheres exchange
//! light through links between clusters of their triangles
//! ([`crate::radiosity::cluster`]), against the sum over every pair of
//! triangles, as the oracle's ε falls, for isotropic and oriented clusters.

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::{Cancelled, LabSettings, Progress};
use crate::radiosity::cluster::{
    ClusterKind, ClusterTree, DEFAULT_EPSILON, cluster_form_factor, triangle_row, uv_sphere,
};
use glam::Vec3A;
use rayon::prelude::*;
use std::time::Instant;

pub const TEXT: &str = "Two unit spheres, 3 apart, each of about N triangles. Their form factor is \
the area-weighted sum over every pair of triangles (N² contour integrals: the reference). \
Hierarchical radiosity with clusters groups triangles into a tree and links two groups whenever \
the light between them is small (its form factor below ε): far parts of the two objects then \
exchange through one link, and the cost falls from N² to about the number of links. Oriented \
clusters project each triangle towards the other cluster (Σ A cos); isotropic ones assume a \
quarter of their area whatever the direction, which is right for a whole closed object and \
wrong for half of one: watch them go astray at middle ε, where half spheres link, and come back \
when links reach the triangles. The true form factor of the two spheres is 0.02964 (Monte Carlo, \
4·10⁷ rays); the meshes, inscribed, fall a little short.";

/// The ε of the table, coarse to fine.
const EPSILONS: [f32; 7] = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5];

/// Runs the experiment with spheres of about `settings.n` triangles each.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    // A UV sphere of r rings and 2r segments has 4r² − 4r triangles.
    let rings = ((settings.n.max(24) as f64 / 4.0).sqrt().round() as u32).max(3);
    let a = ClusterTree::build(&uv_sphere(Vec3A::ZERO, 1.0, rings, 2 * rings));
    let b = ClusterTree::build(&uv_sphere(Vec3A::new(3.0, 0.0, 0.0), 1.0, rings, 2 * rings));
    let (n, pairs) = (
        a.triangle_count(),
        (a.triangle_count() * b.triangle_count()) as u64,
    );
    progress.plan(pairs + 2 * EPSILONS.len() as u64);
    let mut report = Report {
        stages_planned: 1 + 2 * EPSILONS.len() as u32,
        ..Report::default()
    };
    let start = Instant::now();
    let sum: f64 = (0..n)
        .into_par_iter()
        .map(|i| {
            progress.advance(b.triangle_count() as u64)?;
            Ok(triangle_row(&a, i, &b))
        })
        .sum::<Result<f64, Cancelled>>()?;
    let reference = sum / f64::from(a.area());
    let reference_ms = start.elapsed().as_secs_f64() * 1e3;
    report.stages_done += 1;

    let mut table = Table {
        title: format!(
            "Form factor of two spheres of {n} triangles: clusters against all {pairs} pairs ({:.4}, {reference_ms:.0} ms)",
            reference
        ),
        columns: [
            "clusters",
            "epsilon",
            "links",
            "links / pairs",
            "F",
            "relative error",
            "time (ms)",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let mut curves = [Vec::new(), Vec::new()];
    let mut at_default = None;
    for (k, kind) in [ClusterKind::Oriented, ClusterKind::Isotropic]
        .into_iter()
        .enumerate()
    {
        for eps in EPSILONS {
            progress.advance(1)?;
            let start = Instant::now();
            let c = cluster_form_factor(&a, &b, kind, eps);
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let error = (c.f - reference).abs() / reference;
            if kind == ClusterKind::Oriented && eps == DEFAULT_EPSILON {
                at_default = Some((error, c.links));
            }
            table.rows.push(vec![
                Cell::text(format!("{kind:?}").to_lowercase()),
                Cell::sci(f64::from(eps)),
                Cell::int(c.links),
                Cell::sci(c.links as f64 / pairs as f64),
                Cell::fixed(c.f, 6),
                Cell::sci(error),
                Cell::fixed(ms, 1),
            ]);
            curves[k].push((c.links as f64, error.max(1e-7)));
            report.stages_done += 1;
            report.tables = vec![table.clone()];
            report.figures = vec![Figure::log_log(
                "Relative error of the cluster form factor against its links",
                "links",
                "relative error",
                vec![
                    Series::new("oriented", SeriesStyle::Line, 0, &curves[0]),
                    Series::new("isotropic", SeriesStyle::Line, 1, &curves[1]),
                    Series::new(
                        "1%",
                        SeriesStyle::Guide,
                        7,
                        &[(1.0, 0.01), (pairs as f64, 0.01)],
                    ),
                ],
            )];
            progress.publish(&report);
        }
    }
    if let Some((error, links)) = at_default {
        report.checks.push(Check {
            statement: format!(
                "oriented clusters at the default ε {DEFAULT_EPSILON:.0e} are within 1% of the sum over all pairs"
            ),
            measured: format!("relative error {error:.2e}"),
            holds: error < 0.01,
        });
        report.checks.push(Check {
            statement: "they need fewer than a tenth of the pairs' links".into(),
            measured: format!("{links} links for {pairs} pairs"),
            holds: links * 10 < pairs,
        });
    }
    report.checks.push(Check {
        statement: "the triangle sum is within 2% of the spheres' form factor (0.02964)".into(),
        measured: format!("{reference:.5}"),
        holds: (reference / 0.029_639 - 1.0).abs() < 0.02,
    });
    Ok(report)
}
