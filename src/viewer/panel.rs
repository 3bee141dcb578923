//! The side panel: scene, estimator and sampler settings, comparison,
//! display and export controls. Widgets only change `app.settings` (render
//! settings restart the renderer at the next `sync`) or call app actions.

use super::app::ViewerApp;
use super::settings::{CompareLayout, Config, ToneMap, ViewMode};
use crate::filter::FilterSampling;
use crate::integrator::IntegratorKind;
use crate::live::Lock;
use crate::math::OffsetMode;
use crate::sampling::SamplerKind;
use eframe::egui;

/// Which configuration the estimator controls edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Editing {
    #[default]
    A,
    B,
}

pub fn side_panel(ui: &mut egui::Ui, app: &mut ViewerApp, editing: &mut Editing) {
    egui::ScrollArea::vertical().show(ui, |ui| {
        scene_section(ui, app);
        ui.separator();
        compare_section(ui, app, editing);
        ui.separator();
        let merge_scale = app.merge_scale;
        let config = if app.settings.compare && *editing == Editing::B {
            &mut app.settings.b
        } else {
            &mut app.settings.a
        };
        estimator_section(ui, config, merge_scale);
        if app.settings.a.integrator.kind == IntegratorKind::Bdpt {
            ui.checkbox(&mut app.strategy_grid.open, "Strategy images (s, t)")
                .on_hover_text(
                    "Veach's pyramid: each strategy's share of the image, filling in live \
                     (a small copy of the scene on its own thread)",
                );
        }
        ui.separator();
        samples_section(ui, app);
        ui.separator();
        display_section(ui, app);
        ui.separator();
        reference_section(ui, app);
        ui.separator();
        export_section(ui, app);
    });
}

fn scene_section(ui: &mut egui::Ui, app: &mut ViewerApp) {
    ui.heading("Scene");
    let mut chosen = None;
    egui::ComboBox::from_label("Scene file")
        .selected_text(short_name(&app.settings.scene_path))
        .show_ui(ui, |ui| {
            for file in &app.scene_files {
                if ui
                    .selectable_label(*file == app.settings.scene_path, short_name(file))
                    .clicked()
                {
                    chosen = Some(file.clone());
                }
            }
        });
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut app.scene_field)
                .hint_text("scene.toml, scene.xml, mesh.obj or .ply")
                .desired_width(180.0),
        );
        if ui.button("Load").clicked() {
            chosen = Some(app.scene_field.clone());
        }
    });
    if let Some(path) = chosen {
        app.load_scene(&path);
    }
    ui.horizontal(|ui| {
        if ui.button("Reset camera").clicked() {
            app.reset_camera();
        }
        if ui.button("Restart").clicked() {
            app.force_restart();
        }
    });
    // What the file asked for and did not get, for as long as it is loaded.
    let Some(scene) = app.scene().cloned() else {
        return;
    };
    if !scene.warnings.is_empty() {
        egui::CollapsingHeader::new(format!("Scene warnings ({})", scene.warnings.len()))
            .id_salt("scene-warnings")
            .show(ui, |ui| {
                for w in &scene.warnings {
                    ui.label(egui::RichText::new(w).small());
                }
            });
    }
}

/// A scene file's name; an imported scene's folder too (veach-mis/scene.xml).
fn short_name(path: &str) -> String {
    let p = std::path::Path::new(path);
    let name = p
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.to_string());
    match p.parent().and_then(|d| d.file_name()) {
        Some(dir) if p.file_stem().is_some_and(|s| s == "scene") => {
            format!("{}/{name}", dir.to_string_lossy())
        }
        _ => name,
    }
}

