//! Live statistics and the convergence plot (log-log error against samples
//! per pixel or time, with 1/sqrt(N) and 1/N guides, one curve per
//! configuration, past configurations kept).

use super::app::ViewerApp;
use super::plot_scale::{format_power, log_grid};
use crate::integrator::ErrorEstimate;
use crate::live::{ErrorPoint, LiveView};
use eframe::egui;
use egui_plot::{Legend, Line, LineStyle, Plot, PlotPoints};

pub fn stats_panel(ui: &mut egui::Ui, app: &mut ViewerApp) {
    let frame = app.frame();
    // One line per item, truncated rather than wrapped, so that the panel's
    // layout does not jump as the numbers change.
    for (i, view) in frame.views.iter().enumerate() {
        let name = if frame.views.len() == 2 {
            if i == 0 { "A" } else { "B" }
        } else {
            ""
        };
        ui.add(
            egui::Label::new(egui::RichText::new(view_summary(name, view, app)).monospace())
                .truncate(),
        );
        // A solver's own counters, on a line of their own (the summary
        // above is cut at the panel's width).
        if let Some(solver) = view.stats.solver
            && solver.elements > 0
        {
            ui.label(
                egui::RichText::new(format!(
                    "{name} solver: {} steps, {} elements, {} links, {:.1} MB, residual {:.3e}",
                    solver.steps,
                    solver.elements,
                    solver.links,
                    solver.memory as f64 * 1e-6,
                    solver.residual
                ))
                .monospace(),
            );
        }
        if !view.notes.is_empty() {
            let text = format!("{name} notes: {}", view.notes.join(" | "));
            ui.add(egui::Label::new(egui::RichText::new(text).weak()).truncate())
                .on_hover_text(view.notes.join("\n"));
        }
        if !view.shortcuts.is_empty() {
            let text = format!("{name} shortcuts: {}", view.shortcuts.join(" | "));
            ui.add(egui::Label::new(egui::RichText::new(text).weak()).truncate())
                .on_hover_text(view.shortcuts.join("\n"));
        }
    }
    {
        let mut parts = Vec::new();
        if let Some(p95) = app.frame_time_p95() {
            parts.push(format!("UI frame p95 {:.1} ms", p95 * 1e3));
        }
        if let Some(latency) = app.restart_latency_median() {
            parts.push(format!("setting -> image {:.0} ms", latency * 1e3));
        }
        if let Some(rss) = resident_memory_mib() {
            parts.push(format!("memory {rss:.0} MiB"));
        }
        parts.push(if app.live().is_rendering() {
            "rendering".into()
        } else {
            "done".into()
        });
        ui.add(egui::Label::new(egui::RichText::new(parts.join(" | ")).weak()).truncate());
    }
}

fn view_summary(name: &str, view: &LiveView, app: &ViewerApp) -> String {
    let s = &view.stats;
    let seconds = s.render_time.as_secs_f64().max(1e-9);
    let pixels = view.snapshot.samples.len().max(1) as f64;
    let last = view.history.last();
    let mut text = format!(
        "{name} {} spp | {:.2} s | {}{} | {:.2} M samples/s | {:.1} M rays/s | rays/px {:.0} (cam {:.0}, shadow {:.0}, bounce {:.0})",
        s.spp,
        s.render_time.as_secs_f64(),
        match last.map(|p| p.estimate) {
            Some(ErrorEstimate::Sampling(rmse)) => format!("est. RMSE {rmse:.5}"),
            Some(ErrorEstimate::Deterministic) => "deterministic: no sampling noise".into(),
            Some(ErrorEstimate::Residual(r)) => format!("residual {r:.3e}"),
            Some(ErrorEstimate::Unknown) | None => "est. RMSE n/a".into(),
        },
        match last.and_then(|p| p.rmse) {
            // A smaller reference is compared with the image box-downsampled.
            Some(rmse) => match app
                .reference()
                .and_then(|r| view.snapshot.image.scale_over(r))
                .filter(|&k| k > 1)
            {
                Some(k) => format!(" | RMSE {rmse:.5} (image box-downsampled {k}x)"),
                None => format!(" | RMSE {rmse:.5}"),
            },
            None if app.reference().is_some() => " | RMSE n/a (size differs)".into(),
            None => String::new(),
        },
        s.samples as f64 / seconds * 1e-6,
        s.rays.total() as f64 / seconds * 1e-6,
        s.rays.total() as f64 / pixels,
        s.rays.camera as f64 / pixels,
        s.rays.shadow as f64 / pixels,
        s.rays.bounce as f64 / pixels,
    );
    if s.non_finite > 0 {
        text += &format!(" | non-finite {}", s.non_finite);
    }
    if let Some(failure) = &view.failure {
        text += &format!(" | failed: {failure}");
    }
    text
}

