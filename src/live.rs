//! Live rendering for interactive front ends: a background thread that keeps
//! adding passes to one session, or to two taking turns (a side-by-side
//! comparison), and publishes a snapshot after each pass.
//!
//! The API is the small one the viewer needs: [`LiveRender::start`],
//! [`LiveRender::restart`] (new settings), [`LiveRender::latest`] (the newest
//! published frame) and [`LiveRender::stop`]. The caller never waits for a
//! pass: `latest` only clones an `Arc` under a lock that the render thread
//! holds for as long as it takes to swap one in, and `restart` cancels the
//! running pass (it stops at its next tile) without waiting for it.

use crate::error::Result;
use crate::film::FilmSnapshot;
use crate::image::Image;
use crate::integrator::{ErrorEstimate, Integrator};
use crate::render::{RenderSettings, RenderStats, Session, thread_pool};
use crate::scene::Scene;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What keeps two configurations comparable: which one renders next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Lock {
    /// The one with fewer samples per pixel.
    #[default]
    EqualSpp,
    /// The one that has had less render time.
    EqualTime,
    /// The one that has cast fewer rays.
    EqualRays,
}

/// One configuration to render.
#[derive(Clone, Debug)]
pub struct LiveConfig {
    pub scene: Arc<Scene>,
    pub settings: RenderSettings,
    /// Stop at this many samples per pixel; `None` renders until stopped.
    pub target_spp: Option<u32>,
}

/// A point of a convergence curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorPoint {
    pub spp: u32,
    /// Units of progress ([`RenderStats::progress`]): spp, or solver steps.
    pub progress: u64,
    pub seconds: f64,
    /// What the session can say of its error without a reference
    /// ([`Session::error_estimate`]).
    pub estimate: ErrorEstimate,
    /// RMSE against the reference, when one is set and matches the image size.
    pub rmse: Option<f64>,
}

/// The latest state of one configuration.
#[derive(Clone, Debug)]
pub struct LiveView {
    /// The settings this view renders with.
    pub settings: RenderSettings,
    /// How its rays leave surfaces (a property of the scene it renders).
    pub offset: crate::math::OffsetMode,
    pub snapshot: Arc<FilmSnapshot>,
    pub stats: RenderStats,
    pub history: Vec<ErrorPoint>,
    /// Whether the target sample count is reached (a solver: converged and
    /// at the target), or the technique failed.
    pub done: bool,
    /// Why the technique could not run, if it could not.
    pub failure: Option<String>,
    /// Which small-scene shortcuts apply, or why not, one line each
    /// ([`Session::shortcut_report`]; made on the render thread, which
    /// builds the camera lists).
    pub shortcuts: Arc<Vec<String>>,
    /// A solver's notes on the scene ([`Session::solver_notes`]).
    pub notes: Arc<Vec<String>>,
}

/// Everything published after a pass.
#[derive(Clone, Debug, Default)]
pub struct LiveFrame {
    /// Counts calls to [`LiveRender::restart`]; frames of older settings are never shown.
    pub generation: u64,
    pub views: Vec<LiveView>,
    /// Time from the restart to this frame's first pass being published (per view).
    pub first_image_latency: Option<Duration>,
}

enum Command {
    Restart {
        generation: u64,
        configs: Vec<LiveConfig>,
        lock: Lock,
        reference: Option<Arc<Image>>,
        requested: Instant,
    },
    SetReference(Option<Arc<Image>>),
    Stop,
}

struct Shared {
    latest: Mutex<Arc<LiveFrame>>,
    running: Mutex<Vec<Arc<Session>>>,
}

/// A render thread driving sessions; see the module documentation.
pub struct LiveRender {
    shared: Arc<Shared>,
    commands: Sender<Command>,
    generation: u64,
    thread: Option<JoinHandle<()>>,
}

/// Longest pass the thread aims for; short passes keep snapshots frequent
/// and turns between two configurations fine-grained.
const PASS_TARGET: Duration = Duration::from_millis(40);

