//! How the viewer is started: the launch options from the command line (or
//! a test), the settings they give, and where scene files are found.

use super::settings::{Config, Settings, Tab, ViewMode, load_settings, settings_file};
use crate::integrator::{IntegratorKind, IntegratorOptions};
use crate::lab::Experiment;
use std::path::{Path, PathBuf};

/// How the viewer was started (command line or tests).
#[derive(Clone, Debug, Default)]
pub struct Launch {
    /// Scene to open (otherwise the last one, or the Cornell box).
    pub scene: Option<PathBuf>,
    pub integrator: Option<IntegratorKind>,
    pub target_spp: Option<u32>,
    /// Save the window here once every view has `after_spp` samples, then quit.
    pub screenshot: Option<PathBuf>,
    pub after_spp: u32,
    /// Open a side-by-side comparison (A as given, B with the Sobol sampler).
    pub compare: bool,
    /// Open a comparison at equal time with B rendered by this technique.
    pub compare_with: Option<IntegratorKind>,
    /// Start with adaptive sampling by noise on.
    pub distribute: bool,
    /// Start in this view mode.
    pub show: Option<ViewMode>,
    /// Render threads (0 = one per core).
    pub threads: usize,
    /// Start from default settings instead of the saved ones.
    pub fresh: bool,
    pub export_dir: Option<PathBuf>,
    /// Open BDPT's strategy images window.
    pub strategy_grid: bool,
    /// Open the Monte Carlo lab on this experiment.
    pub lab: Option<Experiment>,
    /// The technique's settings from the command line (with
    /// `--integrator`): view A starts with them.
    pub technique: Option<IntegratorOptions>,
    /// The command line set the depth: a scene file's does not replace it.
    pub depth_given: bool,
    /// Mitsuba XML: values for the file's `$name`s (`-D name=value`).
    pub defines: Vec<(String, String)>,
    /// Warnings about a scene file are errors.
    pub strict: bool,
}

impl Launch {
    /// The settings the viewer starts with: the saved ones (unless `fresh`)
    /// or the defaults, with the launch options applied.
    pub(super) fn settings(&self) -> Settings {
        let mut settings = match settings_file() {
            Some(path) if !self.fresh => load_settings(&path),
            _ => Settings::default(),
        };
        if let Some(scene) = &self.scene {
            settings.scene_path = scene.to_string_lossy().into_owned();
        }
        if let Some(options) = self.technique {
            settings.a.integrator = options;
        }
        if let Some(kind) = self.integrator {
            settings.a.integrator.kind = kind;
        }
        if let Some(spp) = self.target_spp {
            settings.target_spp = spp.max(1);
            settings.unlimited = false;
        }
        if self.distribute {
            settings.a.spread_by_noise = true;
        }
        if let Some(mode) = self.show {
            settings.display.view = mode;
        }
        if self.compare {
            settings.compare = true;
            settings.b = Config {
                sampler: crate::sampling::SamplerKind::Sobol,
                ..settings.a
            };
        }
        if let Some(kind) = self.compare_with {
            settings.compare = true;
            settings.lock = crate::live::Lock::EqualTime;
            settings.b = settings.a;
            settings.b.integrator.kind = kind;
        }
        if let Some(dir) = &self.export_dir {
            settings.export_dir = dir.to_string_lossy().into_owned();
        }
        if self.lab.is_some() {
            settings.tab = Tab::Lab;
        }
        if self.screenshot.is_some() {
            settings.target_spp = settings.target_spp.max(self.after_spp);
            settings.unlimited = false;
        }
        settings
    }
}

/// A relative scene path that does not exist here is looked up in the source
/// tree, so `cargo run` works from any directory.
pub(super) fn resolve_scene_path(path: &str) -> String {
    let p = Path::new(path);
    if p.is_relative() && !p.exists() {
        let in_tree = Path::new(env!("CARGO_MANIFEST_DIR")).join(p);
        if in_tree.exists() {
            return in_tree.to_string_lossy().into_owned();
        }
    }
    path.to_string()
}

/// The `.toml` files in `scenes/` and the imported scenes in its folders
/// (`scenes/NAME/scene.xml`), relative to the working directory, or to the
/// source tree when run from elsewhere.
pub(super) fn list_scene_files() -> Vec<String> {
    let local = Path::new("scenes");
    let dir = if local.is_dir() {
        local.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
    };
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter_map(|p| match p.extension().is_some_and(|e| e == "toml") {
            true => Some(p),
            false => Some(p.join("scene.xml")).filter(|x| x.is_file()),
        })
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    files.sort();
    files
}

impl super::app::ViewerApp {
    /// What an imported file asks for (Mitsuba's integrator block): the
    /// technique and depths of view A (the depths of view B too, when
    /// comparing), said in a toast.
    pub(super) fn apply_hints(&mut self, hints: &crate::scene::RenderHints) {
        // A technique named on the command line wins over the file's.
        let keep_kind = self.launch.integrator.is_some();
        let mut hints = hints.clone();
        if self.launch.depth_given {
            hints.max_depth = None;
        }
        let said = match self.settings.a.integrator.take_hints(&hints, keep_kind) {
            Ok(said) => said,
            Err(e) => vec![e],
        };
        // View B keeps its technique but renders the file's depths too: a
        // comparison of two depths would not be one of two techniques.
        if self.settings.compare
            && let Err(e) = self.settings.b.integrator.take_hints(&hints, true)
        {
            self.toast(format!("view B: {e}"));
        }
        if !said.is_empty() {
            self.toast(format!("from the scene file: {}", said.join(", ")));
        }
    }
}
