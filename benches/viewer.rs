//! Responsiveness of the viewer, driven headless through egui_kittest (the
//! real app, without a window): UI frame times while rendering, time from a
//! setting change to the first image of the new settings, CPU-time fairness
//! of an equal-time comparison, memory over a long session, and UI frame
//! times in the MC lab tab while its experiments run
//! (`TRACELAB_BENCH_ONLY=lab` measures only those;
//! `TRACELAB_BENCH_ONLY=transport` only BDPT's, photon mapping's and VCM's frames;
//! `TRACELAB_BENCH_ONLY=radiosity` only radiosity's, while it solves).
//!
//! `cargo bench --bench viewer` (TRACELAB_SOAK_SECONDS=600 for the 10-minute
//! memory figure). Prints a table; asserts nothing.

use eframe::egui::Vec2;
use egui_kittest::Harness;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use tracelab::integrator::IntegratorKind;
use tracelab::lab::Experiment;
use tracelab::live::Lock;
use tracelab::sampling::SamplerKind;
use tracelab::viewer::stats::resident_memory_mib;
use tracelab::viewer::{Launch, Tab, Window};

fn harness() -> Harness<'static, Window> {
    let launch = Launch {
        scene: Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/cornell_box.toml"
        ))),
        threads: 0,
        fresh: true,
        export_dir: Some(std::env::temp_dir().join("tracelab-bench-exports")),
        ..Default::default()
    };
    let mut h = Harness::builder()
        .with_size(Vec2::new(1280.0, 820.0))
        .build_eframe(move |cc| Window::new(cc, launch));
    let app = &mut h.state_mut().app;
    app.settings.resolution = Some((512, 512));
    app.settings.unlimited = true;
    h
}

/// One UI frame at about 60 Hz; returns how long the frame took.
fn frame(h: &mut Harness<'static, Window>) -> Duration {
    let start = Instant::now();
    h.step();
    let took = start.elapsed();
    std::thread::sleep(Duration::from_millis(16).saturating_sub(took));
    took
}

fn percentile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// UI frame times in the MC lab tab while each experiment runs live.
fn lab_frames(h: &mut Harness<'static, Window>) {
    h.state_mut().app.settings.tab = Tab::Lab;
    let mut all = Vec::new();
    for experiment in Experiment::ALL {
        h.state_mut().app.lab.select(experiment);
        let mut frames = Vec::new();
        let start = Instant::now();
        while h.state_mut().app.lab.is_running() {
            frames.push(frame(h).as_secs_f64() * 1e3);
        }
        println!(
            "UI frame time while the lab runs {:<11} median {:.2} ms, p95 {:.2} ms, max {:.2} ms ({} frames, {:.1} s)",
            experiment.name(),
            percentile(frames.clone(), 0.5),
            percentile(frames.clone(), 0.95),
            percentile(frames.clone(), 1.0),
            frames.len(),
            start.elapsed().as_secs_f64()
        );
        all.extend(frames);
    }
    println!(
        "UI frame time while the lab runs, all experiments: median {:.2} ms, p95 {:.2} ms",
        percentile(all.clone(), 0.5),
        percentile(all, 0.95)
    );
    h.state_mut().app.settings.tab = Tab::Renderer;
}

/// UI frame times while bidirectional path tracing and photon mapping
/// render (their passes splat or build a photon map over the whole film).
fn transport_frames(h: &mut Harness<'static, Window>) {
    for kind in [
        IntegratorKind::Bdpt,
        IntegratorKind::Sppm,
        IntegratorKind::Vcm,
    ] {
        h.state_mut().app.settings.a.integrator.kind = kind;
        let mut frames = Vec::new();
        let until = Instant::now() + Duration::from_secs(8);
        while Instant::now() < until {
            frames.push(frame(h).as_secs_f64() * 1e3);
        }
        println!(
            "UI frame time while {} renders: median {:.2} ms, p95 {:.2} ms, max {:.2} ms ({} frames, {} spp)",
            kind.name(),
            percentile(frames.clone(), 0.5),
            percentile(frames.clone(), 0.95),
            percentile(frames.clone(), 1.0),
            frames.len(),
            h.state().app.frame().views[0].stats.spp
        );
    }
    h.state_mut().app.settings.a.integrator.kind = IntegratorKind::Path;
}

