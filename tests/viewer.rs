//! The real viewer driven through egui_kittest: widgets are found by their
//! accessibility labels and clicked; the tests then check the app state, the
//! renderer behind it (what the render thread actually renders), and the
//! files an export writes. The snapshot test renders the window headless
//! through wgpu (llvmpipe without a GPU).

use crate::common::{repo_path, temp_dir};
use eframe::egui::{self, Vec2, pos2};
use egui_kittest::kittest::Queryable;
use egui_kittest::{Harness, SnapshotOptions};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use tracelab::integrator::IntegratorKind;
use tracelab::integrator::radiosity::Radiosity;
use tracelab::lab::Experiment;
use tracelab::render::Adaptive;
use tracelab::sampling::SamplerKind;
use tracelab::viewer::{Launch, Window};

const SIZE: Vec2 = Vec2::new(1280.0, 820.0);

fn launch(export_dir: PathBuf, target_spp: u32) -> Launch {
    Launch {
        scene: Some(repo_path("scenes/cornell_box.toml")),
        target_spp: Some(target_spp),
        threads: 2,
        fresh: true,
        export_dir: Some(export_dir),
        ..Default::default()
    }
}

/// Steps the UI until `done` holds for the window (the renderer runs on its
/// own threads meanwhile).
fn step_until(harness: &mut Harness<'_, Window>, what: &str, done: impl Fn(&Window) -> bool) {
    let start = Instant::now();
    loop {
        harness.step();
        if done(harness.state()) {
            return;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let w = harness.state();
            let frame = w.app.frame();
            let views: Vec<_> = frame
                .views
                .iter()
                .map(|v| (v.stats.spp, v.done, v.settings.integrator.name()))
                .collect();
            panic!(
                "timed out waiting for {what}: generation {} of {}, views (spp, done, technique) {views:?}, errors {:?}",
                frame.generation,
                w.app.live().generation(),
                w.app.errors
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Scrolls the side panel to the widget labelled `label` and clicks it, as a
/// user would.
fn click(harness: &mut Harness<'_, Window>, label: &str) {
    harness.get_by_label(label).scroll_to_me();
    // Let the scroll animation settle before clicking.
    for _ in 0..30 {
        harness.step();
    }
    harness.get_by_label(label).click();
    harness.step();
}

/// View A's radiosity settings, for what a test sets without clicking.
fn radiosity<'a>(harness: &'a mut Harness<'_, Window>) -> &'a mut Radiosity {
    &mut harness.state_mut().app.settings.a.integrator.radiosity
}

/// The renderer shows the current settings and has finished them.
fn finished(w: &Window) -> bool {
    let frame = w.app.frame();
    frame.generation == w.app.live().generation()
        && !frame.views.is_empty()
        && frame.views.iter().all(|v| v.done)
}

#[test]
fn controls_drive_the_renderer_and_export_writes_files() {
    let dir = temp_dir("viewer-export");
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch(dir.to_path_buf(), 4)));
    step_until(&mut harness, "the first render", finished);
    assert_eq!(harness.state().app.frame().views[0].stats.spp, 4);

    // Adaptive sampling by noise, on and off again.
    click(&mut harness, "Adaptive: spread samples by noise");
    step_until(&mut harness, "adaptive sampling", |w| {
        finished(w)
            && matches!(
                w.app.frame().views[0].settings.adaptive,
                Some(Adaptive::Distribute { .. })
            )
    });
    click(&mut harness, "Adaptive: spread samples by noise");
    step_until(&mut harness, "uniform sampling", |w| {
        finished(w) && w.app.frame().views[0].settings.adaptive.is_none()
    });

    // Switch the estimator.
    harness.get_by_label("Light tracing").click();
    step_until(&mut harness, "light tracing", |w| {
        finished(w) && w.app.frame().views[0].settings.integrator.name() == "light"
    });
    assert_eq!(
        harness.state().app.settings.a.integrator.kind,
        IntegratorKind::Light
    );

    // Change the sample target.
    harness.get_by_label("Target spp").set_value_accesskit(8.0);
    step_until(&mut harness, "8 spp", |w| {
        finished(w) && w.app.frame().views[0].stats.spp == 8
    });
    assert_eq!(harness.state().app.settings.target_spp, 8);

    // Toggle stratification.
    harness.get_by_label("Stratify samples").click();
    step_until(&mut harness, "the stratified sampler", |w| {
        finished(w) && w.app.frame().views[0].settings.sampler == SamplerKind::Stratified
    });

    // The classic fixed epsilon instead of robust offsets.
    click(&mut harness, "Fixed ε");
    step_until(&mut harness, "fixed offsets", |w| {
        finished(w) && w.app.frame().views[0].offset == tracelab::math::OffsetMode::Fixed(1e-3)
    });
    click(&mut harness, "Robust");
    step_until(&mut harness, "robust offsets", |w| {
        finished(w) && w.app.frame().views[0].offset == tracelab::math::OffsetMode::Robust
    });

    // Start a side-by-side comparison: B is A with the other sampler.
    click(&mut harness, "Side-by-side comparison");
    step_until(&mut harness, "two views", |w| {
        finished(w) && w.app.frame().views.len() == 2
    });
    let frame = harness.state().app.frame();
    assert_eq!(frame.views[0].settings.sampler, SamplerKind::Stratified);
    assert_eq!(frame.views[1].settings.sampler, SamplerKind::Independent);
    assert!(frame.views.iter().all(|v| v.stats.spp == 8));

    // Export: one PNG and one EXR per view, named by settings and spp.
    click(&mut harness, "Export PNG");
    click(&mut harness, "Export EXR");
    let exports = harness.state().app.exports.clone();
    assert_eq!(exports.len(), 4, "{exports:?}");
    for path in &exports {
        assert!(path.starts_with(&dir), "{}", path.display());
        let name = path.file_name().unwrap().to_string_lossy();
        assert!(name.starts_with("cornell-box_light-d8"), "{name}");
        assert!(name.contains("_8spp"), "{name}");
    }
    let png = image::open(&exports[0]).unwrap();
    assert_eq!((png.width(), png.height()), (256, 256));
    let text = tracelab::viewer::export::read_png_text(&exports[0]).unwrap();
    assert!(
        text.iter().any(|(k, v)| k == "tracelab:spp" && v == "8"),
        "{text:?}"
    );
    assert!(
        text.iter()
            .any(|(k, v)| k == "tracelab:sampler" && v == "stratified")
    );
    let exr = tracelab::image::Image::read(&exports[2]).unwrap();
    assert_eq!(exr, frame.views[0].snapshot.image);

    // Exporting again never overwrites: new names.
    click(&mut harness, "Export PNG");
    let again = &harness.state().app.exports[4];
    assert!(
        again.to_string_lossy().ends_with("-2.png"),
        "{}",
        again.display()
    );
    harness.state_mut().app.shutdown();
}

#[test]
fn a_bad_scene_shows_an_error_and_keeps_the_last_good_one() {
    let dir = temp_dir("viewer-bad-scene");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[camera]\neye = [0, 0]\n").unwrap();
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch(dir.to_path_buf(), 2)));
    step_until(&mut harness, "the first render", finished);
    let good = harness.state().app.scene().unwrap().clone();

    harness.state_mut().app.scene_field = bad.to_string_lossy().into_owned();
    harness.get_by_label("Load").click();
    harness.step();
    harness.step();
    let app = &harness.state().app;
    assert_eq!(app.errors.len(), 1);
    assert!(app.errors[0].contains("bad.toml:2"), "{}", app.errors[0]);
    assert!(std::sync::Arc::ptr_eq(app.scene().unwrap(), &good));
    // The error is on screen, and can be dismissed.
    harness.get_by_label_contains("bad.toml:2");
    harness.get_by_label("Dismiss").click();
    harness.step();
    assert!(harness.state().app.errors.is_empty());

    // A Mitsuba file that asks for something not rendered loads, with its
    // warning listed in the panel (file, line and column) while it is open.
    let xml = dir.join("warned.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\">\n  <shape type=\"cube\"><float name=\"mystery\" value=\"1\"/>\n    <emitter type=\"area\"/></shape>\n  <integrator type=\"path\"/>\n</scene>\n",
    )
    .unwrap();
    harness.state_mut().app.scene_field = xml.to_string_lossy().into_owned();
    harness.step();
    harness.get_by_label("Load").click();
    harness.step();
    harness.step();
    assert!(
        harness.state().app.errors.is_empty(),
        "{:?}",
        harness.state().app.errors
    );
    let warnings = harness.state().app.scene().unwrap().warnings.clone();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    harness.get_by_label("Scene warnings (2)").click();
    harness.step();
    // In the panel's list, and in the toast that announced it.
    let shown = harness
        .get_all_by_label_contains("shape `cube`: property `mystery` ignored")
        .count();
    assert_eq!(shown, 2);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("warned.xml:2:22: shape `cube`")),
        "{warnings:?}"
    );
    // The file's depth (Mitsuba's default, unbounded) survives the panel's
    // depth slider, whose bar ends at 32.
    let depth = |h: &mut Harness<'_, Window>| {
        *h.state_mut()
            .app
            .settings
            .a
            .integrator
            .max_depth_mut()
            .unwrap()
    };
    assert_eq!(depth(&mut harness), tracelab::scene::UNBOUNDED_DEPTH);
    harness.step();
    assert_eq!(depth(&mut harness), tracelab::scene::UNBOUNDED_DEPTH);
    harness.state_mut().app.shutdown();
}

