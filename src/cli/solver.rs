//! Driving a solver technique from the command line: passes of 1, 2, 4, ...
//! steps until it converges, then (with a time budget) more samples of the
//! converged solution's image.

use super::shared::progress_bar;
use std::time::Duration;
use tracelab::Result;
use tracelab::integrator::SolverProgress;
use tracelab::render::{RenderStats, Session};

/// Runs a solver's steps until it converges (or reaches its step limit),
/// in passes of 1, 2, 4, ... steps, each followed by an image of the
/// solution; `after_pass` sees the statistics after each pass.
pub(crate) fn drive_solver(
    session: &Session,
    mut after_pass: impl FnMut(&RenderStats, &SolverProgress),
) -> Result<RenderStats> {
    let mut steps = 1;
    loop {
        if !session.render_pass(steps) {
            break;
        }
        let stats = session.stats();
        let Some(progress) = stats.solver else { break };
        after_pass(&stats, &progress);
        if progress.converged {
            break;
        }
        // Each pass ends with an image of the solution; doubling keeps
        // their number logarithmic in the steps (progressive refinement
        // takes thousands of shots).
        steps = steps.saturating_mul(2);
    }
    if let Some(e) = session.failure() {
        return Err(e);
    }
    for note in session.solver_notes() {
        eprintln!("note: {note}");
    }
    Ok(session.stats())
}

/// One pass after another until the session's render time reaches `limit`.
pub(crate) fn render_until(session: &Session, limit: Duration) -> RenderStats {
    while session.stats().render_time < limit {
        if !session.render_pass(1) {
            break;
        }
    }
    session.stats()
}

/// [`drive_solver`] with a progress bar.
pub(crate) fn render_solver(session: &Session) -> Result<RenderStats> {
    let bar = progress_bar(1, "steps");
    let stats = drive_solver(session, |_, progress| {
        bar.set_message(format!("residual {:.2e}", progress.residual));
        bar.set_position(progress.steps);
    });
    bar.finish_and_clear();
    stats
}