/// UI frame times while radiosity solves: Gauss-Seidel with a round of
/// adaptive subdivision (form factors of a few thousand elements) and the
/// hierarchical solver, each from a fresh start.
fn radiosity_frames(h: &mut Harness<'static, Window>) {
    use tracelab::radiosity::RadiositySolver;
    for (solver, patch_size) in [
        (RadiositySolver::GaussSeidel, 0.15),
        (RadiositySolver::Hierarchical, 0.002),
    ] {
        {
            let options = &mut h.state_mut().app.settings.a.integrator;
            options.kind = IntegratorKind::Radiosity;
            options.radiosity.solver = solver;
            options.radiosity.patch_size = patch_size;
            options.radiosity.adaptive_rounds = 1;
            options.radiosity.epsilon = 1e-5;
        }
        let mut frames = Vec::new();
        let start = Instant::now();
        let until = start + Duration::from_secs(20);
        frame(h);
        while Instant::now() < until {
            frames.push(frame(h).as_secs_f64() * 1e3);
            let app = &h.state().app;
            let f = app.frame();
            let current = f.generation == app.live().generation();
            let solver = f.views.first().and_then(|v| v.stats.solver);
            if current && solver.is_some_and(|s| s.converged) {
                break;
            }
        }
        let elements = h
            .state()
            .app
            .frame()
            .views
            .first()
            .and_then(|v| v.stats.solver);
        println!(
            "UI frame time while radiosity ({}) solves: median {:.2} ms, p95 {:.2} ms, max {:.2} ms ({} frames, {:.1} s, {} elements)",
            solver.name(),
            percentile(frames.clone(), 0.5),
            percentile(frames.clone(), 0.95),
            percentile(frames.clone(), 1.0),
            frames.len(),
            start.elapsed().as_secs_f64(),
            elements.map_or(0, |s| s.elements)
        );
    }
    h.state_mut().app.settings.a.integrator.kind = IntegratorKind::Path;
}

