//! The drivers of the kinds no shipped technique uses yet, run with
//! small techniques whose answers are known exactly.

use super::*;
use crate::integrator::{
    IntegratorOptions, MultiPassEstimator, MultiPassVisitor, Solver, SolverVisitor, Technique,
};

fn session() -> Session {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml");
    let mut scene = Scene::load(&path).unwrap();
    scene.set_resolution(8, 6);
    let settings = RenderSettings {
        integrator: IntegratorOptions::default().build(),
        sampler: SamplerKind::Independent,
        seed: 7,
        planned_spp: 0,
        threads: 2,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    Session::new(Arc::new(scene), settings).unwrap()
}

/// Each pre-pass builds its own number; every sample reads it.
struct PassNumber;

impl Technique for PassNumber {
    const SUMMARY: &'static str = "test";
    type Settings = ();
    fn new(_: &()) -> Self {
        PassNumber
    }
    fn describe(&self) -> String {
        "pass number".into()
    }
}

impl MultiPassEstimator for PassNumber {
    type Pass = f32;
    fn prepare(
        &self,
        _: &Scene,
        pass: u32,
        _: u64,
        _: crate::sampling::SamplerKind,
        counts: &mut RayCounts,
    ) -> f32 {
        counts.bounce += 10;
        pass as f32
    }
    fn radiance(
        &self,
        _: &Scene,
        pass: &f32,
        _: Ray,
        _: (u32, u32),
        _: &mut Sampler,
        _: &mut RayCounts,
    ) -> Rgb {
        Rgb::splat(*pass)
    }
}

#[test]
fn a_multi_pass_estimator_prepares_once_per_iteration() {
    let session = session();
    let (spp, progress) = MultiPass {
        session: &session,
        first: 0,
        k: 4,
    }
    .visit(&PassNumber);
    assert_eq!((spp, progress), (4, 4));
    let snapshot = session.snapshot();
    // Passes 0..4 each add one sample of their number: mean 1.5.
    assert!(snapshot.image.pixels.iter().all(|p| *p == [1.5; 3]));
    assert!(snapshot.samples.iter().all(|&n| n == 4));
    assert_eq!(session.stats().rays.bounce, 40);
}

/// x <- (x + 1) / 2 from 0: the residual 1 - x halves every step.
struct Halving {
    fail: bool,
}

impl Technique for Halving {
    const SUMMARY: &'static str = "test";
    type Settings = ();
    fn new(_: &()) -> Self {
        Halving { fail: false }
    }
    fn describe(&self) -> String {
        "halving".into()
    }
}

impl Solver for Halving {
    type State = f64;
    fn init(&self, _: &Scene) -> crate::Result<f64> {
        if self.fail {
            Err(Error::new("no patches"))
        } else {
            Ok(0.0)
        }
    }
    fn step(&self, _: &Scene, x: &mut f64, steps: u32, _: &mut RayCounts) -> SolverProgress {
        for _ in 0..steps {
            *x = (*x + 1.0) / 2.0;
        }
        SolverProgress {
            steps: u64::from(steps),
            residual: 1.0 - *x,
            converged: *x == 1.0,
            ..SolverProgress::default()
        }
    }
    fn radiance(
        &self,
        _: &Scene,
        x: &f64,
        _: Ray,
        _: PrimaryPixel<'_>,
        _: &mut Sampler,
        _: &mut RayCounts,
    ) -> Rgb {
        Rgb::splat(*x as f32)
    }
    fn display_spp(&self) -> u32 {
        2
    }
}

#[test]
fn a_solver_shows_only_its_latest_solution() {
    let session = session();
    let solver = Halving { fail: false };
    assert_eq!(
        SolverPass {
            session: &session,
            k: 1
        }
        .visit(&solver),
        (2, 1)
    );
    assert_eq!(
        SolverPass {
            session: &session,
            k: 2
        }
        .visit(&solver),
        (2, 2)
    );
    // Three steps: x = 7/8, and the film holds only its image.
    let snapshot = session.snapshot();
    assert!(snapshot.image.pixels.iter().all(|p| *p == [0.875; 3]));
    assert!(snapshot.samples.iter().all(|&n| n == 2));
    assert_eq!(
        session.error_estimate(&snapshot),
        ErrorEstimate::Residual(0.125)
    );
}

#[test]
fn a_solver_that_cannot_start_says_why() {
    let session = session();
    SolverPass {
        session: &session,
        k: 1,
    }
    .visit(&Halving { fail: true });
    assert_eq!(session.failure().unwrap().message(), "no patches");
}

#[test]
fn a_deterministic_estimator_has_no_sampling_error() {
    let mut session = session();
    session.settings.integrator = IntegratorOptions {
        kind: crate::integrator::IntegratorKind::Whitted,
        ..Default::default()
    }
    .build();
    assert!(session.render_pass(1));
    let snapshot = session.snapshot();
    assert_eq!(
        session.error_estimate(&snapshot),
        ErrorEstimate::Deterministic
    );
    assert_eq!(session.stats().passes, 1);
}