/// Parts the first pass of new settings is split into.
const FIRST_PASS_PARTS: u32 = 4;

/// Most points a convergence curve keeps; older points are thinned out.
const HISTORY_LIMIT: usize = 512;

impl LiveRender {
    /// Starts the render thread with `threads` workers (0 = one per core).
    pub fn start(threads: usize) -> Result<LiveRender> {
        let pool = thread_pool(threads)?;
        let shared = Arc::new(Shared {
            latest: Mutex::new(Arc::new(LiveFrame::default())),
            running: Mutex::new(Vec::new()),
        });
        let (commands, receiver) = channel();
        let thread_shared = shared.clone();
        let thread = std::thread::Builder::new()
            .name("tracelab-live".into())
            .spawn(move || render_loop(&thread_shared, &receiver, &pool))
            .map_err(|e| crate::Error::new(format!("cannot start the render thread: {e}")))?;
        Ok(LiveRender {
            shared,
            commands,
            generation: 0,
            thread: Some(thread),
        })
    }

    /// Cancels what is rendering and starts `configs` (one, or two to compare)
    /// from zero samples. Returns the new generation.
    pub fn restart(
        &mut self,
        configs: Vec<LiveConfig>,
        lock: Lock,
        reference: Option<Arc<Image>>,
    ) -> u64 {
        self.generation += 1;
        self.cancel_running();
        let _ = self.commands.send(Command::Restart {
            generation: self.generation,
            configs,
            lock,
            reference,
            requested: Instant::now(),
        });
        self.generation
    }

    /// Sets the image that RMSE is measured against from the next pass on,
    /// without restarting.
    pub fn set_reference(&mut self, reference: Option<Arc<Image>>) {
        let _ = self.commands.send(Command::SetReference(reference));
    }

    /// The generation of the last restart.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The newest published frame (possibly of an older generation).
    pub fn latest(&self) -> Arc<LiveFrame> {
        lock(&self.shared.latest).clone()
    }

    /// True while the thread has passes left to render for the current settings.
    pub fn is_rendering(&self) -> bool {
        let frame = self.latest();
        frame.generation != self.generation || frame.views.iter().any(|v| !v.done)
    }

    /// Stops the thread (cancelling the running pass) and waits for it.
    pub fn stop(&mut self) {
        self.cancel_running();
        let _ = self.commands.send(Command::Stop);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }

    fn cancel_running(&self) {
        for session in lock(&self.shared.running).iter() {
            session.cancel();
        }
    }
}

impl Drop for LiveRender {
    fn drop(&mut self) {
        self.stop();
    }
}

/// A poisoned lock only means a pass panicked; the data is still whole.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

struct Job {
    sessions: Vec<Arc<Session>>,
    targets: Vec<Option<u32>>,
    pass_sizes: Vec<u32>,
    lock: Lock,
    reference: Option<Arc<Image>>,
    requested: Instant,
    frame: LiveFrame,
}

