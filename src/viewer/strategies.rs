//! The live grid of BDPT's strategy images (Veach's (s, t) pyramid): a
//! thread renders one sample per pixel at a time into per-strategy images
//! of a small copy of the scene and publishes the pyramid after each; the
//! window shows it filling in, weighted (they sum to the image) or
//! unweighted (each strategy alone).

use crate::image::Image;
use crate::integrator::Bdpt;
use crate::integrator::strategy_images::StrategyImages;
use crate::sampling::{Sampler, SamplerKind};
use crate::scene::Scene;
use eframe::egui::{self, ColorImage, TextureHandle, TextureOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Rows of the pyramid shown: paths of 0 to 4 bounces.
const ROWS: u32 = 5;
/// Width of one strategy's tile, in pixels.
const TILE_WIDTH: u32 = 96;
/// The grid stops refining here.
const MAX_SPP: u32 = 4096;

/// What the thread publishes: both pyramids tone-mapped, and their spp.
struct Published {
    weighted: ColorImage,
    unweighted: ColorImage,
    spp: u32,
}

/// The worker and what the window shows of it.
#[derive(Default)]
pub struct StrategyGrid {
    /// The window is open.
    pub open: bool,
    /// Show the MIS-weighted images (else unweighted).
    pub weighted: bool,
    running: Option<Worker>,
    texture: Option<TextureHandle>,
    shown: Option<(u32, bool)>,
}

struct Worker {
    key: (usize, Bdpt, SamplerKind),
    cancel: Arc<AtomicBool>,
    latest: Arc<Mutex<Option<Published>>>,
    thread: Option<JoinHandle<()>>,
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl StrategyGrid {
    /// A grid showing the weighted images, its window open or not.
    pub fn new(open: bool) -> Self {
        StrategyGrid {
            open,
            weighted: true,
            ..Default::default()
        }
    }

    /// Starts (or restarts, when the scene or the settings changed) the
    /// worker while the window is open; stops it when it is closed.
    pub fn update(&mut self, scene: Option<&Arc<Scene>>, bdpt: Bdpt, sampler: SamplerKind) {
        let (Some(scene), true) = (scene, self.open) else {
            self.running = None;
            return;
        };
        let key = (Arc::as_ptr(scene) as usize, bdpt, sampler);
        if self.running.as_ref().is_some_and(|w| w.key == key) {
            return;
        }
        self.running = None;
        self.shown = None;
        let cancel = Arc::new(AtomicBool::new(false));
        let latest = Arc::new(Mutex::new(None));
        let mut small = (**scene).clone();
        let (w, h) = (small.camera.width.max(1), small.camera.height.max(1));
        small.set_resolution(TILE_WIDTH, (TILE_WIDTH * h / w).max(1));
        let thread = {
            let (cancel, latest) = (cancel.clone(), latest.clone());
            std::thread::Builder::new()
                .name("tracelab-strategies".into())
                .spawn(move || refine(&small, &bdpt, sampler, &cancel, &latest))
                .ok()
        };
        self.running = Some(Worker {
            key,
            cancel,
            latest,
            thread,
        });
    }

    /// Samples per pixel of the grid shown, if any.
    pub fn spp(&self) -> Option<u32> {
        self.shown.map(|(spp, _)| spp)
    }

    /// The window with the pyramid, when open.
    pub fn show(&mut self, ctx: &egui::Context) {
        if !self.open {
            return;
        }
        if let Some(worker) = &self.running {
            let latest = worker.latest.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(p) = latest.as_ref()
                && self.shown != Some((p.spp, self.weighted))
            {
                let image = if self.weighted {
                    p.weighted.clone()
                } else {
                    p.unweighted.clone()
                };
                self.texture =
                    Some(ctx.load_texture("bdpt-strategies", image, TextureOptions::NEAREST));
                self.shown = Some((p.spp, self.weighted));
            }
        }
        let mut open = self.open;
        // Over the image, not the controls.
        egui::Window::new("Strategy images (s, t)")
            .open(&mut open)
            .anchor(egui::Align2::RIGHT_TOP, egui::vec2(-12.0, 40.0))
            .default_width(560.0)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    ui.radio_value(&mut self.weighted, true, "MIS-weighted (they sum to the image)");
                    ui.radio_value(&mut self.weighted, false, "Unweighted");
                });
                ui.label(
                    "Row k: paths of k bounces; column s: light subpath vertices (s = 0: the camera \
                     path hits the light; s = 1: light sampling; t = 1, the rightmost: light tracing).",
                );
                match (&self.texture, self.shown) {
                    (Some(texture), Some((spp, _))) => {
                        ui.label(format!("{spp} spp at {TILE_WIDTH} pixels wide"));
                        let size = texture.size_vec2();
                        let scale = (ui.available_width() / size.x).clamp(0.5, 4.0);
                        ui.image((texture.id(), size * scale));
                    }
                    _ => {
                        ui.label("rendering...");
                    }
                }
            });
        self.open = open;
    }
}

/// The worker's loop: one spp more per round until cancelled.
fn refine(
    scene: &Scene,
    bdpt: &Bdpt,
    sampler: SamplerKind,
    cancel: &AtomicBool,
    latest: &Mutex<Option<Published>>,
) {
    let mut mean: Option<StrategyImages> = None;
    for round in 0..MAX_SPP {
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        // Each round is one sample per pixel of an independent seed.
        let sampler = Sampler::new(sampler, u64::from(round) + 1, 1);
        let (batch, _) = StrategyImages::render(scene, bdpt, &sampler, 1);
        match &mut mean {
            Some(m) => m.accumulate(&batch, round),
            None => mean = Some(batch),
        }
        let Some(m) = &mean else { continue };
        // Every round at first, then at powers of two and every 16th: the
        // tone mapping costs more than a round of a small image.
        if round < 16 || round % 16 == 0 {
            let weighted = m.sheet(true, ROWS);
            let exposure = exposure_for(&weighted, ROWS + 1);
            *latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(Published {
                weighted: to_color_image(&weighted, exposure),
                unweighted: to_color_image(&m.sheet(false, ROWS), exposure),
                spp: round + 1,
            });
        }
    }
}

/// One exposure for every tile: the image (the sum of the weighted tiles,
/// `columns` per row) at mid-grey.
fn exposure_for(sheet: &Image, columns: u32) -> f32 {
    let mean = sheet.mean();
    let luminance = (0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2]) * f64::from(columns);
    if luminance > 0.0 {
        (0.18 / luminance).log2() as f32
    } else {
        0.0
    }
}

fn to_color_image(image: &Image, exposure: f32) -> ColorImage {
    let rgb = image.to_srgb8(exposure);
    ColorImage::from_rgb([image.width as usize, image.height as usize], rgb.as_raw())
}
