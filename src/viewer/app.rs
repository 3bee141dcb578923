//! The viewer's state and logic: which scene, which settings, what is shown,
//! and the actions (restart, export, screenshots). The panels in `panel.rs`,
//! `image_view.rs` and `stats.rs` only read this state and change settings;
//! [`ViewerApp::sync`] notices changes once per frame and restarts the
//! renderer when a render setting changed.

mod reference;

use super::display::render_view;
use super::export::{export_path, write_color_image, write_exr};
use super::lab::LabState;
use super::launch::{Launch, list_scene_files, resolve_scene_path};
use super::plot_scale::percentile;
use super::settings::{Config, Display, Settings, Tab};
use super::view_transform::ViewTransform;
use crate::camera::Camera;
use crate::image::Image;
use crate::live::{ErrorPoint, LiveConfig, LiveFrame, LiveRender};
use crate::render::{Adaptive, RenderSettings};
use crate::scene::{Limits, Scene};
use eframe::egui::{self, ColorImage, TextureHandle, TextureOptions};
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Uniform samples per pixel before "spread samples by noise" takes over.
const SPREAD_WARMUP_SPP: u32 = 4;

/// A convergence curve of a configuration that is no longer rendering.
#[derive(Clone, Debug)]
pub struct Curve {
    pub label: String,
    pub points: Vec<ErrorPoint>,
}

/// A message that fades after a few seconds.
#[derive(Clone, Debug)]
pub struct Toast {
    pub text: String,
    pub shown_at: Instant,
}

/// What a pending screen capture is for.
#[derive(Clone, Debug, PartialEq)]
pub enum Capture {
    /// The whole window, to this file (from the Export menu or --screenshot).
    Window { path: PathBuf, quit_after: bool },
    /// The comparison sheet layout.
    Sheet { path: PathBuf },
}

/// Everything whose change restarts rendering: the render settings, the
/// camera, the scene (by identity) and a counter of forced restarts.
type RenderKey = (
    (
        Config,
        Option<Config>,
        crate::live::Lock,
        Option<u32>,
        Option<(u32, u32)>,
        crate::math::OffsetMode,
    ),
    // The renderer pauses while the lab tab is shown.
    bool,
    Option<CameraKey>,
    usize,
    u64,
);

type CameraKey = [u32; 6];

fn camera_key(c: &Camera) -> CameraKey {
    [
        c.eye.x.to_bits(),
        c.eye.y.to_bits(),
        c.eye.z.to_bits(),
        c.forward.x.to_bits(),
        c.forward.y.to_bits(),
        c.forward.z.to_bits(),
    ]
}

/// Frame times kept for the p95 figure.
const FRAME_TIME_WINDOW: usize = 600;

pub struct ViewerApp {
    pub settings: Settings,
    live: LiveRender,
    /// The last scene that loaded; kept when a new one fails.
    scene: Option<Arc<Scene>>,
    scene_name: String,
    /// Pixels at the camera's median first hit per unit of a merge radius
    /// given as a fraction of the diagonal, and the frame's width, for the
    /// radius controls of VCM and SPPM.
    pub merge_scale: Option<(f32, u32)>,
    /// Camera moved with the mouse; `None` uses the scene's.
    pub camera: Option<Camera>,
    reference: Option<Arc<Image>>,
    /// Where the reference came from when it was found beside the scene
    /// (the next scene replaces it; a reference chosen by hand stays).
    reference_beside: Option<std::path::PathBuf>,
    pub errors: Vec<String>,
    pub toasts: Vec<Toast>,
    textures: Vec<TextureHandle>,
    shown: Option<(Arc<LiveFrame>, Display)>,
    last_key: Option<RenderKey>,
    restarts: u64,
    /// The configurations of the views now rendering.
    rendered_configs: Vec<Config>,
    pub view: ViewTransform,
    pub curves: Vec<Curve>,
    frame_times: VecDeque<f32>,
    latencies: VecDeque<Duration>,
    counted_latency_generation: u64,
    pub exports: Vec<PathBuf>,
    pub scene_files: Vec<String>,
    pub(super) launch: Launch,
    pub capture: Option<Capture>,
    captured: Arc<Mutex<Option<Arc<ColorImage>>>>,
    capture_requested: bool,
    /// Draw the comparison sheet instead of the normal layout.
    pub sheet_mode: bool,
    /// The path typed into the scene field.
    pub scene_field: String,
    /// The Monte Carlo lab tab.
    pub lab: LabState,
    /// BDPT's live strategy images.
    pub strategy_grid: super::strategies::StrategyGrid,
}

