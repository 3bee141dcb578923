//! "Breaks the quadratic complexity": hierarchical radiosity with clusters
//! ([`crate::radiosity::Hierarchy`]) solving a room with a sphere of N
//! triangles, at N/100, N/10 and N, for oriented and isotropic clusters:
//! links, elements, memory and time against the input's size, and their
//! slopes on log-log axes.

use super::report::{Cell, Check, Figure, Report, Series, SeriesStyle, Table};
use super::stats::log_log_slope;
use super::{Cancelled, LabSettings, Progress};
use crate::integrator::radiosity::MAX_NODES;
use crate::radiosity::cluster::ClusterKind;
use crate::radiosity::{FormFactorMethod, Hierarchy, HierarchySettings};
use crate::scene::{Limits, Scene};
use std::path::Path;
use std::time::Instant;

pub const TEXT: &str = "The Cornell box's room with a sphere of N flat triangles in it \
(scenes/cluster_room.toml), solved by hierarchical radiosity to convergence. Without clusters \
every pair of triangles would start with a link: 10^10 of them at N = 100 000. With a tree of \
clusters above the triangles the solve starts from one link of the whole scene to itself and \
splits it only where the light it carries is large, so links and memory grow with N, not N². \
The slope of links against triangles on log-log axes is the exponent of that growth; 1 is \
linear. Oriented clusters project each triangle towards the other end of a link; isotropic \
ones take a quarter of their area in every direction.";

/// The shipped scene, its sphere's triangle count replaced.
const ROOM: &str = include_str!("../../scenes/cluster_room.toml");

/// Patch size (smallest element edge over the scene's diagonal) and ε of
/// the solves: the walls' elements stay the same at every N.
const PATCH_SIZE: f32 = 0.02;
const EPSILON: f32 = 1e-4;
/// A solve stops when a step changes the radiance by less than this (of
/// the emitted power), or after `MAX_STEPS`.
const CONVERGED: f64 = 1e-5;
const MAX_STEPS: u32 = 40;

/// The room of `scenes/cluster_room.toml` with a sphere of about
/// `triangles` triangles.
pub fn sphere_in_room(triangles: u32) -> crate::Result<Scene> {
    let text = ROOM.replace(
        "triangles = 100000",
        &format!("triangles = {}", triangles.max(8)),
    );
    let input =
        crate::scene::load::parse_scene(Path::new("cluster_room.toml"), &text, &Limits::default())?;
    Scene::build(input)
}

/// One solve's figures.
struct Solve {
    triangles: usize,
    elements: usize,
    links: usize,
    bytes: usize,
    seconds: f64,
    steps: u64,
}

fn solve(scene: &Scene, kind: ClusterKind) -> Result<Solve, String> {
    let start = Instant::now();
    let method = FormFactorMethod::Analytic;
    let mut h = Hierarchy::build(
        scene,
        HierarchySettings {
            epsilon: EPSILON,
            min_size: PATCH_SIZE,
            method,
            samples: method.default_samples(),
            max_nodes: MAX_NODES,
            clusters: kind,
        },
        &[],
    )?;
    while h.steps < u64::from(MAX_STEPS) && h.step(&scene.geometry) > CONVERGED {}
    let (elements, links) = h.counts();
    Ok(Solve {
        triangles: scene.geometry.triangles().len(),
        elements,
        links,
        bytes: h.memory_bytes(),
        seconds: start.elapsed().as_secs_f64(),
        steps: h.steps,
    })
}

/// Runs the experiment with spheres of `settings.n` / 100, / 10 and N triangles.
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let sizes = [settings.n / 100, settings.n / 10, settings.n].map(|n| n.max(100));
    let kinds = [ClusterKind::Oriented, ClusterKind::Isotropic];
    progress.plan((sizes.len() * kinds.len()) as u64);
    let mut report = Report {
        stages_planned: (sizes.len() * kinds.len()) as u32,
        ..Report::default()
    };
    let mut table = Table {
        title: format!(
            "Hierarchical radiosity with clusters, a sphere of N triangles in a room (ε {EPSILON:.0e}, patch size {PATCH_SIZE})"
        ),
        columns: [
            "clusters",
            "triangles",
            "elements",
            "links",
            "links / triangle",
            "memory (MB)",
            "steps",
            "time (s)",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let mut links = [Vec::new(), Vec::new()];
    let mut memory = [Vec::new(), Vec::new()];
    for &n in &sizes {
        let scene = match sphere_in_room(n) {
            Ok(scene) => scene,
            Err(e) => return Ok(failed(report, e.to_string())),
        };
        for (k, &kind) in kinds.iter().enumerate() {
            progress.advance(1)?;
            let s = match solve(&scene, kind) {
                Ok(s) => s,
                Err(e) => return Ok(failed(report, e)),
            };
            table.rows.push(vec![
                Cell::text(format!("{kind:?}").to_lowercase()),
                Cell::int(s.triangles as u64),
                Cell::int(s.elements as u64),
                Cell::int(s.links as u64),
                Cell::fixed(s.links as f64 / s.triangles as f64, 2),
                Cell::fixed(s.bytes as f64 / 1e6, 1),
                Cell::int(s.steps),
                Cell::fixed(s.seconds, 2),
            ]);
            links[k].push((s.triangles as f64, s.links as f64));
            memory[k].push((s.triangles as f64, s.bytes as f64 / 1e6));
            report.stages_done += 1;
            report.tables = vec![table.clone()];
            report.figures = vec![Figure::log_log(
                "Links and memory (MB) against triangles",
                "triangles",
                "links, MB",
                vec![
                    Series::new("links, oriented", SeriesStyle::Line, 0, &links[0]),
                    Series::new("links, isotropic", SeriesStyle::Line, 1, &links[1]),
                    Series::new("MB, oriented", SeriesStyle::Line, 2, &memory[0]),
                    Series::new("MB, isotropic", SeriesStyle::Line, 3, &memory[1]),
                ],
            )];
            progress.publish(&report);
        }
    }
    for (k, kind) in kinds.iter().enumerate() {
        let name = format!("{kind:?}").to_lowercase();
        let (l, m) = (log_log_slope(&links[k]), log_log_slope(&memory[k]));
        report.checks.push(Check {
            statement: format!("{name} clusters: links and memory grow at most as triangles^1.1"),
            measured: format!("slopes {l:.2} (links), {m:.2} (memory)"),
            holds: l <= 1.1 && m <= 1.1,
        });
    }
    Ok(report)
}

/// The report so far with the error as a failed check.
fn failed(mut report: Report, error: String) -> Report {
    report.checks.push(Check {
        statement: "the scene loads and the hierarchy builds".into(),
        measured: error,
        holds: false,
    });
    report
}
