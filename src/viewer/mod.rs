//! The live window (eframe + egui, wgpu renderer). It drives the core only
//! through [`crate::live::LiveRender`] (start, restart with new settings,
//! latest snapshot, stop), so the UI thread never waits on a render pass.
//!
//! Files: `settings.rs` (persisted plain data), `app.rs` (state and actions),
//! `panel.rs` (side panel), `image_view.rs` (image, zoom, inspector, split),
//! `stats.rs` (statistics and convergence plot), `display.rs` (tone mapping
//! and false colour), `export.rs` (PNG/EXR files), `launch.rs` (start-up
//! options, scene lookup).

pub mod app;
pub mod controls;
pub mod display;
pub mod export;
pub mod image_view;
pub mod lab;
pub mod launch;
pub mod panel;
pub mod plot_scale;
pub mod settings;
pub mod stats;
pub mod strategies;
pub mod view_transform;

pub use app::ViewerApp;
pub use launch::Launch;
pub use settings::{Tab, ViewMode};

use crate::error::{Error, Result};
use eframe::egui::{self, Color32, Key, RichText};
use panel::Editing;
use std::time::{Duration, Instant};

/// How long toasts stay.
const TOAST_TIME: Duration = Duration::from_secs(4);

/// Opens the window and runs until it is closed.
pub fn run(launch: Launch) -> Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("tracelab")
            .with_inner_size([1280.0, 820.0])
            .with_min_inner_size([640.0, 400.0]),
        ..Default::default()
    };
    eframe::run_native(
        "tracelab",
        options,
        Box::new(move |cc| Ok(Box::new(Window::new(cc, launch)))),
    )
    .map_err(|e| {
        Error::new(format!(
            "cannot open the window: {e}\n(on Linux the window needs X11 or Wayland; \
             headless: `apt-get install xvfb` and run under `xvfb-run`)"
        ))
    })
}

/// The eframe app: [`ViewerApp`] plus UI-only state.
pub struct Window {
    pub app: ViewerApp,
    editing: Editing,
    persist: bool,
}

impl Window {
    /// eframe's app creator; settings come from our own file, not `_cc.storage`.
    pub fn new(_cc: &eframe::CreationContext<'_>, launch: Launch) -> Self {
        let persist = launch.screenshot.is_none();
        Window {
            app: ViewerApp::new(launch),
            editing: Editing::A,
            persist,
        }
    }
}

impl eframe::App for Window {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let start = Instant::now();
        let ctx = ui.ctx().clone();
        let app = &mut self.app;
        shortcuts(&ctx, app);
        app.sync();
        app.update_textures(&ctx);
        app.handle_capture(&ctx);

        if app.sheet_mode {
            sheet(ui, app);
        } else if app.settings.tab == Tab::Lab {
            app.lab.ensure_started();
            lab_layout(ui, app);
        } else {
            layout(ui, app, &mut self.editing);
            strategy_grid(&ctx, app);
        }
        toasts(&ctx, app);
        if app.settings.show_help {
            help_window(&ctx, app);
        }
        app.record_frame_time(start.elapsed().as_secs_f32());
        if app.live().is_rendering()
            || app.capture.is_some()
            || app.lab.is_running()
            || app.strategy_grid.open
        {
            ctx.request_repaint_after(Duration::from_millis(30));
        }
    }

    fn save(&mut self, _storage: &mut dyn eframe::Storage) {
        // Our own file, written atomically; eframe's storage keeps only the
        // window geometry.
        if self.persist
            && let Some(path) = settings::settings_file()
            && let Err(e) = settings::save_settings(&path, &self.app.settings)
        {
            self.app.errors.push(e.to_string());
        }
    }

    fn on_exit(&mut self) {
        self.app.shutdown();
    }
}

