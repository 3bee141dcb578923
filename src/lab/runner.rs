//! Running an experiment off the caller's thread: progress counters, the
//! latest partial report, cancellation. The CLI polls it for its progress
//! bar; the viewer for its counters and live figures.

use super::{Cancelled, Experiment, LabSettings, Report};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Shared between an experiment and whoever watches it.
#[derive(Debug, Default)]
pub struct Progress {
    /// Units of work done and planned (samples, flips, evaluations).
    done: AtomicU64,
    planned: AtomicU64,
    cancel: AtomicBool,
    latest: Mutex<Option<Arc<Report>>>,
    /// When the last stage was published (for the viewer's pacing).
    last_publish: Mutex<Option<Instant>>,
    pace: Mutex<Duration>,
}

impl Progress {
    /// Counters for a run that publishes at most every `pace`.
    pub fn new(pace: Duration) -> Progress {
        Progress {
            pace: Mutex::new(pace),
            ..Progress::default()
        }
    }

    /// Adds `units` to the planned work.
    pub fn plan(&self, units: u64) {
        self.planned.fetch_add(units, Ordering::Relaxed);
    }

    /// Records `units` of work done; says whether to stop.
    #[inline]
    pub fn advance(&self, units: u64) -> Result<(), Cancelled> {
        self.done.fetch_add(units, Ordering::Relaxed);
        self.check()
    }

    /// `Err(Cancelled)` once [`Progress::cancel`] was called.
    #[inline]
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.cancel.load(Ordering::Relaxed) {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }

    /// Asks the experiment to stop at its next check.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether the run was asked to stop.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Work done and planned.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.planned.load(Ordering::Relaxed),
        )
    }

    /// Makes `report` the latest partial result; waits out the pacing first,
    /// so that a live view shows each stage.
    pub fn publish(&self, report: &Report) {
        let pace = *self.pace.lock().unwrap_or_else(|e| e.into_inner());
        if !pace.is_zero() {
            let last = *self.last_publish.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(last) = last {
                let wait = pace.saturating_sub(last.elapsed());
                // Sleep in slices so that a cancel is seen promptly.
                let until = Instant::now() + wait;
                while Instant::now() < until && !self.is_cancelled() {
                    std::thread::sleep((until - Instant::now()).min(Duration::from_millis(10)));
                }
            }
        }
        *self.last_publish.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
        *self.latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(Arc::new(report.clone()));
    }

    /// The latest report published.
    pub fn latest(&self) -> Option<Arc<Report>> {
        self.latest
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
}

/// One experiment running on its own thread.
pub struct LabRunner {
    pub settings: LabSettings,
    progress: Arc<Progress>,
    thread: Option<JoinHandle<Result<Report, Cancelled>>>,
    started: Instant,
    finished: Option<(Result<Arc<Report>, Cancelled>, Duration)>,
}

impl LabRunner {
    /// Starts `settings.experiment` on a new thread.
    pub fn start(settings: LabSettings) -> LabRunner {
        let progress = Arc::new(Progress::new(settings.pace));
        let thread = {
            let (settings, progress) = (settings.clone(), progress.clone());
            std::thread::Builder::new()
                .name(format!("lab-{}", settings.experiment.name()))
                .spawn(move || settings.experiment.run(&settings, &progress))
                .ok()
        };
        LabRunner {
            settings,
            progress,
            thread,
            started: Instant::now(),
            finished: None,
        }
    }

    /// The experiment.
    pub fn experiment(&self) -> Experiment {
        self.settings.experiment
    }

    /// The shared counters.
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// Collects the result once the thread has finished; returns whether it has.
    pub fn poll(&mut self) -> bool {
        if self.finished.is_some() {
            return true;
        }
        match &self.thread {
            Some(t) if !t.is_finished() => false,
            _ => {
                let result = match self.thread.take().map(JoinHandle::join) {
                    Some(Ok(result)) => result.map(Arc::new),
                    // A panic or a thread that could not start: reported as
                    // cancelled, the viewer shows no result.
                    _ => Err(Cancelled),
                };
                self.finished = Some((result, self.started.elapsed()));
                true
            }
        }
    }

    /// Whether the experiment is still running.
    pub fn is_running(&mut self) -> bool {
        !self.poll()
    }

    /// The final report, or the latest partial one while it runs.
    pub fn report(&self) -> Option<Arc<Report>> {
        match &self.finished {
            Some((Ok(report), _)) => Some(report.clone()),
            _ => self.progress.latest(),
        }
    }

    /// Seconds the run has taken (so far, or in all once finished).
    pub fn seconds(&self) -> f64 {
        match &self.finished {
            Some((_, elapsed)) => elapsed.as_secs_f64(),
            None => self.started.elapsed().as_secs_f64(),
        }
    }

    /// Whether the run ended by a cancel.
    pub fn was_cancelled(&self) -> bool {
        matches!(self.finished, Some((Err(Cancelled), _)))
    }

    /// Asks the experiment to stop and waits for it.
    pub fn cancel(&mut self) {
        self.progress.cancel();
        self.poll_blocking();
    }

    /// Waits for the thread to finish.
    pub fn poll_blocking(&mut self) {
        if let Some(t) = &self.thread {
            while !t.is_finished() {
                std::thread::sleep(Duration::from_millis(2));
            }
        }
        self.poll();
    }
}

impl Drop for LabRunner {
    fn drop(&mut self) {
        self.progress.cancel();
    }
}