fn compare_section(ui: &mut egui::Ui, app: &mut ViewerApp, editing: &mut Editing) {
    let was = app.settings.compare;
    ui.checkbox(&mut app.settings.compare, "Side-by-side comparison");
    if app.settings.compare && !was {
        // B starts as a copy of A with another sampler: one change to study.
        app.settings.b = Config {
            sampler: match app.settings.a.sampler {
                SamplerKind::Independent => SamplerKind::Sobol,
                _ => SamplerKind::Independent,
            },
            ..app.settings.a
        };
    }
    if !app.settings.compare {
        *editing = Editing::A;
        return;
    }
    ui.horizontal(|ui| {
        ui.label("Lock");
        ui.radio_value(&mut app.settings.lock, Lock::EqualSpp, "Equal spp");
        ui.radio_value(&mut app.settings.lock, Lock::EqualTime, "Equal time");
        ui.radio_value(&mut app.settings.lock, Lock::EqualRays, "Equal rays");
    });
    ui.horizontal(|ui| {
        ui.label("Layout");
        let layout = &mut app.settings.display.layout;
        ui.radio_value(layout, CompareLayout::Split, "Split");
        ui.radio_value(layout, CompareLayout::TwoPanes, "Two panes");
    });
    ui.horizontal(|ui| {
        ui.label("Edit");
        ui.selectable_value(editing, Editing::A, "A");
        ui.selectable_value(editing, Editing::B, "B");
    });
}

fn estimator_section(ui: &mut egui::Ui, config: &mut Config, merge_scale: Option<(f32, u32)>) {
    ui.heading("Estimator");
    let options = &mut config.integrator;
    for &kind in IntegratorKind::ALL {
        ui.radio_value(&mut options.kind, kind, kind.label())
            .on_hover_text(kind.summary());
    }
    super::controls::technique(ui, options, merge_scale);
    match config.fixed_sampler() {
        Some(fixed) => {
            ui.label(format!(
                "Sampler: {} (this display looks the solution up: its only noise is \
                 the pixels' coverage)",
                fixed.name()
            ));
        }
        None => sampler_rows(ui, config),
    }
    ui.horizontal(|ui| {
        let label = ui.label("Seed");
        ui.add(egui::DragValue::new(&mut config.seed))
            .labelled_by(label.id);
    });
}

/// The sampler, its domains and sample spreading, for techniques that
/// follow the session's sampler.
fn sampler_rows(ui: &mut egui::Ui, config: &mut Config) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Sampler");
        ui.radio_value(&mut config.sampler, SamplerKind::Independent, "Independent");
        ui.radio_value(&mut config.sampler, SamplerKind::Stratified, "Stratified");
        ui.radio_value(
            &mut config.sampler,
            SamplerKind::MultiJittered,
            "Multi-jittered",
        );
        ui.radio_value(&mut config.sampler, SamplerKind::Sobol, "Sobol");
    });
    let mut stratified = config.sampler != SamplerKind::Independent;
    if ui.checkbox(&mut stratified, "Stratify samples").changed() {
        config.sampler = if stratified {
            SamplerKind::Stratified
        } else {
            SamplerKind::Independent
        };
    }
    ui.add_enabled_ui(config.sampler != SamplerKind::Independent, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.label("Domains");
            let d = &mut config.domains;
            ui.checkbox(&mut d.pixel, "Pixel");
            ui.checkbox(&mut d.lens, "Lens");
            ui.checkbox(&mut d.time, "Time");
            ui.checkbox(&mut d.light, "Light");
            ui.checkbox(&mut d.bsdf, "BSDF");
        });
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Tent / Gaussian filter");
        ui.radio_value(&mut config.filter_sampling, FilterSampling::Splat, "Splat")
            .on_hover_text(
                "Each sample, uniform in its pixel, adds to every pixel the filter covers \
                 (Mitsuba's film): lower noise, correlated neighbours",
            );
        ui.radio_value(
            &mut config.filter_sampling,
            FilterSampling::Importance,
            "Importance",
        )
        .on_hover_text(
            "Each sample's position is drawn from the filter and counts in its own \
             pixel (pbrt-v4): independent pixels. Always so under adaptive sampling",
        );
    });
    if config.spreads_by_noise() || config.can_spread_by_noise() {
        ui.checkbox(
            &mut config.spread_by_noise,
            "Adaptive: spread samples by noise",
        )
        .on_hover_text(
            "After a few samples everywhere, each pass spends its samples where the \
                 per-pixel noise is (Neyman allocation): least RMSE for the time",
        );
    }
}

