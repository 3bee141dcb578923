//! The numerical stress suite (quick settings): every case passes with
//! robust offsets, and a fixed epsilon fails where it must. Tolerances are
//! the suite's own (relative RMSE of an independent render of the reference,
//! i.e. its noise level; zero self-intersections; zero non-finite samples).

use crate::common::repo_path;
use tracelab::math::OffsetMode;
use tracelab::stress::{StressSettings, StressSuite, run};

fn results(offset: OffsetMode) -> Vec<tracelab::stress::CaseResult> {
    let settings = StressSettings {
        offset,
        ..StressSettings::quick()
    };
    let suite = StressSuite::new(&repo_path("scenes"), &settings).expect("stress scenes build");
    run(&suite, &settings, |_| {}).expect("stress suite runs")
}

#[test]
fn robust_offsets_pass_every_case() {
    let results = results(OffsetMode::Robust);
    assert!(results.len() >= 12);
    for r in &results {
        assert!(
            r.passed(),
            "{}: relative RMSE {} (tolerance {}), {} self-intersections of {}, {} non-finite",
            r.name,
            r.relative_rmse,
            r.tolerance,
            r.self_intersections,
            r.spawned,
            r.non_finite
        );
        assert!(r.spawned > 1000, "{}: too few rays probed", r.name);
    }
}

#[test]
fn a_fixed_epsilon_fails_at_large_and_small_scales() {
    let results = results(OffsetMode::Fixed(1e-3));
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.name.as_str())
        .collect();
    // Too small for a box 1e5 away (self-intersections) and too large for
    // a glass ball of radius 1e-3 (the refracted rays start past the ball).
    assert!(
        failed.contains(&"cornell box moved 1e5 along x"),
        "{failed:?}"
    );
    assert!(
        failed.contains(&"glass sphere of radius 1e-3"),
        "{failed:?}"
    );
    let glass = results
        .iter()
        .find(|r| r.name == "glass sphere of radius 1e-3")
        .unwrap();
    assert!(
        glass.relative_rmse > glass.tolerance,
        "{} vs {}",
        glass.relative_rmse,
        glass.tolerance
    );
}