#[test]
fn window_layout_snapshot() {
    // Paths shown in the panel must not depend on the checkout or the process.
    let launch = Launch {
        scene: Some(PathBuf::from("scenes/cornell_box.toml")),
        export_dir: Some(std::env::temp_dir().join("tracelab-snapshot-exports")),
        ..launch(PathBuf::new(), 16)
    };
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .wgpu()
        .build_eframe(|cc| Window::new(cc, launch));
    step_until(&mut harness, "16 spp", finished);
    harness.step();
    // Timings, memory and the convergence curve vary from run to run: mask
    // the statistics panel right of the controls (the image, the controls
    // and the panel layout stay in the comparison).
    harness.mask(egui::Rect::from_min_max(
        pos2(312.0, 570.0),
        pos2(SIZE.x, SIZE.y),
    ));
    harness.snapshot_options(
        "viewer_cornell_box",
        &SnapshotOptions::new().output_path(repo_path("tests/snapshots")),
    );
    harness.state_mut().app.shutdown();
}

#[test]
fn the_lab_tab_runs_every_experiment_live_and_cancels() {
    let dir = temp_dir("viewer-lab");
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch(dir.to_path_buf(), 4)));
    harness.get_by_label("MC lab").click();
    // One frame to take the click, one to draw the lab.
    harness.step();
    harness.step();
    assert_eq!(harness.state().app.settings.tab, tracelab::viewer::Tab::Lab);
    for experiment in Experiment::ALL {
        click(&mut harness, experiment.label());
        assert_eq!(harness.state().app.lab.experiment(), experiment);
        // Partial reports appear while it runs: the UI never waits for the end.
        step_until(&mut harness, "a first stage", |w| {
            w.app.lab.report().is_some_and(|r| r.stages_done >= 1)
        });
        step_until(&mut harness, experiment.name(), |w| {
            w.app.lab.frames_since_finished >= 2
        });
        let report = harness.state().app.lab.report().unwrap();
        assert!(
            !report.figures.is_empty() && report.all_hold(),
            "{experiment:?}"
        );
        // The checks are on screen.
        let shown = harness.query_all_by_label_contains("holds:").count();
        assert_eq!(shown, report.checks.len(), "{experiment:?}");
    }
    // A long run is cancelled by its button and says so.
    click(&mut harness, Experiment::Stratified.label());
    harness.state_mut().app.lab.settings.runs = 100_000;
    harness.state_mut().app.lab.start();
    harness.step();
    click(&mut harness, "Cancel");
    step_until(&mut harness, "the cancel", |w| w.app.lab.was_cancelled());
    harness.get_by_label_contains("cancelled");
    // Back to the renderer: it renders again.
    harness.get_by_label("Renderer").click();
    step_until(&mut harness, "the render", finished);
}

