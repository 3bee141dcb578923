//! The Monte Carlo lab: each experiment at its default settings (what
//! `tracelab lab <experiment>` prints) meets the statements of its issue.
//! The tolerances are the experiments' own checks, each derived from the
//! estimator's variance in the experiment's code; the seeds are fixed, so
//! these tests pass or fail deterministically.

use glam::{Vec2, Vec3A};
use tracelab::lab::warps::{Fixtures, Warp};
use tracelab::lab::{Experiment, LabRunner, LabSettings, Progress, Report};
use tracelab::sampling::warp::*;

fn run(experiment: Experiment) -> Report {
    run_with(experiment.default_settings())
}

fn run_with(settings: LabSettings) -> Report {
    let report = settings
        .experiment
        .run(&settings, &Progress::default())
        .expect("not cancelled");
    assert_eq!(report.stages_done, report.stages_planned);
    for check in &report.checks {
        assert!(check.holds, "{}: {}", check.statement, check.measured);
    }
    report
}

/// The number in column `column` of the row whose first cell is `first`.
fn value(report: &Report, table: usize, first: &str, column: &str) -> f64 {
    let t = &report.tables[table];
    let c = t.columns.iter().position(|c| c == column).expect(column);
    let row = t.rows.iter().find(|r| r[0].text == first).expect(first);
    row[c].value.expect("a number")
}

#[test]
fn coins_exact_and_simulated() {
    let report = run(Experiment::Coins);
    assert_eq!(value(&report, 0, "1", "exact"), 0.5);
    assert_eq!(value(&report, 0, "2", "exact"), 0.25);
    assert_eq!(value(&report, 0, "4", "exact"), 0.1875);
    // Within 3 standard errors (the column is |sim - exact| / s.e.).
    for n in ["1", "2", "4"] {
        assert!(value(&report, 0, n, "|sim - exact| / s.e.") <= 3.0);
    }
    let ratio = value(&report, 0, "1024", "exact * sqrt(n)") / 0.398_942_280_4;
    assert!((ratio - 1.0).abs() < 0.01, "{ratio}");
    assert_eq!(report.checks.len(), 3);
}

#[test]
fn stratified_slopes_and_value() {
    let report = run(Experiment::Stratified);
    // The lecture's table: N = 1, 10, ..., 10^5.
    let lecture = &report.tables[0];
    let ns: Vec<&str> = lecture.rows.iter().map(|r| r[0].text.as_str()).collect();
    assert_eq!(ns, ["1", "10", "100", "1000", "10000", "100000"]);
    let independent = value(&report, 2, "independent", "slope");
    let jittered = value(&report, 2, "jittered", "slope");
    assert!((independent + 0.5).abs() <= 0.05, "{independent}");
    assert!((jittered + 1.5).abs() <= 0.1, "{jittered}");
    assert!(value(&report, 1, "100000", "mean jittered - I").abs() < 1e-6);
    assert_eq!(report.checks.len(), 4);
}

#[test]
fn pi_follows_its_variance_and_stratification_wins() {
    let report = run(Experiment::Pi);
    let rmse = value(&report, 0, "10000", "RMSE independent");
    let theory = (std::f64::consts::PI * (4.0 - std::f64::consts::PI) / 1e4).sqrt();
    assert!((rmse / theory - 1.0).abs() < 0.05, "{rmse} vs {theory}");
    for sampler in ["stratified", "multijitter", "sobol"] {
        assert!(value(&report, 0, "10000", &format!("RMSE {sampler}")) < rmse);
        let slope = value(&report, 1, sampler, "slope");
        assert!(slope < -0.6, "{sampler}: {slope}");
    }
}

#[test]
fn importance_variances_and_the_biased_density() {
    let report = run(Experiment::Importance);
    // Seven densities: four in 1D, three on the hemisphere, each within 5%,
    // and the truncated one more than 10 standard errors off.
    assert_eq!(report.checks.len(), 8);
    let z = value(
        &report,
        0,
        "p = 2 on [0, 1/2), 0 elsewhere",
        "(mean - I) / s.e.",
    );
    assert!(z.abs() > 10.0, "{z}");
}

