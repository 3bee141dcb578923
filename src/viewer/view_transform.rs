//! Zoom and pan of the image area: view state the app holds and the image
//! view changes; never persisted, never restarts a render.

use eframe::egui;

/// Zoom and pan of the image area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewTransform {
    /// Screen points per image pixel; `None` fits the image to the area.
    pub zoom: Option<f32>,
    pub pan: egui::Vec2,
}

impl Default for ViewTransform {
    fn default() -> Self {
        ViewTransform {
            zoom: None,
            pan: egui::Vec2::ZERO,
        }
    }
}