fn samples_section(ui: &mut egui::Ui, app: &mut ViewerApp) {
    ui.heading("Samples");
    ui.horizontal(|ui| {
        let label = ui.label("Target spp");
        ui.add_enabled(
            !app.settings.unlimited,
            egui::DragValue::new(&mut app.settings.target_spp)
                .range(1..=1_000_000)
                .speed(4),
        )
        .labelled_by(label.id);
        ui.checkbox(&mut app.settings.unlimited, "Unlimited");
    });
    let mut scene_size = app.settings.resolution.is_none();
    ui.checkbox(&mut scene_size, "Scene resolution");
    if scene_size {
        app.settings.resolution = None;
    } else {
        let (mut w, mut h) = app.settings.resolution.unwrap_or_else(|| {
            app.scene()
                .map_or((256, 256), |s| (s.camera.width, s.camera.height))
        });
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(&mut w).range(16..=4096).prefix("w "));
            ui.add(egui::DragValue::new(&mut h).range(16..=4096).prefix("h "));
        });
        app.settings.resolution = Some((w, h));
    }
    ray_offsets(ui, &mut app.settings.offset);
}

/// Robust offsets, or the classic fixed epsilon to see what it gets wrong.
fn ray_offsets(ui: &mut egui::Ui, offset: &mut OffsetMode) {
    ui.horizontal(|ui| {
        ui.label("Ray offsets");
        let mut fixed = matches!(offset, OffsetMode::Fixed(_));
        ui.radio_value(&mut fixed, false, "Robust");
        ui.radio_value(&mut fixed, true, "Fixed ε");
        let mut eps = match *offset {
            OffsetMode::Fixed(e) => e,
            OffsetMode::Robust => 1e-3,
        };
        if fixed {
            ui.add(
                egui::DragValue::new(&mut eps)
                    .range(0.0..=1e3)
                    .speed(1e-4)
                    .max_decimals(6),
            );
            *offset = OffsetMode::Fixed(eps);
        } else {
            *offset = OffsetMode::Robust;
        }
    });
}

fn display_section(ui: &mut egui::Ui, app: &mut ViewerApp) {
    ui.heading("Display");
    let display = &mut app.settings.display;
    ui.add(egui::Slider::new(&mut display.exposure, -8.0..=8.0).text("Exposure (stops)"));
    egui::ComboBox::from_label("Tone map")
        .selected_text(format!("{:?}", display.tone_map))
        .show_ui(ui, |ui| {
            for t in ToneMap::ALL {
                ui.selectable_value(&mut display.tone_map, t, format!("{t:?}"));
            }
        });
    ui.horizontal_wrapped(|ui| {
        for mode in ViewMode::ALL {
            ui.selectable_value(&mut display.view, mode, mode.label());
        }
    });
    if display.view == ViewMode::Fireflies {
        ui.add(
            egui::Slider::new(&mut display.firefly_threshold, 0.05..=2.0)
                .text("Firefly rel. error"),
        );
    }
}

fn reference_section(ui: &mut egui::Ui, app: &mut ViewerApp) {
    ui.heading("Reference");
    let mut path = app.settings.reference_path.clone();
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut path)
                .hint_text("reference.exr")
                .desired_width(180.0),
        );
        if ui.button("Load reference").clicked() {
            app.load_reference(&path);
        } else if ui.button("Clear").clicked() {
            app.load_reference("");
        } else {
            app.settings.reference_path = path;
        }
    });
    if let Some(path) = app.reference_beside_scene() {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        ui.label(format!("In use: {name}, found beside the scene"));
    }
    if ui
        .button("Use image A as reference")
        .on_hover_text("Freeze the current image A (e.g. a long render) as the reference for RMSE")
        .clicked()
    {
        app.use_view_as_reference(0);
    }
}

fn export_section(ui: &mut egui::Ui, app: &mut ViewerApp) {
    ui.heading("Export");
    ui.horizontal(|ui| {
        let label = ui.label("Export folder");
        ui.text_edit_singleline(&mut app.settings.export_dir)
            .labelled_by(label.id);
    });
    ui.horizontal_wrapped(|ui| {
        if ui.button("Export PNG").clicked() {
            for i in 0..app.configs().len() {
                app.export_png(i);
            }
        }
        if ui.button("Export EXR").clicked() {
            for i in 0..app.configs().len() {
                app.export_exr(i);
            }
        }
        if ui.button("Save window").clicked() {
            app.export_window();
        }
        if ui
            .add_enabled(
                app.settings.compare,
                egui::Button::new("Save comparison sheet"),
            )
            .clicked()
        {
            app.export_sheet();
        }
    });
}
