//! The passes of multi-pass estimators and solvers: each is compiled for the
//! technique's concrete type through the visitors of `crate::integrator`.

use super::{Session, lock};
use crate::integrator::{MultiPassEstimator, MultiPassVisitor, RayCounts, Solver, SolverVisitor};
use std::sync::atomic::Ordering;

/// A multi-pass estimator's pass: `k` iterations, each a pre-pass (numbered
/// by the session's passes so far) and one sample per pixel reading it.
pub(super) struct MultiPass<'a> {
    pub(super) session: &'a Session,
    pub(super) first: u32,
    pub(super) k: u32,
}

impl MultiPassVisitor for MultiPass<'_> {
    type Output = (u32, u64);

    fn visit<E: MultiPassEstimator>(self, estimator: &E) -> (u32, u64) {
        let session = self.session;
        let settings = &session.settings;
        for i in 0..self.k {
            if session.cancelled.load(Ordering::Relaxed) {
                break;
            }
            let iteration = self.first + i;
            let mut counts = RayCounts::default();
            let pass = session.pool.install(|| {
                estimator.prepare(
                    &session.scene,
                    iteration,
                    settings.seed,
                    settings.sampler,
                    &mut counts,
                )
            });
            session.add_counts(0, &counts, 0);
            session.camera_pass(
                iteration,
                1,
                None,
                0,
                1,
                false,
                settings.sampler,
                |scene, ray, _, pixel, sampler, c| {
                    estimator.radiance(scene, &pass, ray, pixel, sampler, c)
                },
            );
        }
        (self.first + self.k, u64::from(self.k))
    }
}

/// A solver's pass: `k` solve steps, then a new image of the solution (the
/// film restarts: the solution it showed is gone), or, once the solution
/// has converged, more samples of the same image.
pub(super) struct SolverPass<'a> {
    pub(super) session: &'a Session,
    pub(super) k: u32,
}

impl SolverVisitor for SolverPass<'_> {
    type Output = (u32, u64);

    fn visit<S: Solver>(self, solver: &S) -> (u32, u64) {
        let session = self.session;
        let scene = &*session.scene;
        let mut state = lock(&session.solver_state);
        if state.is_none() {
            match session.pool.install(|| solver.init(scene)) {
                Ok(initial) => *state = Some(Box::new(initial)),
                Err(e) => {
                    *lock(&session.failure) = Some(e);
                    return (0, 0);
                }
            }
        }
        let Some(typed) = state.as_mut().and_then(|s| s.downcast_mut::<S::State>()) else {
            unreachable!("a session's solver state has its solver's type");
        };
        let before = *lock(&session.solver_progress);
        let mut counts = RayCounts::default();
        let progress = session
            .pool
            .install(|| solver.step(scene, typed, self.k, &mut counts));
        session.add_counts(0, &counts, 0);
        *lock(&session.solver_progress) = Some(progress);
        *lock(&session.solver_notes) = solver.notes(typed);
        // A converged solution that this pass left as it was keeps its
        // image, which gains samples (the gather display's noise falls);
        // any other pass draws the new solution on a clear film.
        let unchanged = before.is_some_and(|b| b.converged && b.steps == progress.steps);
        let first = if unchanged {
            session.spp.load(Ordering::Relaxed)
        } else {
            session.film.clear();
            0
        };
        let spp = solver.display_spp().max(1);
        let typed = &*typed;
        session.camera_pass(
            first,
            spp,
            None,
            0,
            1,
            spp == 1,
            solver.display_sampler().unwrap_or(session.settings.sampler),
            |scene, ray, pixel, _, sampler, c| {
                solver.radiance(scene, typed, ray, pixel, sampler, c)
            },
        );
        (first + spp, u64::from(self.k))
    }
}
