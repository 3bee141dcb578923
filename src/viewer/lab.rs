//! The "MC lab" tab: the Monte Carlo lab's experiments run live on their own
//! thread ([`crate::lab::LabRunner`]); this file only edits their settings
//! and draws the latest report (figures with egui_plot, histograms and
//! spectra as textures, tables, checks). The UI thread never waits on a run.

use crate::lab::{Axes, Experiment, Figure, LabRunner, LabSettings, Report, SeriesStyle};
use crate::sampling::SamplerKind;
use eframe::egui::{self, Color32, ColorImage, RichText, TextureHandle, TextureOptions};
use egui_plot::{Legend, Line, Plot, PlotPoints, Points};
use std::sync::Arc;
use std::time::Duration;

/// Least time between the stages a live run shows, so that curves visibly grow.
const PACE: Duration = Duration::from_millis(120);

/// Series colours: the same palette as the CLI's plots.
const PALETTE: [Color32; 8] = [
    Color32::from_rgb(31, 119, 180),
    Color32::from_rgb(255, 127, 14),
    Color32::from_rgb(44, 160, 44),
    Color32::from_rgb(214, 39, 40),
    Color32::from_rgb(148, 103, 189),
    Color32::from_rgb(140, 86, 75),
    Color32::from_rgb(227, 119, 194),
    Color32::from_rgb(150, 150, 150),
];

/// The lab's state in the viewer.
pub struct LabState {
    /// The settings being edited; a run starts from a copy.
    pub settings: LabSettings,
    runner: Option<LabRunner>,
    /// Textures of the shown report's heatmaps, by figure index.
    textures: Vec<Option<TextureHandle>>,
    textured: Option<Arc<Report>>,
    /// Frames drawn since the run finished (the automated screenshot waits
    /// until the final report has been drawn).
    pub frames_since_finished: u32,
}

impl Default for LabState {
    fn default() -> Self {
        LabState::new(Experiment::Pi)
    }
}

impl LabState {
    /// The lab on `experiment`, not yet running.
    pub fn new(experiment: Experiment) -> LabState {
        LabState {
            settings: LabState::defaults(experiment),
            runner: None,
            textures: Vec::new(),
            textured: None,
            frames_since_finished: 0,
        }
    }

    /// An experiment's default settings, paced for watching.
    fn defaults(experiment: Experiment) -> LabSettings {
        LabSettings {
            pace: PACE,
            ..experiment.default_settings()
        }
    }

    /// Switches to `experiment` with its default settings and runs it.
    pub fn select(&mut self, experiment: Experiment) {
        let sampler = self.settings.sampler;
        self.settings = LabState::defaults(experiment);
        self.settings.sampler = sampler;
        self.start();
    }

    /// (Re)starts the experiment with the edited settings.
    pub fn start(&mut self) {
        if let Some(mut old) = self.runner.take() {
            old.cancel();
        }
        self.runner = Some(LabRunner::start(self.settings.clone()));
    }

    /// Starts a run if none has been made yet (the tab was just opened).
    pub fn ensure_started(&mut self) {
        if self.runner.is_none() {
            self.start();
        }
    }

    /// Stops the running experiment, keeping its partial report.
    pub fn cancel(&mut self) {
        if let Some(runner) = &mut self.runner {
            runner.cancel();
        }
    }

    /// Whether an experiment is running.
    pub fn is_running(&mut self) -> bool {
        self.runner.as_mut().is_some_and(LabRunner::is_running)
    }

    /// Whether the last run finished (not cancelled).
    pub fn is_finished(&mut self) -> bool {
        match &mut self.runner {
            Some(r) => !r.is_running() && !r.was_cancelled(),
            None => false,
        }
    }

    /// Whether the last run ended by a cancel.
    pub fn was_cancelled(&self) -> bool {
        self.runner.as_ref().is_some_and(LabRunner::was_cancelled)
    }

    /// The report shown: the final one, or the latest partial one.
    pub fn report(&self) -> Option<Arc<Report>> {
        self.runner.as_ref().and_then(LabRunner::report)
    }

    /// The experiment of the shown run (or of the settings before any run).
    pub fn experiment(&self) -> Experiment {
        self.runner
            .as_ref()
            .map_or(self.settings.experiment, LabRunner::experiment)
    }

    /// Progress text: stages, work units, seconds; "cancelled" after a cancel.
    pub fn status(&mut self) -> String {
        let Some(runner) = &mut self.runner else {
            return "not started".into();
        };
        let running = runner.is_running();
        let (done, planned) = runner.progress().counts();
        let stages = runner
            .report()
            .map_or((0, 0), |r| (r.stages_done, r.stages_planned));
        let state = if running {
            "running"
        } else if runner.was_cancelled() {
            "cancelled"
        } else {
            "done"
        };
        format!(
            "{state}: stage {}/{}, {:.0}% of {} samples, {:.1} s",
            stages.0,
            stages.1,
            100.0 * done as f64 / planned.max(1) as f64,
            planned,
            runner.seconds()
        )
    }

