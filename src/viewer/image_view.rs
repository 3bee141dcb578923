//! The central image: one view, a split view with a draggable divider, or two
//! panes; zoom (scroll), pan (left drag), camera orbit (right drag) and dolly
//! (shift + scroll); a pixel inspector under the cursor; view-mode legends.

use super::app::ViewerApp;
use super::display::{
    SAMPLES_SCALE_LOG2, STANDARD_ERROR_SCALE, diverging, relative_standard_error, sequential,
};
use super::settings::{CompareLayout, ViewMode};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Vec2, pos2, vec2};

const UV_FULL: Rect = Rect::from_min_max(Pos2::ZERO, pos2(1.0, 1.0));

pub fn image_area(ui: &mut egui::Ui, app: &mut ViewerApp) {
    let frame = app.frame();
    let textures = app.textures().to_vec();
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    let Some(first) = frame.views.first() else {
        ui.painter().text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "Starting the renderer...",
            egui::FontId::proportional(16.0),
            ui.visuals().text_color(),
        );
        return;
    };
    if textures.len() < frame.views.len() {
        return;
    }
    let image_size = vec2(
        first.snapshot.image.width as f32,
        first.snapshot.image.height as f32,
    );
    let two_panes = textures.len() == 2 && app.settings.display.layout == CompareLayout::TwoPanes;
    let panes: Vec<Rect> = if two_panes {
        let half = rect.width() / 2.0;
        vec![
            Rect::from_min_size(rect.min, vec2(half - 2.0, rect.height())),
            Rect::from_min_size(
                rect.min + vec2(half + 2.0, 0.0),
                vec2(half - 2.0, rect.height()),
            ),
        ]
    } else {
        vec![rect]
    };
    // Fitting fills the area: a 256x256 image in a large area shown at a
    // whole factor (2x in 700 points) looked small. A whole factor is kept
    // only where it fills at least 90% of the fit, so that every image
    // pixel covers the same number of screen pixels when that costs little.
    let fit = (panes[0].width() / image_size.x).min(panes[0].height() / image_size.y);
    let fit = if fit >= 1.0 && fit.floor() >= 0.9 * fit {
        fit.floor()
    } else {
        fit
    };
    let zoom = app.view.zoom.unwrap_or(fit).max(0.01);
    let pixels_per_point = ui.ctx().pixels_per_point();
    let snap = |p: Pos2| {
        pos2(
            (p.x * pixels_per_point).round() / pixels_per_point,
            (p.y * pixels_per_point).round() / pixels_per_point,
        )
    };

    // Zoom about the cursor; shift + scroll dollies the camera instead.
    if response.hovered() {
        let (scroll, shift, pointer) = ui.input(|i| {
            (
                i.smooth_scroll_delta.y,
                i.modifiers.shift,
                i.pointer.hover_pos(),
            )
        });
        if scroll != 0.0 {
            if shift {
                app.orbit(0.0, 0.0, (-scroll * 0.002).exp());
            } else if let Some(pointer) = pointer {
                let factor = (scroll * 0.002).exp();
                let new_zoom = (zoom * factor).clamp(0.05, 64.0);
                let centre = panes[0].center() + app.view.pan;
                let from_centre = pointer - centre;
                app.view.pan += from_centre - from_centre * (new_zoom / zoom);
                app.view.zoom = Some(new_zoom);
            }
        }
    }
    if response.dragged_by(egui::PointerButton::Primary) {
        app.view.pan += response.drag_delta();
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        let d = response.drag_delta();
        app.orbit(d.x * 0.005, d.y * 0.005, 1.0);
    }

    let painter = ui.painter_at(rect);
    let image_rects: Vec<Rect> = panes
        .iter()
        .map(|pane| {
            let r = Rect::from_center_size(pane.center() + app.view.pan, image_size * zoom);
            Rect::from_min_size(snap(r.min), r.size())
        })
        .collect();
    if two_panes {
        for (i, (pane, image_rect)) in panes.iter().zip(&image_rects).enumerate() {
            let painter = painter.with_clip_rect(*pane);
            painter.image(textures[i].id(), *image_rect, UV_FULL, Color32::WHITE);
            pane_label(
                &painter,
                *pane,
                &format!("{}: {}", letter(i), app.view_label(i)),
                frame.views[i].stats.spp,
            );
        }
    } else if textures.len() == 2 {
        // Split view: A left of the divider, B right of it.
        let image_rect = image_rects[0];
        let split_x = image_rect.left() + app.settings.display.split * image_rect.width();
        let left = Rect::from_min_max(rect.min, pos2(split_x, rect.max.y));
        let right = Rect::from_min_max(pos2(split_x, rect.min.y), rect.max);
        painter
            .with_clip_rect(left)
            .image(textures[0].id(), image_rect, UV_FULL, Color32::WHITE);
        painter
            .with_clip_rect(right)
            .image(textures[1].id(), image_rect, UV_FULL, Color32::WHITE);
        let handle =
            Rect::from_center_size(pos2(split_x, rect.center().y), vec2(10.0, rect.height()));
        let divider = ui.interact(handle, ui.scope_id().with("divider"), Sense::drag());
        if divider.dragged() {
            let x = divider.interact_pointer_pos().map_or(split_x, |p| p.x);
            app.settings.display.split =
                ((x - image_rect.left()) / image_rect.width()).clamp(0.0, 1.0);
        }
        if divider.hovered() || divider.dragged() {
            ui.ctx().set_cursor_icon(egui::CursorIcon::ResizeHorizontal);
        }
        painter.line_segment(
            [pos2(split_x, rect.top()), pos2(split_x, rect.bottom())],
            Stroke::new(2.0, Color32::WHITE),
        );
        pane_label(
            &painter,
            left,
            &format!("A: {}", app.view_label(0)),
            frame.views[0].stats.spp,
        );
        let right_label = Rect::from_min_max(pos2(split_x + 4.0, rect.min.y), rect.max);
        pane_label(
            &painter,
            right_label,
            &format!("B: {}", app.view_label(1)),
            frame.views[1].stats.spp,
        );
    } else {
        painter.image(textures[0].id(), image_rects[0], UV_FULL, Color32::WHITE);
    }

    legend(&painter, rect, app.settings.display.view);

    // Pixel inspector.
    if let Some(pointer) = response.hover_pos() {
        let pane = panes.iter().position(|p| p.contains(pointer)).unwrap_or(0);
        let image_rect = image_rects[pane];
        let mut view_index = pane;
        if !two_panes && textures.len() == 2 {
            let split_x = image_rect.left() + app.settings.display.split * image_rect.width();
            view_index = usize::from(pointer.x >= split_x);
        }
        let p = (pointer - image_rect.min) / zoom;
        let (x, y) = (p.x.floor() as i64, p.y.floor() as i64);
        let (w, h) = (image_size.x as i64, image_size.y as i64);
        if (0..w).contains(&x) && (0..h).contains(&y) {
            let snapshot = &frame.views[view_index].snapshot;
            let i = (y * w + x) as usize;
            let m = snapshot.image.pixels[i];
            let se = snapshot.standard_error.pixels[i];
            let text = format!(
                "{} ({x}, {y})  L = {:.4} {:.4} {:.4}  spp {}  std. error {:.4} {:.4} {:.4} ({:.1}%)",
                letter(view_index),
                m[0],
                m[1],
                m[2],
                snapshot.samples[i],
                se[0],
                se[1],
                se[2],
                100.0 * relative_standard_error(m, se)
            );
            let bar = Rect::from_min_max(pos2(rect.left(), rect.bottom() - 20.0), rect.max);
            painter.rect_filled(bar, 0.0, Color32::from_black_alpha(180));
            painter.text(
                bar.left_center() + vec2(6.0, 0.0),
                egui::Align2::LEFT_CENTER,
                text,
                egui::FontId::monospace(12.0),
                Color32::WHITE,
            );
        }
    }
}