/// BDPT's strategy images, while A is bidirectional and the window open.
fn strategy_grid(ctx: &egui::Context, app: &mut ViewerApp) {
    use crate::integrator::{Bdpt, IntegratorKind, Technique};
    let a = app.settings.a;
    if a.integrator.kind != IntegratorKind::Bdpt {
        app.strategy_grid.open = false;
    }
    let scene = app.scene().cloned();
    app.strategy_grid
        .update(scene.as_ref(), Bdpt::new(&a.integrator.bdpt), a.sampler);
    app.strategy_grid.show(ctx);
}

/// The tabs, the scene's name and the view modes (renderer) or nothing more (lab).
fn top_bar(ui: &mut egui::Ui, app: &mut ViewerApp) {
    egui::Panel::top("top_bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.strong("tracelab");
            ui.selectable_value(&mut app.settings.tab, Tab::Renderer, "Renderer");
            ui.selectable_value(&mut app.settings.tab, Tab::Lab, "MC lab");
            ui.separator();
            if app.settings.tab == Tab::Renderer {
                ui.label(RichText::new(app.scene_name().to_string()).weak());
                ui.separator();
                for mode in ViewMode::ALL {
                    ui.selectable_value(&mut app.settings.display.view, mode, mode.label());
                }
                ui.separator();
            } else {
                ui.label(RichText::new("the renderer pauses while the lab is shown").weak());
                ui.separator();
            }
            ui.toggle_value(&mut app.settings.show_help, "Help (H)");
        });
    });
}