    /// Uploads the heatmaps of a newly published report.
    fn update_textures(&mut self, ctx: &egui::Context) {
        let report = self.report();
        let same = match (&report, &self.textured) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        if same {
            return;
        }
        self.textures = report.as_ref().map_or(Vec::new(), |r| {
            r.figures
                .iter()
                .enumerate()
                .map(|(i, f)| {
                    f.heatmap.as_ref().map(|map| {
                        let pixels: Vec<Color32> = (0..map.height)
                            .rev()
                            .flat_map(|row| (0..map.width).map(move |col| row * map.width + col))
                            .map(|k| {
                                let level = (255.0 * map.values[k].clamp(0.0, 1.0)) as u8;
                                Color32::from_gray(level)
                            })
                            .collect();
                        let image = ColorImage {
                            size: [map.width, map.height],
                            source_size: egui::vec2(map.width as f32, map.height as f32),
                            pixels,
                        };
                        ctx.load_texture(format!("lab-heatmap-{i}"), image, TextureOptions::NEAREST)
                    })
                })
                .collect()
        });
        self.textured = report;
    }
}

/// The side panel: experiments, controls, progress, the lab text, the checks.
pub fn lab_panel(ui: &mut egui::Ui, lab: &mut LabState) {
    ui.heading("Monte Carlo lab");
    ui.label(
        RichText::new("The renderer's own samplers and warps, on integrals with known answers.")
            .weak(),
    );
    ui.separator();
    let current = lab.settings.experiment;
    for experiment in Experiment::ALL {
        if ui
            .selectable_label(current == experiment, experiment.label())
            .clicked()
            && current != experiment
        {
            lab.select(experiment);
        }
    }
    ui.separator();
    let before = lab.settings.clone();
    egui::Grid::new("lab-controls")
        .num_columns(2)
        .show(ui, |ui| {
            if matches!(
                current,
                Experiment::Pi | Experiment::PointSets | Experiment::Stratified
            ) {
                ui.label("Scatter sampler");
                egui::ComboBox::from_id_salt("lab-sampler")
                    .selected_text(lab.settings.sampler.name())
                    .show_ui(ui, |ui| {
                        for kind in SamplerKind::ALL {
                            ui.selectable_value(&mut lab.settings.sampler, kind, kind.name());
                        }
                    });
                ui.end_row();
            }
            let max_n = match current {
                Experiment::Coins => 1 << 14,
                Experiment::PointSets => crate::lab::MAX_POINT_SET,
                Experiment::Clusters => crate::lab::MAX_CLUSTER_TRIANGLES,
                Experiment::ClusterSolve => crate::lab::MAX_SOLVE_TRIANGLES,
                _ => 10_000_000,
            };
            ui.label("Largest N");
            ui.add(
                egui::DragValue::new(&mut lab.settings.n)
                    .range(16..=max_n)
                    .speed(100.0),
            );
            ui.end_row();
            if !matches!(
                current,
                Experiment::Importance
                    | Experiment::Warps
                    | Experiment::Clusters
                    | Experiment::ClusterSolve
            ) {
                ui.label("Runs");
                ui.add(
                    egui::DragValue::new(&mut lab.settings.runs)
                        .range(2..=100_000)
                        .speed(10.0),
                );
                ui.end_row();
            }
            ui.label("Seed");
            ui.add(egui::DragValue::new(&mut lab.settings.seed));
            ui.end_row();
        });
    if lab.settings != before {
        lab.start();
    }
    ui.horizontal(|ui| {
        if ui.button("Run again").clicked() {
            lab.start();
        }
        let running = lab.is_running();
        if ui
            .add_enabled(running, egui::Button::new("Cancel"))
            .clicked()
        {
            lab.cancel();
        }
    });
    ui.label(RichText::new(lab.status()).monospace().small());
    ui.separator();
    egui::ScrollArea::vertical()
        .id_salt("lab-text")
        .show(ui, |ui| {
            ui.label(lab.experiment().text());
            if let Some(report) = lab.report()
                && !report.checks.is_empty()
            {
                ui.separator();
                for check in &report.checks {
                    let (mark, color) = if check.holds {
                        ("holds", Color32::from_rgb(90, 180, 90))
                    } else {
                        ("does not hold", Color32::from_rgb(220, 80, 80))
                    };
                    ui.label(RichText::new(format!("{mark}: {}", check.statement)).color(color));
                    ui.label(RichText::new(&check.measured).small().weak());
                }
            }
        });
}