#[test]
fn radiosity_controls_drive_the_solver() {
    let dir = temp_dir("viewer-radiosity");
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch(dir.to_path_buf(), 4)));
    // Every solver runs on a coarse mesh (206 uniform elements), for time.
    radiosity(&mut harness).patch_size = 0.3;
    click(&mut harness, "Radiosity");
    click(&mut harness, "hierarchical");
    click(&mut harness, "flat");
    // A lookup display antialiases with its own sampler, and says so in place
    // of the sampler's controls.
    harness.get_by_label_contains("Sampler: sobol");
    assert!(harness.query_by_label("Stratify samples").is_none());
    // Each form-factor method starts from the count at which it is accurate.
    let samples = |h: &Harness<'_, Window>| {
        h.state()
            .app
            .settings
            .a
            .integrator
            .radiosity
            .form_factor_samples
    };
    click(&mut harness, "Ray casting");
    assert_eq!(samples(&harness), 256);
    click(&mut harness, "Contour integral");
    assert_eq!(samples(&harness), 16);
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.kind, IntegratorKind::Radiosity);
    assert_eq!(
        options.radiosity.solver,
        tracelab::radiosity::RadiositySolver::Hierarchical
    );
    // The solver runs its steps (the target of 4 "spp" is 4 steps here) and
    // the statistics line counts its elements and links.
    step_until(&mut harness, "the hierarchical solution", finished);
    let frame = harness.state().app.frame();
    let solver = frame.views[0].stats.solver.expect("a solver's progress");
    assert!(
        solver.steps >= 1 && solver.elements > 32 && solver.links > solver.elements,
        "{solver:?}"
    );
    // The statistics line shows the frame drawn: one more frame or two
    // for the last one to reach the screen.
    harness.run_steps(2);
    harness.get_by_label_contains("links");
    // Another solver restarts from its own mesh. Progressive refinement
    // converges over thousands of shots: 50 here.
    radiosity(&mut harness).iterations = 50;
    click(&mut harness, "progressive");
    let ambient = harness.state().app.settings.a.integrator.radiosity.ambient;
    click(&mut harness, "Ambient term");
    step_until(&mut harness, "the progressive solution", finished);
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.radiosity.ambient, !ambient);
    assert_eq!(
        options.radiosity.solver,
        tracelab::radiosity::RadiositySolver::Progressive
    );
    // Gauss-Seidel with a round of adaptive subdivision and the wireframe:
    // the converged mesh has more elements than the uniform one (206).
    radiosity(&mut harness).iterations = 0;
    click(&mut harness, "gauss-seidel");
    harness.get_by_role_and_label(egui::accesskit::Role::Slider, "Adaptive subdivision rounds");
    radiosity(&mut harness).adaptive_rounds = 1;
    click(&mut harness, "Wireframe (colour by level)");
    step_until(&mut harness, "the adaptive solution", finished);
    assert!(
        harness
            .state()
            .app
            .settings
            .a
            .integrator
            .radiosity
            .wireframe
    );
    let solver = harness.state().app.frame().views[0].stats.solver.unwrap();
    assert!(solver.converged && solver.elements > 206, "{solver:?}");
    harness.run_steps(2);
    harness.get_by_label_contains("MB, residual");
    // Discontinuity meshing: the receivers are split along the shadows'
    // lines before meshing, and the notes line says how.
    click(&mut harness, "Discontinuity meshing (lines in cyan)");
    assert!(
        harness
            .state()
            .app
            .settings
            .a
            .integrator
            .radiosity
            .discontinuity
    );
    step_until(&mut harness, "the discontinuity mesh's solution", finished);
    harness.run_steps(2);
    harness.get_by_label_contains("critical wedges");
}

