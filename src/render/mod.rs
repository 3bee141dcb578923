//! A render session: the one API every front end drives (the CLI, the tests
//! and, through [`crate::live`], the viewer). A session owns a film and a
//! thread pool; its unit of progress is a pass ([`Session::render_pass`]),
//! whatever the kind of technique ([`crate::integrator::TechniqueKind`]):
//! k samples more for every pixel (camera estimators), k particles per pixel
//! splatted anywhere (splatting estimators), k iterations of a pre-pass and
//! one sample per pixel (multi-pass estimators), or k solve steps and a new
//! image of the solution (solvers). Between passes, callers take snapshots,
//! read statistics and the error estimate, or cancel.
//!
//! Sample `s` of pixel `p` is a pure function of (seed, p, s), and each pixel's
//! samples are summed in sample order, so the film is bit-identical whatever
//! the thread count or tile schedule.

use crate::error::{Error, Result};
use crate::film::filtered::{self, Apron, PassAprons};
use crate::film::{Film, FilmSnapshot, Tile, classify, non_finite_of, note_flagged};
use crate::filter::{FilterSampling, PixelFilter};
use crate::integrator::{ErrorEstimate, Integrator, RayCounts, SolverProgress, camera_ray_through};
use crate::math::{Ray, Rgb};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domains, Sampler, SamplerKind};
use crate::scene::Scene;
use crate::shortcuts::{CameraSampling, PrimaryPixel};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use technique_passes::{MultiPass, SolverPass};

/// How to render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub integrator: Integrator,
    pub sampler: SamplerKind,
    pub seed: u64,
    /// Samples per pixel the render plans to take (0 = unknown); stratified
    /// samplers stratify over batches of this size.
    pub planned_spp: u32,
    /// Worker threads (0 = one per core).
    pub threads: usize,
    /// Stop sampling pixels that have converged (off by default).
    pub adaptive: Option<Adaptive>,
    /// Domains the sampler applies to; the others are independent.
    pub domains: Domains,
    /// Scale down any sample whose largest component exceeds this (off by
    /// default): removes fireflies at the price of bias, and is reported so.
    pub clamp: Option<f32>,
    /// How camera samples meet a pixel filter wider than the box (splatted
    /// by default, as Mitsuba's film; importance-sampled under adaptive
    /// sampling, whose per-pixel counts a splat would mix).
    pub filter_sampling: FilterSampling,
}

/// Adaptive sampling: samples go where the noise is rather than evenly.
/// `Stop` trades a little bias for time (a pixel's count depends on its own
/// noisy error estimate); `Distribute` sets a pixel's count from its
/// neighbours' noise, which keeps its mean unbiased to first order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adaptive {
    /// A pixel with at least `min_spp` samples whose relative standard error
    /// (luminance) is below `threshold` gets no further samples: for
    /// relative noise (dark regions), and it saves time, not RMSE.
    Stop { threshold: f32, min_spp: u32 },
    /// After `warmup_spp` samples everywhere, each pass spreads its samples
    /// (spp x pixels in all) over the pixels in proportion to their noise
    /// ([`crate::allocation`]): minimises the RMSE for the time spent.
    /// [`RenderStats::spp`] is then the mean count.
    Distribute { warmup_spp: u32 },
}

/// Counters of a session so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Samples per pixel completed (every pixel has this many; with
    /// [`Adaptive`] sampling, the mean over pixels of what passes planned).
    /// For a solver, the samples per pixel of the image of its solution.
    pub spp: u32,
    /// Passes completed.
    pub passes: u64,
    /// Units of progress completed: samples per pixel, or a solver's steps.
    pub progress: u64,
    /// A solver's progress after its last pass.
    pub solver: Option<SolverProgress>,
    /// Camera samples taken (= camera paths).
    pub samples: u64,
    pub rays: RayCounts,
    /// Samples that were NaN or infinite and were left out of the film.
    pub non_finite: u64,
    /// Samples adaptive sampling did not take (converged pixels).
    pub skipped: u64,
    /// Finite samples brighter than [`crate::film::EXTREME_LUMINANCE`].
    pub extreme: u64,
    /// Samples scaled down by [`RenderSettings::clamp`].
    pub clamped: u64,
    /// Wall time spent inside passes.
    pub render_time: Duration,
}