fn render_loop(shared: &Shared, commands: &Receiver<Command>, pool: &Arc<rayon::ThreadPool>) {
    let mut job: Option<Job> = None;
    loop {
        // Take the newest command; block only when there is nothing to render.
        let idle = job
            .as_ref()
            .is_none_or(|j| j.frame.views.iter().all(|v| v.done));
        let command = if idle {
            match commands.recv() {
                Ok(c) => Some(c),
                Err(_) => return,
            }
        } else {
            match commands.try_recv() {
                Ok(c) => Some(c),
                Err(TryRecvError::Empty) => None,
                Err(TryRecvError::Disconnected) => return,
            }
        };
        match command {
            Some(Command::Stop) => return,
            Some(Command::SetReference(reference)) => {
                if let Some(job) = job.as_mut() {
                    job.reference = reference;
                }
                continue;
            }
            Some(Command::Restart {
                generation,
                configs,
                lock: lock_mode,
                reference,
                requested,
            }) => {
                let sessions: Vec<Arc<Session>> = configs
                    .iter()
                    .map(|c| {
                        Arc::new(Session::with_pool(
                            c.scene.clone(),
                            c.settings.clone(),
                            pool.clone(),
                        ))
                    })
                    .collect();
                *lock(&shared.running) = sessions.clone();
                let views = sessions
                    .iter()
                    .map(|s| LiveView {
                        settings: s.settings().clone(),
                        offset: s.scene().geometry.offset(),
                        snapshot: Arc::new(s.snapshot()),
                        stats: s.stats(),
                        history: Vec::new(),
                        done: false,
                        failure: None,
                        shortcuts: Arc::new(s.shortcut_report()),
                        notes: Arc::new(Vec::new()),
                    })
                    .collect();
                job = Some(Job {
                    targets: configs.iter().map(|c| c.target_spp).collect(),
                    pass_sizes: vec![1; sessions.len()],
                    sessions,
                    lock: lock_mode,
                    reference,
                    requested,
                    frame: LiveFrame {
                        generation,
                        views,
                        first_image_latency: None,
                    },
                });
                continue;
            }
            None => {}
        }
        let Some(job) = job.as_mut() else { continue };
        let Some(next) = job.next_view() else {
            continue;
        };
        let session = job.sessions[next].clone();
        if session.is_cancelled() {
            continue;
        }
        let stats = session.stats();
        let mut k = job.pass_sizes[next];
        if let Some(target) = job.targets[next] {
            k = k.min(target.saturating_sub(stats.spp)).max(1);
        }
        let start = Instant::now();
        if stats.passes == 0 {
            // The first pass of new settings comes in parts spread over the
            // image, each published, so the change shows at once.
            let parts = match session.settings().integrator {
                Integrator::Camera(_) => FIRST_PASS_PARTS,
                _ => 1,
            };
            let mut ok = true;
            for part in 0..parts {
                ok = session.render_pass_part(1, part, parts);
                if !ok {
                    if session.failure().is_some() {
                        job.publish(next, shared);
                    }
                    break;
                }
                job.publish(next, shared);
            }
            if ok {
                job.pass_sizes[next] = 1;
            }
            continue;
        }
        if !session.render_pass(k) {
            if session.failure().is_some() {
                job.publish(next, shared);
            }
            continue;
        }
        // Grow or shrink passes towards the target duration.
        let took = start.elapsed();
        job.pass_sizes[next] = if took < PASS_TARGET / 2 {
            (k * 2).min(256)
        } else if took > PASS_TARGET * 2 {
            (k / 2).max(1)
        } else {
            k
        };
        job.publish(next, shared);
    }
}

