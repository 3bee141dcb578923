//! The Monte Carlo lab: the integration lessons behind every estimator, on
//! one- and two-dimensional integrals, computed with the renderer's own
//! samplers ([`crate::sampling::Sampler`]) and warps
//! ([`crate::sampling::warp`], the lights' and BSDFs' `sample`), never copies.
//!
//! Each experiment is one file and one function `run(&LabSettings, &Progress)
//! -> Result<Report, Cancelled>`. A [`Report`] is plain data (tables,
//! figures, checked statements and a text for students); the CLI prints and
//! writes it (`tracelab lab`), the viewer draws it live (its "MC lab" tab)
//! from the partial reports an experiment publishes as its N grows.

pub mod cluster_solve;
pub mod clusters;
pub mod coins;
pub mod importance;
pub mod pi;
pub mod point_sets;
pub mod report;
pub mod runner;
pub mod stats;
pub mod stratified;
pub mod warps;

pub use report::{Axes, Cell, Check, Figure, Heatmap, Report, Series, SeriesStyle, Table};
pub use runner::{LabRunner, Progress};

use crate::sampling::SamplerKind;

/// The experiments, in the order the lab presents them.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Experiment {
    /// π by darts thrown at the unit square.
    #[default]
    Pi,
    /// The mean absolute error of n fair coin flips.
    Coins,
    /// ∫₀¹ e^{sin 3x²} dx with independent, jittered, Latin hypercube and Sobol points.
    Stratified,
    /// (1/N) Σ f(x)/p(x) for several p, in 1D and on the hemisphere.
    Importance,
    /// The renderer's 2D point sets: scatter, spectrum, discrepancy, error.
    PointSets,
    /// Every warp of the renderer against its pdf (χ²).
    Warps,
    /// The form factor between two meshes by cluster links (radiosity).
    Clusters,
    /// Radiosity with clusters on a mesh of N triangles: links and memory against N.
    ClusterSolve,
}

impl Experiment {
    pub const ALL: [Experiment; 8] = [
        Experiment::Pi,
        Experiment::Coins,
        Experiment::Stratified,
        Experiment::Importance,
        Experiment::PointSets,
        Experiment::Warps,
        Experiment::Clusters,
        Experiment::ClusterSolve,
    ];

    /// Name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Experiment::Pi => "pi",
            Experiment::Coins => "coins",
            Experiment::Stratified => "stratified",
            Experiment::Importance => "importance",
            Experiment::PointSets => "point-sets",
            Experiment::Warps => "warps",
            Experiment::Clusters => "clusters",
            Experiment::ClusterSolve => "cluster-solve",
        }
    }

    /// Title in the viewer and above the CLI's tables.
    pub fn label(self) -> &'static str {
        match self {
            Experiment::Pi => "π by darts",
            Experiment::Coins => "Coin flips",
            Experiment::Stratified => "Stratified vs unstratified",
            Experiment::Importance => "Importance sampling",
            Experiment::PointSets => "Point sets",
            Experiment::Warps => "Warps and their pdfs",
            Experiment::Clusters => "Clusters: the form factor of two meshes",
            Experiment::ClusterSolve => "Clusters: radiosity of a mesh in a room",
        }
    }

    /// The lab text: what to look at, what the numbers mean.
    pub fn text(self) -> &'static str {
        match self {
            Experiment::Pi => pi::TEXT,
            Experiment::Coins => coins::TEXT,
            Experiment::Stratified => stratified::TEXT,
            Experiment::Importance => importance::TEXT,
            Experiment::PointSets => point_sets::TEXT,
            Experiment::Warps => warps::TEXT,
            Experiment::Clusters => clusters::TEXT,
            Experiment::ClusterSolve => cluster_solve::TEXT,
        }
    }

    /// The experiment called `name` on the command line.
    pub fn from_name(name: &str) -> Option<Experiment> {
        Experiment::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The settings the CLI and the viewer start from.
    pub fn default_settings(self) -> LabSettings {
        let (n, runs) = match self {
            Experiment::Pi => (10_000, 1000),
            Experiment::Coins => (1024, 10_000),
            Experiment::Stratified => (100_000, 400),
            Experiment::Importance => (1_000_000, 1),
            Experiment::PointSets => (4096, 256),
            Experiment::Warps => (1_000_000, 1),
            Experiment::Clusters => (4096, 1),
            Experiment::ClusterSolve => (100_000, 1),
        };
        LabSettings {
            experiment: self,
            sampler: SamplerKind::Independent,
            n,
            runs,
            seed: 1,
            pace: std::time::Duration::ZERO,
        }
    }

    /// Why `settings` cannot be run, if they cannot: counts of zero, and
    /// point sets past what the O(N²) discrepancy finishes in minutes.
    pub fn check(self, settings: &LabSettings) -> Result<(), String> {
        if settings.n == 0 || settings.runs == 0 {
            return Err("the largest N and the number of runs must be at least 1".into());
        }
        if self == Experiment::PointSets && settings.n > MAX_POINT_SET {
            return Err(format!(
                "point-sets computes the L2 star discrepancy in O(N^2): N is at most {MAX_POINT_SET}, got {}",
                settings.n
            ));
        }
        if self == Experiment::ClusterSolve && settings.n > MAX_SOLVE_TRIANGLES {
            return Err(format!(
                "cluster-solve meshes at most {MAX_SOLVE_TRIANGLES} triangles (about 600 bytes each with its BVH), got {}",
                settings.n
            ));
        }
        if self == Experiment::Clusters && settings.n > MAX_CLUSTER_TRIANGLES {
            return Err(format!(
                "clusters sums every pair of triangles for its reference, O(N^2): N is at most {MAX_CLUSTER_TRIANGLES}, got {}",
                settings.n
            ));
        }
        Ok(())
    }

    /// Runs the experiment; partial reports go to `progress` as it goes.
    pub fn run(self, settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
        let report = match self {
            Experiment::Pi => pi::run(settings, progress),
            Experiment::Coins => coins::run(settings, progress),
            Experiment::Stratified => stratified::run(settings, progress),
            Experiment::Importance => importance::run(settings, progress),
            Experiment::PointSets => point_sets::run(settings, progress),
            Experiment::Warps => warps::run(settings, progress),
            Experiment::Clusters => clusters::run(settings, progress),
            Experiment::ClusterSolve => cluster_solve::run(settings, progress),
        }?;
        progress.publish(&report);
        Ok(report)
    }
}