/// A progressive render of one scene with fixed settings.
pub struct Session {
    scene: Arc<Scene>,
    settings: RenderSettings,
    film: Film,
    pool: Arc<rayon::ThreadPool>,
    spp: AtomicU32,
    passes: AtomicU64,
    progress: AtomicU64,
    samples: AtomicU64,
    camera_rays: AtomicU64,
    shadow_rays: AtomicU64,
    bounce_rays: AtomicU64,
    non_finite: AtomicU64,
    extreme: AtomicU64,
    clamped: AtomicU64,
    skipped: AtomicU64,
    render_nanos: AtomicU64,
    cancelled: AtomicBool,
    /// Samples per pixel of the pass in progress under
    /// [`Adaptive::Distribute`], made by its part 0 for all its parts.
    pass_plan: Mutex<Option<Arc<Vec<u32>>>>,
    /// A solver's state between passes, typed by the solver
    /// ([`Solver::State`]); `None` until the first pass.
    solver_state: Mutex<Option<Box<dyn std::any::Any + Send + Sync>>>,
    solver_progress: Mutex<Option<SolverProgress>>,
    /// A solver's notes on the scene ([`crate::integrator::Solver::notes`]).
    solver_notes: Mutex<Vec<String>>,
    /// Why the technique could not run (a solver's set-up failed).
    failure: Mutex<Option<Error>>,
}

impl Session {
    /// Starts a session with its own `settings.threads` worker threads;
    /// nothing renders until [`Session::render_pass`].
    /// Refuses, before allocating, a render whose film would not fit in
    /// the memory available ([`Session::memory_estimate`]).
    pub fn new(scene: Arc<Scene>, settings: RenderSettings) -> Result<Session> {
        let needed = Session::memory_estimate(&scene, &settings);
        if let Some(available) = available_memory()
            && needed > available
        {
            return Err(Error::new(format!(
                "a {}x{} render needs about {:.1} GB for its film, image and buffers, more than the {:.1} GB available",
                scene.camera.width,
                scene.camera.height,
                needed as f64 * 1e-9,
                available as f64 * 1e-9
            )));
        }
        let pool = thread_pool(settings.threads)?;
        Ok(Self::with_pool(scene, settings, pool))
    }

    /// Starts a session on an existing pool (sessions that take turns share one).
    pub fn with_pool(
        scene: Arc<Scene>,
        settings: RenderSettings,
        pool: Arc<rayon::ThreadPool>,
    ) -> Session {
        let settings = RenderSettings {
            integrator: settings.integrator.for_scene(&scene),
            ..settings
        };
        let film = Film::new(scene.camera.width, scene.camera.height);
        Session {
            scene,
            settings,
            film,
            pool,
            spp: AtomicU32::new(0),
            passes: AtomicU64::new(0),
            progress: AtomicU64::new(0),
            samples: AtomicU64::new(0),
            camera_rays: AtomicU64::new(0),
            shadow_rays: AtomicU64::new(0),
            bounce_rays: AtomicU64::new(0),
            non_finite: AtomicU64::new(0),
            extreme: AtomicU64::new(0),
            clamped: AtomicU64::new(0),
            skipped: AtomicU64::new(0),
            render_nanos: AtomicU64::new(0),
            cancelled: AtomicBool::new(false),
            pass_plan: Mutex::new(None),
            solver_state: Mutex::new(None),
            solver_progress: Mutex::new(None),
            solver_notes: Mutex::new(Vec::new()),
            failure: Mutex::new(None),
        }
    }