impl Job {
    /// The unfinished view that is furthest behind under the lock mode.
    fn next_view(&self) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for (i, session) in self.sessions.iter().enumerate() {
            if self.frame.views[i].done {
                continue;
            }
            let stats = session.stats();
            let progress = match self.lock {
                Lock::EqualSpp => f64::from(stats.spp),
                Lock::EqualTime => stats.render_time.as_secs_f64(),
                Lock::EqualRays => stats.rays.total() as f64,
            };
            if best.is_none_or(|(_, p)| progress < p) {
                best = Some((i, progress));
            }
        }
        best.map(|(i, _)| i)
    }

    fn publish(&mut self, index: usize, shared: &Shared) {
        let session = &self.sessions[index];
        let snapshot = session.snapshot();
        let stats = session.stats();
        let point = ErrorPoint {
            spp: stats.spp,
            progress: stats.progress,
            seconds: stats.render_time.as_secs_f64(),
            estimate: session.error_estimate(&snapshot),
            rmse: self
                .reference
                .as_ref()
                .and_then(|r| snapshot.image.compare(r).ok())
                .map(|m| m.rmse),
        };
        let view = &mut self.frame.views[index];
        if stats.passes > 0
            && view
                .history
                .last()
                .is_none_or(|p| p.progress < stats.progress)
        {
            view.history.push(point);
        }
        if view.history.len() > HISTORY_LIMIT {
            // Keep the first point and every other one after it: the curve
            // stays spread over the whole run in log scale.
            let mut i = 0;
            view.history.retain(|_| {
                i += 1;
                i == 1 || i % 2 == 0
            });
        }
        view.snapshot = Arc::new(snapshot);
        view.stats = stats;
        view.failure = session.failure().map(|e| e.to_string());
        let notes = session.solver_notes();
        if *view.notes != notes {
            view.notes = Arc::new(notes);
        }
        let target_reached = self.targets[index].is_some_and(|t| stats.spp >= t);
        // A solver is done once converged and its image has the target's
        // samples (until then its passes add samples to the same image).
        view.done = view.failure.is_some()
            || match stats.solver {
                Some(s) => s.converged && target_reached,
                None => target_reached,
            };
        if self.frame.first_image_latency.is_none() {
            self.frame.first_image_latency = Some(self.requested.elapsed());
        }
        *lock(&shared.latest) = Arc::new(self.frame.clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::IntegratorOptions;
    use crate::sampling::SamplerKind;

    fn small_cornell() -> Arc<Scene> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml");
        let mut scene = Scene::load(&path).unwrap();
        scene.set_resolution(32, 32);
        Arc::new(scene)
    }

    fn config(scene: &Arc<Scene>, spp: u32) -> LiveConfig {
        LiveConfig {
            scene: scene.clone(),
            settings: RenderSettings {
                integrator: IntegratorOptions::default().build(),
                sampler: SamplerKind::Independent,
                seed: 0,
                planned_spp: 0,
                threads: 0,
                adaptive: None,
                domains: Default::default(),
                clamp: None,
                filter_sampling: Default::default(),
            },
            target_spp: Some(spp),
        }
    }

    fn wait_done(live: &LiveRender) -> Arc<LiveFrame> {
        let start = Instant::now();
        while live.is_rendering() {
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "render never finished"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        live.latest()
    }

    #[test]
    fn renders_to_the_target_and_restarts_from_zero() {
        let scene = small_cornell();
        let mut live = LiveRender::start(2).unwrap();
        live.restart(vec![config(&scene, 16)], Lock::EqualSpp, None);
        let frame = wait_done(&live);
        assert_eq!(frame.generation, 1);
        assert_eq!(frame.views[0].stats.spp, 16);
        assert!(matches!(
            frame.views[0].history.last().unwrap().estimate,
            ErrorEstimate::Sampling(rmse) if rmse > 0.0
        ));

        live.restart(
            vec![config(&scene, 4), config(&scene, 8)],
            Lock::EqualSpp,
            None,
        );
        let frame = wait_done(&live);
        assert_eq!(frame.generation, 2);
        assert_eq!(frame.views.len(), 2);
        assert_eq!(frame.views[0].stats.spp, 4);
        assert_eq!(frame.views[1].stats.spp, 8);
        live.stop();
    }

    #[test]
    fn equal_spp_lock_keeps_two_views_within_one_pass() {
        let scene = small_cornell();
        let mut live = LiveRender::start(2).unwrap();
        let unlimited = |c: LiveConfig| LiveConfig {
            target_spp: None,
            ..c
        };
        live.restart(
            vec![unlimited(config(&scene, 0)), unlimited(config(&scene, 0))],
            Lock::EqualSpp,
            None,
        );
        std::thread::sleep(Duration::from_millis(300));
        let frame = live.latest();
        live.stop();
        let (a, b) = (frame.views[0].stats.spp, frame.views[1].stats.spp);
        assert!(a > 0 && b > 0);
        // The one behind always renders next, so neither leads by more than
        // one pass (at most 256 spp).
        assert!(a.abs_diff(b) <= 256, "{a} vs {b}");
    }
}