impl ViewerApp {
    /// Builds the app: restores saved settings (unless `launch.fresh`), applies
    /// the launch options, loads the scene and starts rendering.
    pub fn new(launch: Launch) -> Self {
        let strategy_grid = launch.strategy_grid;
        let settings = launch.settings();
        let lab = LabState::new(launch.lab.unwrap_or_default());
        let mut errors = Vec::new();
        let live = match LiveRender::start(launch.threads) {
            Ok(live) => live,
            Err(e) => {
                errors.push(e.to_string());
                LiveRender::start(1).expect("a single render thread starts")
            }
        };
        let capture = launch.screenshot.clone().map(|path| Capture::Window {
            path,
            quit_after: true,
        });
        let mut app = ViewerApp {
            scene_field: settings.scene_path.clone(),
            settings,
            live,
            scene: None,
            scene_name: String::new(),
            merge_scale: None,
            camera: None,
            reference: None,
            reference_beside: None,
            errors,
            toasts: Vec::new(),
            textures: Vec::new(),
            shown: None,
            last_key: None,
            restarts: 0,
            rendered_configs: Vec::new(),
            view: ViewTransform::default(),
            curves: Vec::new(),
            frame_times: VecDeque::new(),
            latencies: VecDeque::new(),
            counted_latency_generation: 0,
            exports: Vec::new(),
            scene_files: list_scene_files(),
            launch,
            capture,
            captured: Arc::new(Mutex::new(None)),
            capture_requested: false,
            sheet_mode: false,
            lab,
            strategy_grid: super::strategies::StrategyGrid::new(strategy_grid),
        };
        let scene_path = resolve_scene_path(&app.settings.scene_path);
        app.load_scene(&scene_path);
        if !app.settings.reference_path.is_empty() {
            app.load_reference(&app.settings.reference_path.clone());
        }
        app
    }