    /// Bytes a session of `settings` on `scene` allocates, in all: per
    /// pixel the film's statistics, a splatting estimator's buffer, the
    /// aprons of camera samples splatted through the filter and the image
    /// it ends with, and VCM's light vertices of an iteration.
    pub fn memory_estimate(scene: &Scene, settings: &RenderSettings) -> u64 {
        let pixels = u64::from(scene.camera.width) * u64::from(scene.camera.height);
        let film = std::mem::size_of::<crate::film::PixelSums>() as u64;
        let image = 12;
        let threads = match settings.threads {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            n => n,
        };
        // A splat buffer's shards, one per thread as memory allows.
        let shards = crate::film::splats::shard_count(pixels, threads) as u64;
        let splats = match settings.integrator {
            Integrator::Splatting(_) => crate::film::splats::SPLAT_BYTES * shards,
            _ => 0,
        };
        // Camera passes that splat keep the weights each pixel received, and
        // an apron per tile until the pass ends.
        let aprons = match settings.integrator {
            Integrator::Splatting(e) if !e.has_camera_strategies() => 0,
            _ if settings.filter_sampling == FilterSampling::Splat
                && filtered::can_splat(scene.camera.filter) =>
            {
                let side =
                    u64::from(crate::film::TILE_SIZE + 2 * filtered::reach(scene.camera.filter));
                let tile = u64::from(crate::film::TILE_SIZE).pow(2);
                (side * side * std::mem::size_of::<filtered::SplatCell>() as u64).div_ceil(tile)
                    + std::mem::size_of::<filtered::WeightSums>() as u64
            }
            _ => 0,
        };
        let iteration = match settings.integrator {
            Integrator::MultiPass(crate::integrator::MultiPassIntegrator::Vcm(_)) => {
                crate::integrator::vcm::Vcm::memory_per_iteration(scene, threads)
            }
            _ => 0,
        };
        pixels * (film + image + splats + aprons) + iteration
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Asks running and future passes to stop at the next tile.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Renders one pass of size `k` (see the module documentation).
    /// Returns false (and leaves the film with a partial pass that
    /// [`RenderStats::spp`] does not count) when cancelled or failed.
    pub fn render_pass(&self, k: u32) -> bool {
        self.render_pass_part(k, 0, 1)
    }

    /// Renders part `part` of `parts` of a pass of size `k`. Camera
    /// estimators render the tiles whose index is `part` modulo `parts`,
    /// spread over the image, and the film is the same as after one whole
    /// pass; a live view uses parts to show the first pass of new settings
    /// sooner. The other kinds need the whole film at once (splats land
    /// anywhere, a pre-pass or a solve step serves every pixel), so they
    /// render the whole pass with part 0 and skip the others. The pass
    /// counts (in [`RenderStats`]) once complete.
    pub fn render_pass_part(&self, k: u32, part: u32, parts: u32) -> bool {
        if lock(&self.failure).is_some() {
            return false;
        }
        let start = Instant::now();
        let first = self.spp.load(Ordering::Relaxed);
        let parts = parts.max(1);
        let whole_film = !matches!(self.settings.integrator, Integrator::Camera(_));
        if whole_film && part != 0 {
            return !self.cancelled.load(Ordering::Relaxed);
        }
        let (spp, progress) = match self.settings.integrator {
            Integrator::Camera(estimator) => {
                let plan = self.pass_plan(first, k, part);
                let pixel_plan = plan.as_deref().map(Vec::as_slice);
                let deterministic = estimator.is_deterministic();
                self.camera_pass(
                    first,
                    k,
                    pixel_plan,
                    part,
                    parts,
                    deterministic,
                    self.settings.sampler,
                    |s, r, p, _, sa, c| estimator.radiance(s, r, p, sa, c),
                );
                (first + k, u64::from(k))
            }
            Integrator::Splatting(estimator) => {
                self.splat_pass(&estimator, first, k);
                (first + k, u64::from(k))
            }
            Integrator::MultiPass(estimator) => estimator.visit(MultiPass {
                session: self,
                first,
                k,
            }),
            Integrator::Solver(solver) => solver.visit(SolverPass { session: self, k }),
        };
        self.render_nanos
            .fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        if self.cancelled.load(Ordering::Relaxed) || self.failure().is_some() {
            return false;
        }
        if whole_film || part + 1 == parts {
            self.spp.store(spp, Ordering::Relaxed);
            self.passes.fetch_add(1, Ordering::Relaxed);
            self.progress.fetch_add(progress, Ordering::Relaxed);
        }
        true
    }

    /// True when the technique's camera samples are splatted through the
    /// scene's pixel filter ([`FilterSampling::Splat`]; not with the box,
    /// adaptive sampling, a deterministic technique, or a splatting
    /// technique without camera strategies).
    pub fn splats_camera_samples(&self) -> bool {
        self.splats_through_filter(self.settings.integrator.is_deterministic())
            && match self.settings.integrator {
                Integrator::Splatting(e) => e.has_camera_strategies(),
                _ => true,
            }
    }

    /// Whether a pass's camera samples, `deterministic` or not, are
    /// splatted through the scene's filter: the one rule of
    /// [`Session::splats_camera_samples`] and the passes.
    fn splats_through_filter(&self, deterministic: bool) -> bool {
        splats_through_filter(&self.scene, &self.settings, deterministic)
    }

    /// Why the technique could not run, if it could not.
    pub fn failure(&self) -> Option<Error> {
        lock(&self.failure).clone()
    }

    /// What the session can say about its error without a reference:
    /// the RMS of the pixels' standard errors (`snapshot` from
    /// [`Session::snapshot`]), nothing for a deterministic estimator, a
    /// solver's residual.
    pub fn error_estimate(&self, snapshot: &FilmSnapshot) -> ErrorEstimate {
        if let Some(progress) = *lock(&self.solver_progress) {
            return ErrorEstimate::Residual(progress.residual);
        }
        if self.settings.integrator.is_deterministic() {
            return ErrorEstimate::Deterministic;
        }
        let rmse = snapshot.estimated_rmse();
        if rmse.is_finite() {
            ErrorEstimate::Sampling(rmse)
        } else {
            ErrorEstimate::Unknown
        }
    }

    /// Per-pixel sample counts for the pass of `spp` that starts at `first`
    /// spp, under [`Adaptive::Distribute`] once the warm-up is done; made by
    /// part 0 and shared by the other parts of the pass.
    fn pass_plan(&self, first: u32, spp: u32, part: u32) -> Option<Arc<Vec<u32>>> {
        let Some(Adaptive::Distribute { warmup_spp }) = self.settings.adaptive else {
            return None;
        };
        let mut shared = self.pass_plan.lock().unwrap_or_else(|e| e.into_inner());
        if part == 0 {
            *shared = (first >= warmup_spp).then(|| {
                let budget = u64::from(spp) * u64::from(self.film.width() * self.film.height());
                let key = hash_combine(self.settings.seed, u64::from(first));
                Arc::new(crate::allocation::plan(
                    &self.film.noise(),
                    self.film.width(),
                    self.film.height(),
                    budget,
                    crate::allocation::variance_exponent(self.settings.sampler),
                    key,
                ))
            });
        }
        shared.clone()
    }

    /// Camera samples: `spp` samples (or `plan`'s count) more for every
    /// pixel of the tiles in part `part` of `parts`, each `estimate`d along
    /// its camera ray. Samples are numbered from `first`, or under
    /// [`Adaptive::Distribute`] from the pixel's own count.
    #[allow(clippy::too_many_arguments)]
    fn camera_pass<E>(
        &self,
        first: u32,
        spp: u32,
        plan: Option<&[u32]>,
        part: u32,
        parts: u32,
        deterministic: bool,
        sampler: SamplerKind,
        estimate: E,
    ) where
        E: Fn(&Scene, Ray, PrimaryPixel<'_>, (u32, u32), &mut Sampler, &mut RayCounts) -> Rgb
            + Sync,
    {
        let scene = &*self.scene;
        let settings = &self.settings;
        let general = matches!(settings.integrator, Integrator::Camera(e) if e.is_general());
        let width = self.film.width();
        // Samples uniform in their pixels, splatted through the filter
        // (crate::film::filtered), or drawn from it and kept in their pixel.
        let filter = scene.camera.filter;
        let splat = self.splats_through_filter(deterministic);
        let position_filter = if splat { PixelFilter::Box } else { filter };
        let sampling = CameraSampling::of(filter, splat, deterministic);
        let primary = scene
            .primary_candidates()
            .filter(|_| sampling.lists_apply());
        let seen_emission = sampling.seen_emission_applies();
        let aprons = PassAprons::new(self.film.tiles().len(), splat);
        self.pool.install(|| {
            self.film
                .tiles()
                .par_iter()
                .enumerate()
                // One job per tile, so an idle thread can take any tile not
                // started. Left to itself rayon runs quarters of the tile
                // list as unsplittable runs once nothing is stolen early:
                // with samples spread by noise one thread then rendered a
                // run of heavy tiles alone while the other waited (2 threads:
                // 99% of the passes' CPU time busy with Neyman shares, 80%
                // with the variance^2/5 ones).
                .with_max_len(1)
                .for_each(|(index, tile)| {
                    if index as u32 % parts != part || self.cancelled.load(Ordering::Relaxed) {
                        return;
                    }
                    let mut tile = tile.lock().unwrap_or_else(|e| e.into_inner());
                    let mut apron = splat.then(|| Apron::new(&tile, filter));
                    let mut sampler = Sampler::new(sampler, settings.seed, settings.planned_spp)
                        .with_domains(settings.domains);
                    // The next sample's, whose camera ray is made while this
                    // sample's path is traced (below).
                    let mut ahead = sampler.clone();
                    let mut counts = RayCounts::default();
                    let mut non_finite = 0u64;
                    let mut skipped = 0u64;
                    let (mut extreme, mut clamped) = (0u64, 0u64);
                    let (x0, y0, tile_width) = (tile.x0, tile.y0, tile.width);
                    let Tile { pixels, flags, .. } = &mut *tile;
                    for (i, pixel) in pixels.iter_mut().enumerate() {
                        let (x, y) = (x0 + i as u32 % tile_width, y0 + i as u32 / tile_width);
                        let pixel_index = y * width + x;
                        let (begin, count) = match settings.adaptive {
                            Some(Adaptive::Stop { threshold, min_spp })
                                if pixel.count >= min_spp
                                    && pixel.relative_standard_error() < threshold =>
                            {
                                skipped += u64::from(spp);
                                continue;
                            }
                            Some(Adaptive::Distribute { .. }) => {
                                let taken = pixel.count + non_finite_of(flags, i as u32);
                                (taken, plan.map_or(spp, |p| p[pixel_index as usize]))
                            }
                            _ => (first, spp),
                        };
                        if count == 0 {
                            continue;
                        }
                        // A camera sample is a long chain of dependent hashes
                        // and a division. Made one sample ahead, by a second
                        // sampler, it runs beside the path before it instead
                        // of holding up its own.
                        let end = begin + count;
                        let mut known = primary.map(|p| p.pixel(pixel_index)).unwrap_or_default();
                        known.seen_emission = known.seen_emission.filter(|_| seen_emission);
                        let through = |s: &mut Sampler| {
                            camera_ray_through(
                                scene,
                                s,
                                x,
                                y,
                                deterministic,
                                general,
                                position_filter,
                            )
                        };
                        ahead.start(pixel_index, begin);
                        let mut ray_ahead = through(&mut ahead);
                        for s in begin..end {
                            std::mem::swap(&mut sampler, &mut ahead);
                            let (ray, film_point) = ray_ahead;
                            if s + 1 < end {
                                ahead.start(pixel_index, s + 1);
                                ray_ahead = through(&mut ahead);
                            }
                            counts.camera += 1;
                            let mut value =
                                estimate(scene, ray, known, (x, y), &mut sampler, &mut counts);
                            let (finite, is_extreme) = classify(value);
                            if !finite || is_extreme {
                                note_flagged(flags, i as u32, s, finite);
                            }
                            non_finite += u64::from(!finite);
                            extreme += u64::from(is_extreme);
                            if let Some(limit) = settings.clamp {
                                clamped += u64::from(clamp_sample(&mut value, limit));
                            }
                            if finite {
                                match apron.as_mut() {
                                    Some(apron) => {
                                        apron.splat(film_point, value);
                                        pixel.count += 1;
                                    }
                                    None => pixel.add(value),
                                }
                            }
                        }
                    }
                    drop(tile);
                    if let Some(apron) = apron {
                        aprons.put(index, apron);
                    }
                    self.add_counts(counts.camera, &counts, non_finite);
                    self.skipped.fetch_add(skipped, Ordering::Relaxed);
                    self.extreme.fetch_add(extreme, Ordering::Relaxed);
                    self.clamped.fetch_add(clamped, Ordering::Relaxed);
                });
            if splat && !self.cancelled.load(Ordering::Relaxed) {
                let aprons = aprons.into_aprons();
                let across = self.film.tiles_across();
                self.film.tiles().par_iter().for_each(|tile| {
                    let mut tile = tile.lock().unwrap_or_else(|e| e.into_inner());
                    filtered::fold(&mut tile, &aprons, across);
                });
            }
        });
    }

    fn add_counts(&self, samples: u64, counts: &RayCounts, non_finite: u64) {
        self.samples.fetch_add(samples, Ordering::Relaxed);
        self.camera_rays.fetch_add(counts.camera, Ordering::Relaxed);
        self.shadow_rays.fetch_add(counts.shadow, Ordering::Relaxed);
        self.bounce_rays.fetch_add(counts.bounce, Ordering::Relaxed);
        self.non_finite.fetch_add(non_finite, Ordering::Relaxed);
    }

    /// True once [`Session::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    /// Ends the session: its image, made while the film is taken apart, with
    /// the scene (and what it holds per pixel) released first, so that the
    /// end of a large render needs little more than the film.
    pub fn into_final(self) -> crate::film::FinalImage {
        let Session { scene, film, .. } = self;
        drop(scene);
        film.into_final()
    }

    /// A solver's notes on the scene after its last pass (surfaces left
    /// out, materials approximated), one line each.
    pub fn solver_notes(&self) -> Vec<String> {
        lock(&self.solver_notes).clone()
    }

    /// Which small-scene shortcuts apply to this render, or why not, one
    /// line each ([`Scene::shortcut_report`]).
    pub fn shortcut_report(&self) -> Vec<String> {
        let deterministic = self.settings.integrator.is_deterministic();
        let sampling = CameraSampling::of(
            self.scene.camera.filter,
            self.splats_through_filter(deterministic),
            deterministic,
        );
        self.scene
            .shortcut_report(self.settings.integrator.shortcuts_used(), sampling)
    }

    /// The fewest and the most samples any pixel has.
    pub fn sample_count_range(&self) -> (u32, u32) {
        self.film.sample_count_range()
    }

    /// Copies the film (means, standard errors, counts) while passes may run.
    pub fn snapshot(&self) -> FilmSnapshot {
        self.film.snapshot()
    }

    /// Counters so far.
    pub fn stats(&self) -> RenderStats {
        RenderStats {
            spp: self.spp.load(Ordering::Relaxed),
            passes: self.passes.load(Ordering::Relaxed),
            progress: self.progress.load(Ordering::Relaxed),
            solver: *lock(&self.solver_progress),
            samples: self.samples.load(Ordering::Relaxed),
            rays: RayCounts {
                camera: self.camera_rays.load(Ordering::Relaxed),
                shadow: self.shadow_rays.load(Ordering::Relaxed),
                bounce: self.bounce_rays.load(Ordering::Relaxed),
            },
            non_finite: self.non_finite.load(Ordering::Relaxed),
            skipped: self.skipped.load(Ordering::Relaxed),
            extreme: self.extreme.load(Ordering::Relaxed),
            clamped: self.clamped.load(Ordering::Relaxed),
            render_time: Duration::from_nanos(self.render_nanos.load(Ordering::Relaxed)),
        }
    }
}

/// Memory the system can give without swapping (Linux's MemAvailable), if known.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// A poisoned lock only means a pass panicked; the data is still whole.
fn lock<T: ?Sized>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Scales `value` down so that its largest component is at most `limit`;
/// returns true when it did.
#[inline]
pub fn clamp_sample(value: &mut Rgb, limit: f32) -> bool {
    let max = value.max_element();
    if max > limit && value.is_finite() {
        *value *= limit / max;
        true
    } else {
        false
    }
}

/// Whether a render's camera samples, `deterministic` or not, are splatted
/// through the scene's filter (drawn uniformly in their pixel), the rule
/// of the passes and of [`crate::replay`].
pub(crate) fn splats_through_filter(
    scene: &Scene,
    settings: &RenderSettings,
    deterministic: bool,
) -> bool {
    settings.filter_sampling == FilterSampling::Splat
        && filtered::can_splat(scene.camera.filter)
        && settings.adaptive.is_none()
        && !deterministic
}

/// A pool of `threads` render threads (0 = one per core).
pub fn thread_pool(threads: usize) -> Result<Arc<rayon::ThreadPool>> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("tracelab-render-{i}"))
        .build()
        .map(Arc::new)
        .map_err(|e| Error::new(format!("cannot start render threads: {e}")))
}

mod splat_pass;
mod technique_passes;

#[cfg(test)]
mod tests;