/// Cow against cow (issue 39): oriented clusters within 1% of the sum over
/// all pairs at the default ε with a fraction of the links (the report's
/// checks), and closer as ε falls to 1e-5.
#[test]
fn cluster_form_factors_approach_the_sum_over_all_pairs() {
    let mut settings = Experiment::Clusters.default_settings();
    settings.n = 1024;
    let report = run_with(settings);
    assert_eq!(report.checks.len(), 3);
    let rows = &report.tables[0].rows;
    let error = |kind: &str, eps: &str| {
        rows.iter()
            .find(|r| r[0].text == kind && r[1].text == eps)
            .and_then(|r| r[5].value)
            .unwrap()
    };
    assert!(error("oriented", "1.000e-5") < error("oriented", "1.000e-1"));
    assert!(error("oriented", "1.000e-5") < 0.002);
}

#[test]
fn warps_pass_and_the_wrong_pdf_fails() {
    let report = run(Experiment::Warps);
    // Nine routines, the wrong pdf, the dielectric.
    assert_eq!(report.checks.len(), 11);
    let wrong = report.tables[0]
        .rows
        .iter()
        .find(|r| r[0].text.starts_with("WRONG"))
        .unwrap();
    assert_eq!(wrong.last().unwrap().text, "FAIL");
    // Three figures per routine and the dielectric's.
    assert_eq!(report.figures.len(), 3 * Warp::ALL.len() + 1);
}

#[test]
fn warps_call_the_renderers_functions() {
    // The lab's samples are the renderer's, bit for bit.
    let fixtures = Fixtures::new();
    for i in 0..1000 {
        let u = Vec2::new(
            (i as f32 * 0.618_034).fract(),
            (i as f32 * 0.414_213_5).fract(),
        );
        let same = |warp: Warp, expected: Vec3A| {
            let got = warp.sample(&fixtures, u).unwrap();
            assert_eq!(
                got.to_array().map(f32::to_bits),
                expected.to_array().map(f32::to_bits),
                "{warp:?}"
            );
        };
        same(Warp::CosineHemisphere, square_to_cosine_hemisphere(u));
        same(Warp::UniformHemisphere, square_to_uniform_cone(u, 0.0));
        same(Warp::PhongLobe, square_to_phong_lobe(u, 12.0));
        same(Warp::UniformSphere, square_to_uniform_sphere(u));
        same(Warp::SphereCone, square_to_uniform_cone(u, 0.8));
        same(
            Warp::ConcentricDisk,
            square_to_concentric_disk(u).extend(0.0).into(),
        );
        let light = fixtures
            .solid_angle
            .sample(fixtures.reference, 0.0, u)
            .map(|s| s.wi);
        assert_eq!(Warp::SphericalTriangle.sample(&fixtures, u), light);
    }
}

#[test]
fn point_sets_show_stratification() {
    let report = run(Experiment::PointSets);
    // Slopes: independent about -1/2 everywhere; every stratified set
    // integrates the smooth Gaussian faster than N^-0.9.
    let slope = |sampler: &str, column: &str| value(&report, 3, sampler, column);
    for column in ["discrepancy", "Gaussian", "disc"] {
        let s = slope("independent", column);
        assert!((s + 0.5).abs() < 0.1, "independent {column}: {s}");
    }
    for sampler in ["stratified", "multijitter", "sobol"] {
        assert!(slope(sampler, "Gaussian") < -0.9, "{sampler}");
        assert!(slope(sampler, "discrepancy") < -0.7, "{sampler}");
    }
    // Scatter, periodogram, radial average, three error curves.
    assert_eq!(report.figures.len(), 6);
}

#[test]
fn a_run_can_be_cancelled_and_publishes_as_it_goes() {
    let mut settings = Experiment::Stratified.default_settings();
    settings.runs = 100_000;
    let mut runner = LabRunner::start(settings);
    while runner.progress().counts().0 == 0 {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    runner.cancel();
    assert!(runner.was_cancelled());
    let (done, planned) = runner.progress().counts();
    assert!(done < planned, "{done} of {planned}");
    // A short run publishes a partial report per stage and then the final one.
    let mut settings = Experiment::Coins.default_settings();
    settings.runs = 100;
    let mut runner = LabRunner::start(settings);
    runner.poll_blocking();
    let report = runner.report().unwrap();
    assert_eq!(report.stages_done, 11);
    assert!(!runner.was_cancelled());
}