    /// Loads a scene file; on failure shows the error and keeps the last good scene.
    pub fn load_scene(&mut self, path: &str) {
        let options = crate::scene::LoadOptions {
            limits: Limits::default(),
            defines: self.launch.defines.clone(),
            strict: self.launch.strict,
        };
        match Scene::load_with(Path::new(path), &options) {
            Ok(scene) => {
                for w in &scene.warnings {
                    self.toast(format!("{path}: {w}"));
                }
                self.apply_hints(&scene.hints);
                self.merge_scale =
                    crate::integrator::photon_map::pixel_footprint(&scene).map(|w| {
                        (
                            crate::integrator::photon_map::of_diagonal(&scene, 1.0) / w,
                            scene.camera.width,
                        )
                    });
                self.scene = Some(Arc::new(scene));
                self.camera = None;
                self.settings.scene_path = path.to_string();
                self.scene_field = path.to_string();
                // An imported scene is named after its folder (veach-mis/scene.xml).
                let p = Path::new(path);
                let named = match p.file_stem().is_some_and(|s| s == "scene") {
                    true => p.parent().and_then(Path::file_name),
                    false => p.file_stem(),
                };
                self.scene_name = named
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "scene".into());
                self.view = ViewTransform::default();
                self.pick_reference_beside(p);
            }
            Err(e) => self.errors.push(e.to_string()),
        }
    }

    pub fn scene(&self) -> Option<&Arc<Scene>> {
        self.scene.as_ref()
    }

    pub fn scene_name(&self) -> &str {
        &self.scene_name
    }

    /// The camera in use: the orbited one or the scene's.
    pub fn current_camera(&self) -> Option<Camera> {
        self.camera
            .or_else(|| self.scene.as_ref().map(|s| s.camera))
    }

    /// Restarts accumulation with unchanged settings.
    pub fn force_restart(&mut self) {
        self.restarts += 1;
    }

    pub fn toast(&mut self, text: String) {
        self.toasts.push(Toast {
            text,
            shown_at: Instant::now(),
        });
    }

    /// The newest frame from the renderer.
    pub fn frame(&self) -> Arc<LiveFrame> {
        self.live.latest()
    }

    pub fn live(&self) -> &LiveRender {
        &self.live
    }

    /// The configurations being rendered, in view order.
    pub fn configs(&self) -> Vec<Config> {
        let mut v = vec![self.settings.a];
        if self.settings.compare {
            v.push(self.settings.b);
        }
        v
    }

    /// Restarts the renderer when a render setting, the camera or the scene changed.
    pub fn sync(&mut self) {
        let Some(scene) = self.scene.clone() else {
            return;
        };
        let key: RenderKey = (
            self.settings.render_key(),
            self.settings.tab == Tab::Lab,
            self.camera.as_ref().map(camera_key),
            Arc::as_ptr(&scene) as usize,
            self.restarts,
        );
        if self.last_key.as_ref() == Some(&key) {
            return;
        }
        self.last_key = Some(key);

        // Finished curves stay on the plot, labelled by their settings.
        let frame = self.live.latest();
        for (view, config) in frame.views.iter().zip(self.rendered_configs.iter()) {
            if view.history.len() >= 2 {
                self.curves.push(Curve {
                    label: config.label(),
                    points: view.history.clone(),
                });
            }
        }
        let excess = self.curves.len().saturating_sub(8);
        self.curves.drain(..excess);
        if self.settings.tab == Tab::Lab {
            // Both cores go to the lab; coming back restarts the render.
            self.rendered_configs.clear();
            self.live
                .restart(Vec::new(), self.settings.lock, self.reference.clone());
            return;
        }

        let mut scene = (*scene).clone();
        if let Some(camera) = self.camera {
            scene.set_camera(camera);
        }
        if let Some((w, h)) = self.settings.resolution {
            scene.set_resolution(w, h);
        }
        scene.set_offset(self.settings.offset);
        let scene = Arc::new(scene);
        let configs = self.configs();
        let target = (!self.settings.unlimited).then_some(self.settings.target_spp.max(1));
        let live_configs = configs
            .iter()
            .map(|c| {
                let integrator = c.integrator.build();
                LiveConfig {
                    scene: scene.clone(),
                    settings: RenderSettings {
                        integrator,
                        sampler: c.sampler,
                        seed: c.seed,
                        planned_spp: target.unwrap_or(0),
                        threads: 0,
                        adaptive: c.spreads_by_noise().then_some(Adaptive::Distribute {
                            warmup_spp: SPREAD_WARMUP_SPP,
                        }),
                        domains: c.domains,
                        clamp: None,
                        filter_sampling: c.filter_sampling,
                    },
                    target_spp: if integrator.is_deterministic() {
                        Some(1)
                    } else {
                        target
                    },
                }
            })
            .collect();
        self.rendered_configs = configs;
        self.live
            .restart(live_configs, self.settings.lock, self.reference.clone());
    }

    /// Uploads new frames (or the same frame under new display settings) to textures.
    pub fn update_textures(&mut self, ctx: &egui::Context) {
        let frame = self.live.latest();
        if frame.views.is_empty() {
            return;
        }
        if frame.generation == self.live.generation()
            && self.counted_latency_generation != frame.generation
        {
            if let Some(latency) = frame.first_image_latency {
                self.latencies.push_back(latency);
                if self.latencies.len() > 200 {
                    self.latencies.pop_front();
                }
            }
            self.counted_latency_generation = frame.generation;
        }
        let display = self.settings.display;
        if let Some((shown, shown_display)) = &self.shown
            && Arc::ptr_eq(shown, &frame)
            && *shown_display == display
        {
            return;
        }
        let images: Vec<ColorImage> = frame
            .views
            .iter()
            .enumerate()
            .map(|(i, view)| {
                // Differences: A against B, B against A, or against the reference.
                let other = if frame.views.len() == 2 {
                    Some(&frame.views[1 - i].snapshot.image)
                } else {
                    self.reference.as_deref()
                };
                render_view(&view.snapshot, other, &display)
            })
            .collect();
        self.textures.truncate(images.len());
        for (i, image) in images.into_iter().enumerate() {
            if let Some(texture) = self.textures.get_mut(i) {
                texture.set(image, TextureOptions::NEAREST);
            } else {
                self.textures.push(ctx.load_texture(
                    format!("view-{i}"),
                    image,
                    TextureOptions::NEAREST,
                ));
            }
        }
        self.shown = Some((frame, display));
    }

    pub fn textures(&self) -> &[TextureHandle] {
        &self.textures
    }

    /// Records how long the UI took to build a frame.
    pub fn record_frame_time(&mut self, seconds: f32) {
        self.frame_times.push_back(seconds);
        if self.frame_times.len() > FRAME_TIME_WINDOW {
            self.frame_times.pop_front();
        }
    }

    /// 95th percentile of recent UI frame times, in seconds.
    pub fn frame_time_p95(&self) -> Option<f32> {
        percentile(self.frame_times.iter().copied(), 0.95)
    }

    /// Median time from a setting change to the first image of the new settings.
    pub fn restart_latency_median(&self) -> Option<f32> {
        percentile(self.latencies.iter().map(Duration::as_secs_f32), 0.5)
    }

    /// Exports view `index` as a tone-mapped PNG with its settings in text chunks.
    pub fn export_png(&mut self, index: usize) -> Option<PathBuf> {
        let frame = self.live.latest();
        let view = frame.views.get(index)?;
        let config = *self.rendered_configs.get(index)?;
        let display = Display {
            view: super::settings::ViewMode::Image,
            ..self.settings.display
        };
        let image = render_view(&view.snapshot, None, &display);
        let path = export_path(
            Path::new(&self.settings.export_dir),
            &self.scene_name,
            &config.label(),
            view.stats.spp,
            "png",
        );
        let text = self.png_text(&config, view.stats.spp);
        self.report(write_color_image(&path, &image, &text))
    }

    /// Exports view `index`'s linear radiance as EXR.
    pub fn export_exr(&mut self, index: usize) -> Option<PathBuf> {
        let frame = self.live.latest();
        let view = frame.views.get(index)?;
        let config = *self.rendered_configs.get(index)?;
        let path = export_path(
            Path::new(&self.settings.export_dir),
            &self.scene_name,
            &config.label(),
            view.stats.spp,
            "exr",
        );
        self.report(write_exr(&path, &view.snapshot))
    }

    /// Asks for a capture of the whole window (written when it arrives).
    pub fn export_window(&mut self) {
        let spp = self.live.latest().views.first().map_or(0, |v| v.stats.spp);
        let path = export_path(
            Path::new(&self.settings.export_dir),
            &self.scene_name,
            &format!("window {}", self.settings.a.label()),
            spp,
            "png",
        );
        self.capture = Some(Capture::Window {
            path,
            quit_after: false,
        });
    }

    /// Asks for a capture of the comparison sheet (A, B, difference, plot, settings).
    pub fn export_sheet(&mut self) {
        let spp = self.live.latest().views.first().map_or(0, |v| v.stats.spp);
        let path = export_path(
            Path::new(&self.settings.export_dir),
            &self.scene_name,
            &format!(
                "sheet {} vs {}",
                self.settings.a.label(),
                self.settings.b.label()
            ),
            spp,
            "png",
        );
        self.capture = Some(Capture::Sheet { path });
    }

    fn png_text(&self, config: &Config, spp: u32) -> Vec<(&'static str, String)> {
        vec![
            (
                "Software",
                format!("tracelab {}", env!("CARGO_PKG_VERSION")),
            ),
            ("tracelab:scene", self.settings.scene_path.clone()),
            ("tracelab:spp", spp.to_string()),
            ("tracelab:integrator", config.integrator.build().describe()),
            ("tracelab:sampler", config.sampler.name().to_string()),
            ("tracelab:seed", config.seed.to_string()),
            (
                "tracelab:display",
                format!(
                    "exposure {} tone map {:?}",
                    self.settings.display.exposure, self.settings.display.tone_map
                ),
            ),
        ]
    }

    fn report(&mut self, result: crate::Result<PathBuf>) -> Option<PathBuf> {
        match result {
            Ok(path) => {
                self.toast(format!("saved {}", path.display()));
                self.exports.push(path.clone());
                Some(path)
            }
            Err(e) => {
                self.errors.push(e.to_string());
                None
            }
        }
    }

    /// Drives captures: requests one when due, writes it when it arrives.
    pub fn handle_capture(&mut self, ctx: &egui::Context) {
        let Some(capture) = self.capture.clone() else {
            return;
        };
        self.sheet_mode = matches!(capture, Capture::Sheet { .. });
        let arrived = self
            .captured
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        if let Some(image) = arrived {
            let (path, quit) = match capture {
                Capture::Window { path, quit_after } => (path, quit_after),
                Capture::Sheet { path } => (path, false),
            };
            let config = self.settings.a;
            let spp = self.live.latest().views.first().map_or(0, |v| v.stats.spp);
            let text = self.png_text(&config, spp);
            let written = self.report(write_color_image(&path, &image, &text));
            self.capture = None;
            self.capture_requested = false;
            self.sheet_mode = false;
            if quit {
                if written.is_none() {
                    for e in &self.errors {
                        eprintln!("error: {e}");
                    }
                }
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            return;
        }
        if self.capture_requested {
            ctx.request_repaint();
            return;
        }
        // The automated screenshot waits for its sample count (or the lab
        // for its run to finish and show); exports go now.
        let ready = match &capture {
            Capture::Window {
                quit_after: true, ..
            } if self.settings.tab == Tab::Lab => self.lab.frames_since_finished >= 3,
            Capture::Window {
                quit_after: true, ..
            } => {
                let frame = self.live.latest();
                frame.generation == self.live.generation()
                    && !frame.views.is_empty()
                    && frame
                        .views
                        .iter()
                        .all(|v| v.done || v.stats.spp >= self.launch.after_spp)
                    && (!self.strategy_grid.open
                        || self
                            .strategy_grid
                            .spp()
                            .is_some_and(|spp| spp >= self.launch.after_spp))
                    && self
                        .shown
                        .as_ref()
                        .is_some_and(|(shown, _)| Arc::ptr_eq(shown, &frame))
            }
            _ => true,
        };
        if ready {
            let slot = self.captured.clone();
            ctx.request_screenshot(move |image| {
                *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(image);
            });
            self.capture_requested = true;
            ctx.request_repaint();
        }
    }

    /// Moves the camera: orbit about the point in focus by `yaw`/`pitch`
    /// radians and dolly towards it by the factor `dolly` (1 = no change).
    pub fn orbit(&mut self, yaw: f32, pitch: f32, dolly: f32) {
        let Some(camera) = self.current_camera() else {
            return;
        };
        let pivot = camera.eye + camera.forward * camera.focus_distance;
        let offset = camera.eye - pivot;
        let up = glam::Vec3A::Y;
        let rotation = glam::Quat::from_axis_angle(up.into(), -yaw)
            * glam::Quat::from_axis_angle(camera.right.into(), -pitch);
        let mut new_offset = glam::Vec3A::from(rotation * glam::Vec3::from(offset)) * dolly;
        // Stay off the poles, where the up vector would flip.
        let dir = new_offset.normalize();
        if dir.dot(up).abs() > 0.98 {
            new_offset = offset * dolly;
        }
        let distance = new_offset.length();
        let fov = 2.0 * camera.tan_half_fov_y.atan().to_degrees();
        self.camera = Some(
            Camera::look_at(
                pivot + new_offset,
                pivot,
                up,
                fov,
                camera.width,
                camera.height,
                camera.aperture_radius,
                distance,
            )
            .with_shutter(camera.shutter_open, camera.shutter_close),
        );
    }

    /// Back to the scene's own camera.
    pub fn reset_camera(&mut self) {
        self.camera = None;
    }

    /// The label of the configuration shown in view `index`.
    pub fn view_label(&self, index: usize) -> String {
        self.rendered_configs
            .get(index)
            .map(Config::label)
            .unwrap_or_default()
    }
}

impl ViewerApp {
    pub fn shutdown(&mut self) {
        self.live.stop();
    }
}
