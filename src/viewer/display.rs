//! Radiance to screen colour: exposure, tone mapping, sRGB encoding, and the
//! false-colour maps of the analysis views. Pure functions of pixels.

use super::settings::{Display, ToneMap, ViewMode};
use crate::film::FilmSnapshot;
use eframe::egui::{Color32, ColorImage};

/// sRGB transfer function of a linear value in [0, 1].
#[inline]
fn srgb_encode(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

#[inline]
fn tone_map(v: f32, map: ToneMap) -> f32 {
    let v = if v.is_finite() { v.max(0.0) } else { 0.0 };
    match map {
        ToneMap::Clamp => v,
        ToneMap::Reinhard => v / (1.0 + v),
        ToneMap::Aces => (v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14),
    }
}

/// A radiance value as displayed.
#[inline]
pub fn radiance_to_color(rgb: [f32; 3], display: &Display) -> Color32 {
    let scale = display.exposure.exp2();
    let [r, g, b] = rgb.map(|v| srgb_encode(tone_map(v * scale, display.tone_map)));
    Color32::from_rgb(r, g, b)
}

/// Blue-to-red diverging map of `v` in [-1, 1] (white at 0).
#[inline]
pub fn diverging(v: f32) -> Color32 {
    let v = if v.is_finite() {
        v.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let fade = (255.0 * (1.0 - v.abs())) as u8;
    if v >= 0.0 {
        Color32::from_rgb(255, fade, fade)
    } else {
        Color32::from_rgb(fade, fade, 255)
    }
}

/// A perceptually ordered dark-to-bright map of `t` in [0, 1] (a 5-stop
/// approximation of viridis).
pub fn sequential(t: f32) -> Color32 {
    const STOPS: [[f32; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| (STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

/// Upper end of the standard-error colour scale (relative error).
pub const STANDARD_ERROR_SCALE: f32 = 0.5;

/// Samples per pixel at the top of the samples view's colour scale (log2).
pub const SAMPLES_SCALE_LOG2: f32 = 12.0;

/// Relative standard error of a pixel (luminance-weighted).
#[inline]
pub fn relative_standard_error(mean: [f32; 3], se: [f32; 3]) -> f32 {
    let l = 0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2];
    let s = 0.2126 * se[0] + 0.7152 * se[1] + 0.0722 * se[2];
    if l > 0.0 { s / l } else { 0.0 }
}

/// The screen image of `view` for the selected view mode. `other` is the
/// image that differences are taken against (B, or a reference).
pub fn render_view(
    view: &FilmSnapshot,
    other: Option<&crate::image::Image>,
    display: &Display,
) -> ColorImage {
    let (w, h) = (view.image.width as usize, view.image.height as usize);
    let scale = display.exposure.exp2();
    let pixels: Vec<Color32> = match display.view {
        ViewMode::Image => view
            .image
            .pixels
            .iter()
            .map(|p| radiance_to_color(*p, display))
            .collect(),
        ViewMode::Difference => {
            match other.filter(|o| (o.width, o.height) == (view.image.width, view.image.height)) {
                Some(other) => view
                    .image
                    .pixels
                    .iter()
                    .zip(&other.pixels)
                    .map(|(a, b)| {
                        let d = (0..3).map(|c| a[c] - b[c]).sum::<f32>() / 3.0;
                        diverging(d * scale)
                    })
                    .collect(),
                None => vec![Color32::from_gray(40); w * h],
            }
        }
        ViewMode::StandardError => view
            .image
            .pixels
            .iter()
            .zip(&view.standard_error.pixels)
            .map(|(m, se)| sequential(relative_standard_error(*m, *se) / STANDARD_ERROR_SCALE))
            .collect(),
        ViewMode::Fireflies => view
            .image
            .pixels
            .iter()
            .zip(&view.standard_error.pixels)
            .zip(&view.non_finite_pixels)
            .map(|((m, se), bad)| {
                if *bad > 0 {
                    Color32::from_rgb(255, 0, 255)
                } else if relative_standard_error(*m, *se) > display.firefly_threshold {
                    Color32::from_rgb(255, 220, 0)
                } else {
                    let c = radiance_to_color(*m, display);
                    // Dim the rest so the marks stand out.
                    Color32::from_rgb(c.r() / 3, c.g() / 3, c.b() / 3)
                }
            })
            .collect(),
        ViewMode::Samples => view
            .samples
            .iter()
            .map(|&n| sequential((n.max(1) as f32).log2() / SAMPLES_SCALE_LOG2))
            .collect(),
    };
    ColorImage::new([w, h], pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_and_tone_maps_hit_their_end_points() {
        assert_eq!(srgb_encode(0.0), 0);
        assert_eq!(srgb_encode(1.0), 255);
        assert_eq!(srgb_encode(0.5), 188);
        assert_eq!(tone_map(1.0, ToneMap::Reinhard), 0.5);
        assert!(tone_map(100.0, ToneMap::Aces) > 0.99);
        assert_eq!(tone_map(f32::NAN, ToneMap::Clamp), 0.0);
        assert_eq!(diverging(0.0), Color32::WHITE);
        assert_eq!(diverging(1.0), Color32::from_rgb(255, 0, 0));
    }
}