#[test]
fn bidirectional_and_photon_mapping_controls_drive_the_renderer() {
    let dir = temp_dir("viewer-bdpt");
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch(dir.to_path_buf(), 2)));
    click(&mut harness, "Bidirectional path tracing");
    click(&mut harness, "Balance");
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.kind, IntegratorKind::Bdpt);
    assert_eq!(
        options.bdpt.mis,
        tracelab::integrator::MisHeuristic::Balance
    );
    step_until(&mut harness, "2 spp of BDPT", finished);
    assert!(harness.state().app.frame().views[0].stats.spp >= 2);
    // The strategy images fill in on their own thread.
    click(&mut harness, "Strategy images (s, t)");
    step_until(&mut harness, "the strategy images", |w| {
        w.app.strategy_grid.spp().is_some_and(|spp| spp >= 2)
    });
    harness.get_by_label_contains("spp at 96 pixels wide");

    click(&mut harness, "Photon mapping (Jensen)");
    harness.run_steps(2);
    harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "k (photons per estimate)")
        .set_value_accesskit(20.0);
    harness.run_steps(2);
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.kind, IntegratorKind::Photon);
    assert_eq!(options.photon.k, 20);
    assert!(
        !harness.state().app.strategy_grid.open,
        "the grid closes with BDPT"
    );
    step_until(
        &mut harness,
        "2 iterations of Jensen's photon mapping",
        finished,
    );

    click(&mut harness, "Progressive photon mapping");
    harness
        .get_by_role_and_label(
            egui::accesskit::Role::Slider,
            "Alpha (1: fixed radius, biased)",
        )
        .set_value_accesskit(1.0);
    harness.run_steps(2);
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.kind, IntegratorKind::Sppm);
    assert_eq!(options.sppm.alpha, 1.0);
    step_until(&mut harness, "2 iterations of photon mapping", finished);
    assert!(harness.state().app.frame().views[0].stats.spp >= 2);

    // VCM: the heuristic, roulette and the merge radius.
    click(&mut harness, "Vertex connection and merging");
    click(&mut harness, "Power");
    harness
        .get_by_role_and_label(
            egui::accesskit::Role::Slider,
            "First radius (of the scene's diagonal)",
        )
        .set_value_accesskit(0.01);
    harness.run_steps(2);
    // The radius in pixels under its slider, as the CLI's summary says it
    // (the Cornell box's 256 pixels: about 3.5, no warning).
    harness.get_by_label_contains("pixels at the median first hit");
    assert!(
        harness
            .query_by_label_contains("more than an eighth of the frame")
            .is_none()
    );
    let options = harness.state().app.settings.a.integrator;
    assert_eq!(options.kind, IntegratorKind::Vcm);
    assert_eq!(options.vcm.mis, tracelab::integrator::MisHeuristic::Power);
    assert!(
        (options.vcm.radius - 0.01).abs() < 1e-6,
        "{}",
        options.vcm.radius
    );
    step_until(&mut harness, "2 iterations of VCM", finished);
    assert!(harness.state().app.frame().views[0].stats.spp >= 2);
}