/// What an experiment is asked to do. Every experiment reads `seed`; the
/// others as its documentation says (the viewer shows the ones it reads).
#[derive(Clone, Debug, PartialEq)]
pub struct LabSettings {
    pub experiment: Experiment,
    /// The sampler of the live scatter (π, point sets); the curves show all.
    pub sampler: SamplerKind,
    /// The largest sample count (darts, flips, points, warped samples).
    pub n: u32,
    /// Independent runs the error statistics average over.
    pub runs: u32,
    pub seed: u64,
    /// Least time between published stages, so that a student sees the
    /// curves grow (the viewer); zero on the command line.
    pub pace: std::time::Duration,
}

/// The largest mesh `clusters` accepts (its reference is O(N²)).
pub const MAX_CLUSTER_TRIANGLES: u32 = 16_384;

/// The largest sphere `cluster-solve` meshes.
pub const MAX_SOLVE_TRIANGLES: u32 = 2_000_000;

/// The largest point set `point-sets` accepts.
pub const MAX_POINT_SET: u32 = 1 << 16;

/// The run was cancelled (the viewer's Cancel, a new run, the window closing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

/// Sample counts 1, 2, 5, 10, 20, 50, ... from `from` up to `to` inclusive.
pub fn one_two_five(from: u32, to: u32) -> Vec<u32> {
    let mut counts = Vec::new();
    let mut decade = 1u64;
    while decade <= to as u64 {
        for m in [1, 2, 5] {
            let n = decade * m;
            if n >= from as u64 && n <= to as u64 {
                counts.push(n as u32);
            }
        }
        decade *= 10;
    }
    counts
}

/// Powers of two from `from` up to `to` inclusive.
pub fn powers_of_two(from: u32, to: u32) -> Vec<u32> {
    (0..32)
        .map(|k| 1u64 << k)
        .filter(|&n| n >= from as u64 && n <= to as u64)
        .map(|n| n as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_grids_are_right() {
        for e in Experiment::ALL {
            assert_eq!(Experiment::from_name(e.name()), Some(e));
            assert!(!e.text().is_empty());
        }
        assert_eq!(one_two_five(10, 100), vec![10, 20, 50, 100]);
        assert_eq!(powers_of_two(16, 100), vec![16, 32, 64]);
    }
}