/// Resident set size of this process (Linux), for the long-session check.
pub fn resident_memory_mib() -> Option<f64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: f64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096.0 / (1024.0 * 1024.0))
}

/// The metric plotted: RMSE when a reference is loaded, else the film's noise.
fn metric(p: &ErrorPoint, use_rmse: bool) -> Option<f64> {
    let v = if use_rmse {
        p.rmse?
    } else {
        match p.estimate {
            ErrorEstimate::Sampling(v) | ErrorEstimate::Residual(v) => v,
            // Nothing to plot: no noise, or not known yet.
            ErrorEstimate::Deterministic | ErrorEstimate::Unknown => return None,
        }
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Seconds, or progress: samples per pixel, a solver's steps.
fn abscissa(p: &ErrorPoint, time: bool) -> Option<f64> {
    let x = if time { p.seconds } else { p.progress as f64 };
    (x > 0.0).then_some(x)
}

fn log_points(points: &[ErrorPoint], time: bool, use_rmse: bool) -> Vec<[f64; 2]> {
    points
        .iter()
        .filter_map(|p| Some([abscissa(p, time)?.log10(), metric(p, use_rmse)?.log10()]))
        .collect()
}

/// The plot fills the height left in `ui` (never more, so that a panel
/// holding it does not grow frame after frame).
pub fn convergence_plot(ui: &mut egui::Ui, app: &mut ViewerApp) {
    let frame = app.frame();
    let use_rmse = app.reference().is_some();
    ui.horizontal(|ui| {
        ui.label(if use_rmse {
            "RMSE vs reference"
        } else {
            "Estimated RMSE (film variance; load a reference for the true RMSE)"
        });
        ui.radio_value(&mut app.settings.display.plot_time, false, "vs spp / steps");
        ui.radio_value(&mut app.settings.display.plot_time, true, "vs time");
        if ui.button("Clear old curves").clicked() {
            app.curves.clear();
        }
    });
    let height = (ui.available_height() - 6.0).max(60.0);
    let time = app.settings.display.plot_time;
    let current: Vec<(String, Vec<[f64; 2]>)> = frame
        .views
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let prefix = if frame.views.len() == 2 {
                if i == 0 { "A: " } else { "B: " }
            } else {
                ""
            };
            (
                format!("{prefix}{}", app.view_label(i)),
                log_points(&v.history, time, use_rmse),
            )
        })
        .collect();
    let past: Vec<(String, Vec<[f64; 2]>)> = app
        .curves
        .iter()
        .map(|c| (c.label.clone(), log_points(&c.points, time, use_rmse)))
        .collect();
    let anchor = current.first().and_then(|(_, pts)| pts.first().copied());
    let x_end = current
        .iter()
        .chain(&past)
        .flat_map(|(_, p)| p.iter().map(|q| q[0]))
        .fold(f64::NAN, f64::max);
    let ten_to =
        |mark: egui_plot::GridMark, _: &std::ops::RangeInclusive<f64>| format_power(mark.value);
    Plot::new("convergence")
        .height(height)
        .legend(Legend::default())
        .x_axis_label(if time {
            "seconds"
        } else {
            "spp (solvers: steps)"
        })
        .x_axis_formatter(ten_to)
        .y_axis_formatter(ten_to)
        .x_grid_spacer(log_grid)
        .y_grid_spacer(log_grid)
        .show(ui, |plot| {
            for (label, points) in past {
                plot.line(
                    Line::new(label, PlotPoints::from(points)).style(LineStyle::dotted_dense()),
                );
            }
            for (label, points) in current {
                plot.line(Line::new(label, PlotPoints::from(points)).width(2.0));
            }
            if let Some([x0, y0]) = anchor
                && x_end.is_finite()
                && x_end > x0
            {
                for (label, slope) in [("1/sqrt(N)", -0.5), ("1/N", -1.0)] {
                    let guide = vec![[x0, y0], [x_end, y0 + slope * (x_end - x0)]];
                    plot.line(
                        Line::new(label, PlotPoints::from(guide))
                            .style(LineStyle::dashed_loose())
                            .color(egui::Color32::GRAY),
                    );
                }
            }
        });
}