#[test]
fn a_comparison_renders_the_files_depth_in_both_views() {
    // veach-bidir asks for max_depth 7 (6 bounces): B, path tracing beside
    // BDPT, must not keep its own default of 8.
    let exports = temp_dir("viewer-compare-depth");
    let launch = Launch {
        scene: Some(repo_path("scenes/veach-bidir/scene.xml")),
        integrator: Some(IntegratorKind::Bdpt),
        compare_with: Some(IntegratorKind::Path),
        defines: vec![("resx".into(), "32".into()), ("resy".into(), "32".into())],
        target_spp: Some(1),
        threads: 2,
        fresh: true,
        export_dir: Some(exports.to_path_buf()),
        ..Default::default()
    };
    let mut harness = Harness::builder()
        .with_size(SIZE)
        .build_eframe(|cc| Window::new(cc, launch));
    step_until(&mut harness, "both views", finished);
    let settings = &harness.state().app.settings;
    let depths = [&settings.a, &settings.b].map(|v| (v.integrator.kind, v.integrator.max_depth()));
    assert_eq!(
        depths,
        [
            (IntegratorKind::Bdpt, Some(6)),
            (IntegratorKind::Path, Some(6))
        ]
    );
    assert_eq!(harness.state().app.frame().views.len(), 2);
    harness.state_mut().app.shutdown();
}