fn letter(i: usize) -> &'static str {
    if i == 0 { "A" } else { "B" }
}

fn pane_label(painter: &egui::Painter, pane: Rect, text: &str, spp: u32) {
    let galley = painter.layout_no_wrap(
        format!("{text}  {spp} spp"),
        egui::FontId::proportional(13.0),
        Color32::WHITE,
    );
    let pos = pane.min + vec2(6.0, 6.0);
    painter.rect_filled(
        Rect::from_min_size(pos - vec2(3.0, 2.0), galley.size() + vec2(6.0, 4.0)),
        3.0,
        Color32::from_black_alpha(160),
    );
    painter.galley(pos, galley, Color32::WHITE);
}

/// Colour bar for the analysis views.
fn legend(painter: &egui::Painter, rect: Rect, mode: ViewMode) {
    let (low, high, colour): (&str, String, fn(f32) -> Color32) = match mode {
        ViewMode::StandardError => (
            "0",
            format!("{:.0}% rel. std. error", STANDARD_ERROR_SCALE * 100.0),
            sequential,
        ),
        ViewMode::Difference => ("-1", "+1 (A - B, x exposure)".into(), |t| {
            diverging(2.0 * t - 1.0)
        }),
        ViewMode::Samples => (
            "1",
            format!("{} spp (log scale)", 1u32 << SAMPLES_SCALE_LOG2 as u32),
            sequential,
        ),
        _ => return,
    };
    let bar = Rect::from_min_size(rect.right_top() + vec2(-230.0, 10.0), vec2(200.0, 12.0));
    painter.rect_filled(bar.expand(22.0), 4.0, Color32::from_black_alpha(170));
    let steps = 50;
    for s in 0..steps {
        let t0 = s as f32 / steps as f32;
        let r = Rect::from_min_max(
            pos2(bar.left() + t0 * bar.width(), bar.top()),
            pos2(
                bar.left() + (t0 + 1.0 / steps as f32) * bar.width() + 0.5,
                bar.bottom(),
            ),
        );
        painter.rect_filled(r, 0.0, colour(t0));
    }
    let font = egui::FontId::proportional(11.0);
    painter.text(
        bar.left_bottom() + Vec2::new(0.0, 2.0),
        egui::Align2::LEFT_TOP,
        low,
        font.clone(),
        Color32::WHITE,
    );
    painter.text(
        bar.right_bottom() + Vec2::new(0.0, 2.0),
        egui::Align2::RIGHT_TOP,
        high,
        font,
        Color32::WHITE,
    );
}