/// The Monte Carlo lab: its panel on the left, figures and tables in the middle.
fn lab_layout(ui: &mut egui::Ui, app: &mut ViewerApp) {
    top_bar(ui, app);
    egui::Panel::left("lab_controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| lab::lab_panel(ui, &mut app.lab));
    egui::CentralPanel::default().show(ui, |ui| lab::lab_area(ui, &mut app.lab));
}

fn layout(ui: &mut egui::Ui, app: &mut ViewerApp, editing: &mut Editing) {
    top_bar(ui, app);
    if !app.errors.is_empty() {
        egui::Panel::top("errors").show(ui, |ui| {
            let mut dismiss = false;
            egui::Frame::new()
                .fill(Color32::from_rgb(90, 20, 20))
                .inner_margin(6.0)
                .show(ui, |ui| {
                    for e in &app.errors {
                        ui.label(RichText::new(e).color(Color32::WHITE));
                    }
                    dismiss = ui.button("Dismiss").clicked();
                });
            if dismiss {
                app.errors.clear();
            }
        });
    }
    egui::Panel::left("controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| panel::side_panel(ui, app, editing));
    // A fixed height: the plot fills it, and the image above keeps its place.
    egui::Panel::bottom("statistics")
        .resizable(false)
        .exact_size(250.0)
        .show(ui, |ui| {
            stats::stats_panel(ui, app);
            stats::convergence_plot(ui, app);
        });
    egui::CentralPanel::default().show(ui, |ui| image_view::image_area(ui, app));
}

/// One page with A, B, their difference, the plot and the settings, for the
/// comparison-sheet export.
fn sheet(ui: &mut egui::Ui, app: &mut ViewerApp) {
    let frame = app.frame();
    let ctx = ui.ctx().clone();
    egui::CentralPanel::default().show(ui, |ui| {
        ui.heading(format!("tracelab comparison: {}", app.scene_name()));
        let textures = app.textures().to_vec();
        if frame.views.len() == 2 && textures.len() == 2 {
            let diff = display::render_view(
                &frame.views[0].snapshot,
                Some(&frame.views[1].snapshot.image),
                &settings::Display {
                    view: ViewMode::Difference,
                    ..app.settings.display
                },
            );
            let diff = ctx.load_texture("sheet-diff", diff, egui::TextureOptions::NEAREST);
            let w = (ui.available_width() / 3.0 - 8.0).max(64.0);
            let size = egui::vec2(
                frame.views[0].snapshot.image.width as f32,
                frame.views[0].snapshot.image.height as f32,
            );
            let size = size * (w / size.x);
            ui.horizontal(|ui| {
                for (title, id) in [
                    (format!("A: {}", app.view_label(0)), textures[0].id()),
                    (format!("B: {}", app.view_label(1)), textures[1].id()),
                    ("A - B".to_string(), diff.id()),
                ] {
                    ui.vertical(|ui| {
                        ui.label(title);
                        ui.image((id, size));
                    });
                }
            });
        }
        ui.label(
            RichText::new(format!("A: {:?}\nB: {:?}", app.settings.a, app.settings.b))
                .monospace()
                .small(),
        );
        stats::stats_panel(ui, app);
        stats::convergence_plot(ui, app);
    });
}

fn shortcuts(ctx: &egui::Context, app: &mut ViewerApp) {
    if ctx.egui_wants_keyboard_input() {
        return;
    }
    ctx.input(|i| {
        if i.key_pressed(Key::H) {
            app.settings.show_help = !app.settings.show_help;
        }
        if i.key_pressed(Key::F) {
            app.view = view_transform::ViewTransform::default();
        }
        if i.key_pressed(Key::Num1) {
            app.view.zoom = Some(1.0);
        }
        if i.key_pressed(Key::C) {
            app.settings.compare = !app.settings.compare;
        }
        if i.key_pressed(Key::V) {
            let modes = ViewMode::ALL;
            let current = modes
                .iter()
                .position(|m| *m == app.settings.display.view)
                .unwrap_or(0);
            app.settings.display.view = modes[(current + 1) % modes.len()];
        }
        if i.key_pressed(Key::Plus) || i.key_pressed(Key::Equals) {
            app.settings.display.exposure += 0.5;
        }
        if i.key_pressed(Key::Minus) {
            app.settings.display.exposure -= 0.5;
        }
    });
    let (restart, export, reset) = ctx.input(|i| {
        (
            i.key_pressed(Key::R),
            i.key_pressed(Key::S),
            i.key_pressed(Key::Home),
        )
    });
    if restart {
        app.force_restart();
    }
    if export {
        for i in 0..app.configs().len() {
            app.export_png(i);
        }
    }
    if reset {
        app.reset_camera();
    }
}

/// Mouse and keyboard controls, as the help panel lists them.
pub const CONTROLS: [(&str, &str); 14] = [
    ("Scroll", "zoom the image about the cursor"),
    ("Left drag", "pan the image"),
    ("Right or middle drag", "orbit the camera (restarts)"),
    ("Shift + scroll", "dolly the camera (restarts)"),
    ("Drag the divider", "move the A | B split"),
    ("F / 1", "fit the image / one image pixel per screen pixel"),
    ("Home", "back to the scene's camera"),
    ("R", "restart accumulation"),
    ("C", "side-by-side comparison on/off"),
    (
        "V",
        "next view mode (image, difference, std. error, fireflies)",
    ),
    ("+ / -", "exposure up / down half a stop"),
    ("S", "export the image(s) as PNG"),
    ("H", "this help"),
    ("Hover", "pixel inspector: radiance, spp, standard error"),
];

fn help_window(ctx: &egui::Context, app: &mut ViewerApp) {
    let mut open = app.settings.show_help;
    egui::Window::new("Help")
        .open(&mut open)
        .resizable(false)
        .show(ctx, |ui| {
            egui::Grid::new("controls").striped(true).show(ui, |ui| {
                for (input, action) in CONTROLS {
                    ui.strong(input);
                    ui.label(action);
                    ui.end_row();
                }
            });
            ui.separator();
            ui.label("Render settings restart accumulation; display settings never do.");
        });
    app.settings.show_help = open;
}

fn toasts(ctx: &egui::Context, app: &mut ViewerApp) {
    app.toasts.retain(|t| t.shown_at.elapsed() < TOAST_TIME);
    if app.toasts.is_empty() {
        return;
    }
    egui::Area::new(egui::Id::unique("tracelab-toasts"))
        .anchor(egui::Align2::RIGHT_BOTTOM, [-12.0, -12.0])
        .show(ctx, |ui| {
            for t in &app.toasts {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.label(&t.text);
                });
            }
        });
    ctx.request_repaint_after(Duration::from_millis(250));
}