/// The central area: the report's figures in a grid, then its tables.
pub fn lab_area(ui: &mut egui::Ui, lab: &mut LabState) {
    lab.update_textures(ui.ctx());
    if lab.is_finished() {
        lab.frames_since_finished += 1;
    } else {
        lab.frames_since_finished = 0;
    }
    let Some(report) = lab.report() else {
        ui.centered_and_justified(|ui| ui.label("Starting…"));
        return;
    };
    egui::ScrollArea::vertical()
        .id_salt("lab-area")
        .show(ui, |ui| {
            // Warps have three figures per routine (points, histogram, pdf): one row each.
            let columns = if lab.experiment() == Experiment::Warps {
                3
            } else {
                2
            };
            let width = (ui.available_width() / columns as f32 - 8.0).max(160.0);
            let height = (width * 0.7).clamp(140.0, 360.0);
            for (row, figures) in report.figures.chunks(columns).enumerate() {
                ui.horizontal(|ui| {
                    for (k, figure) in figures.iter().enumerate() {
                        let index = row * columns + k;
                        ui.vertical(|ui| {
                            ui.set_width(width);
                            ui.label(RichText::new(&figure.title).strong().small());
                            match lab.textures.get(index).and_then(Option::as_ref) {
                                Some(texture) => {
                                    ui.image((texture.id(), egui::vec2(width, height)));
                                }
                                None => draw_figure(ui, figure, index, egui::vec2(width, height)),
                            }
                        });
                    }
                });
            }
            ui.separator();
            for (t, table) in report.tables.iter().enumerate() {
                ui.label(RichText::new(&table.title).strong());
                egui::ScrollArea::horizontal()
                    .id_salt(("lab-table", t))
                    .show(ui, |ui| {
                        egui::Grid::new(("lab-table-grid", t))
                            .striped(true)
                            .show(ui, |ui| {
                                for c in &table.columns {
                                    ui.label(RichText::new(c).small().strong());
                                }
                                ui.end_row();
                                for row in &table.rows {
                                    for cell in row {
                                        ui.label(RichText::new(&cell.text).monospace().small());
                                    }
                                    ui.end_row();
                                }
                            });
                    });
                ui.add_space(6.0);
            }
        });
}

/// One figure with egui_plot: log axes as log10 of the values.
fn draw_figure(ui: &mut egui::Ui, figure: &Figure, index: usize, size: egui::Vec2) {
    let log = figure.axes == Axes::LogLog;
    let transform = |(x, y): (f64, f64)| -> Option<[f64; 2]> {
        if log {
            (x > 0.0 && y > 0.0).then(|| [x.log10(), y.log10()])
        } else {
            Some([x, y])
        }
    };
    let mut plot = Plot::new(("lab-figure", index))
        .width(size.x)
        .height(size.y)
        .legend(Legend::default())
        .allow_scroll(false)
        .x_axis_label(figure.x_label.as_str())
        .y_axis_label(figure.y_label.as_str());
    if log {
        plot = plot
            .x_axis_formatter(|mark, _| super::plot_scale::format_power(mark.value))
            .y_axis_formatter(|mark, _| super::plot_scale::format_power(mark.value))
            .x_grid_spacer(super::plot_scale::log_grid)
            .y_grid_spacer(super::plot_scale::log_grid);
    } else if let Axes::Linear { x, y } = figure.axes {
        plot = plot.default_x_bounds(x.0, x.1).default_y_bounds(y.0, y.1);
        // Point sets and warped points are shapes: a square plot keeps circles round.
        if x == y {
            let side = size.x.min(size.y);
            plot = plot.width(side).height(side);
        }
    }
    plot.show(ui, |plot_ui| {
        for s in &figure.series {
            let points: Vec<[f64; 2]> = s.points.iter().filter_map(|&p| transform(p)).collect();
            let color = match s.style {
                SeriesStyle::Guide => PALETTE[7],
                _ => PALETTE[s.color % PALETTE.len()],
            };
            match s.style {
                SeriesStyle::Points => plot_ui.points(
                    Points::new(s.name.as_str(), PlotPoints::from(points))
                        .color(color)
                        .radius(1.5),
                ),
                SeriesStyle::Line => plot_ui.line(
                    Line::new(s.name.as_str(), PlotPoints::from(points))
                        .color(color)
                        .width(2.0),
                ),
                SeriesStyle::Guide => plot_ui.line(
                    Line::new(s.name.as_str(), PlotPoints::from(points))
                        .color(color)
                        .width(1.0)
                        .style(egui_plot::LineStyle::dashed_loose()),
                ),
            }
        }
    });
}