fn main() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "viewer responsiveness, 512x512 Cornell box, {cores} cores, kittest (no GPU painting)"
    );
    let mut h = harness();
    let only = std::env::var("TRACELAB_BENCH_ONLY").unwrap_or_default();
    if only.is_empty() || only == "lab" {
        lab_frames(&mut h);
    }
    if only.is_empty() || only == "transport" {
        transport_frames(&mut h);
    }
    if only.is_empty() || only == "radiosity" {
        radiosity_frames(&mut h);
    }
    if !only.is_empty() {
        return;
    }
    let rss_start = resident_memory_mib().unwrap_or(f64::NAN);

    // 1. Frame times while rendering.
    let mut frames = Vec::new();
    let until = Instant::now() + Duration::from_secs(10);
    while Instant::now() < until {
        frames.push(frame(&mut h).as_secs_f64() * 1e3);
    }
    let spp = h.state().app.frame().views[0].stats.spp;
    println!(
        "UI frame time while rendering: median {:.2} ms, p95 {:.2} ms, max {:.2} ms ({} frames, {spp} spp rendered meanwhile)",
        percentile(frames.clone(), 0.5),
        percentile(frames.clone(), 0.95),
        percentile(frames.clone(), 1.0),
        frames.len()
    );

    // 2. Setting changes: time to the first frame of the new settings on
    // screen (the first quarter of the first pass), and to the whole first pass.
    let mut latencies = Vec::new();
    let mut latencies_path = Vec::new();
    let mut full_pass = Vec::new();
    for i in 0..100u64 {
        {
            let settings = &mut h.state_mut().app.settings;
            settings.a.seed = i + 1;
            settings.a.sampler = if i % 2 == 0 {
                SamplerKind::Stratified
            } else {
                SamplerKind::Independent
            };
            settings.a.integrator.kind = if i % 3 == 0 {
                IntegratorKind::Light
            } else {
                IntegratorKind::Path
            };
        }
        let changed = Instant::now();
        let mut first = None;
        loop {
            frame(&mut h);
            let app = &h.state().app;
            let f = app.frame();
            if f.generation != app.live().generation() {
                continue;
            }
            // The frame just built uploaded it (update_textures runs every frame).
            let ms = changed.elapsed().as_secs_f64() * 1e3;
            if first.is_none() {
                first = Some(ms);
                latencies.push(ms);
                if i % 3 != 0 {
                    latencies_path.push(ms);
                }
            }
            if f.views.iter().all(|v| v.stats.spp >= 1) {
                full_pass.push(ms);
                break;
            }
        }
        for _ in 0..10 {
            frame(&mut h);
        }
    }
    println!(
        "setting change -> first new image: median {:.0} ms, p95 {:.0} ms, max {:.0} ms (100 changes, 60 Hz frames)",
        percentile(latencies.clone(), 0.5),
        percentile(latencies.clone(), 0.95),
        percentile(latencies, 1.0)
    );
    println!(
        "  of which path tracing: median {:.0} ms, p95 {:.0} ms; light tracing (whole first pass at once) the rest",
        percentile(latencies_path.clone(), 0.5),
        percentile(latencies_path, 0.95)
    );
    println!(
        "setting change -> whole first pass on screen: median {:.0} ms, p95 {:.0} ms",
        percentile(full_pass.clone(), 0.5),
        percentile(full_pass, 0.95)
    );
    let rss_changes = resident_memory_mib().unwrap_or(f64::NAN);

    // 3. Equal-time comparison of two estimators of different cost.
    {
        let settings = &mut h.state_mut().app.settings;
        settings.a.integrator.kind = IntegratorKind::Path;
        settings.b = settings.a;
        settings.b.integrator.kind = IntegratorKind::Mcrt;
        settings.b.integrator.mcrt.glossy_rays = 2;
        settings.b.integrator.mcrt.shadow_rays = 2;
        settings.b.integrator.mcrt.max_depth = 3;
        settings.compare = true;
        settings.lock = Lock::EqualTime;
    }
    let until = Instant::now() + Duration::from_secs(10);
    while Instant::now() < until {
        frame(&mut h);
    }
    let f = h.state().app.frame();
    let (a, b) = (&f.views[0].stats, &f.views[1].stats);
    let (ta, tb) = (a.render_time.as_secs_f64(), b.render_time.as_secs_f64());
    println!(
        "equal-time comparison (path vs mcrt 2x2 depth 3): render time A {ta:.2} s, B {tb:.2} s, difference {:.1}% ({} vs {} spp)",
        100.0 * (ta - tb).abs() / ta.max(tb),
        a.spp,
        b.spp
    );

    // 4. Memory over a long session.
    let soak: u64 = std::env::var("TRACELAB_SOAK_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    h.state_mut().app.settings.compare = false;
    let soak_start = Instant::now();
    let mut next_report = 120;
    while soak_start.elapsed() < Duration::from_secs(soak) {
        frame(&mut h);
        if soak_start.elapsed() >= Duration::from_secs(next_report) {
            println!(
                "  after {next_report} s: {:.0} MiB",
                resident_memory_mib().unwrap_or(f64::NAN)
            );
            next_report += 120;
        }
    }
    println!(
        "resident memory: {rss_start:.0} MiB at start, {rss_changes:.0} MiB after 100 setting changes, {:.0} MiB after {soak} s more rendering ({} spp)",
        resident_memory_mib().unwrap_or(f64::NAN),
        h.state().app.frame().views[0].stats.spp
    );
    h.state_mut().app.shutdown();
}
