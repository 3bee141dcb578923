//! Everything the user sets in the window, as plain data that eframe
//! persists between runs. Render settings (which restart accumulation) and
//! display settings (which never do) are kept apart.

use crate::filter::FilterSampling;
use crate::integrator::{IntegratorKind, IntegratorOptions, TechniqueKind};
use crate::live::Lock;
use crate::math::OffsetMode;
use crate::sampling::{Domains, SamplerKind};
use serde::{Deserialize, Serialize};

/// One configuration of the estimator (A, or B when comparing).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Config {
    pub integrator: IntegratorOptions,
    pub sampler: SamplerKind,
    /// Domains the sampler applies to (the rest are independent).
    pub domains: Domains,
    pub seed: u64,
    /// Adaptive sampling: after a few samples everywhere, each pass spends
    /// its samples where the noise is ([`crate::render::Adaptive::Distribute`]).
    pub spread_by_noise: bool,
    /// How camera samples meet a tent or Gaussian pixel filter.
    pub filter_sampling: FilterSampling,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            integrator: IntegratorOptions::default(),
            sampler: SamplerKind::Independent,
            domains: Domains::ALL,
            seed: 0,
            spread_by_noise: false,
            filter_sampling: FilterSampling::default(),
        }
    }
}

impl Config {
    /// True when the technique takes samples per pixel that can be spread
    /// by noise: a camera estimator with sampling noise.
    pub fn can_spread_by_noise(&self) -> bool {
        self.integrator.kind.technique() == TechniqueKind::Camera
            && !self.integrator.build().is_deterministic()
    }

    /// True when samples are spread by noise.
    pub fn spreads_by_noise(&self) -> bool {
        self.spread_by_noise && self.can_spread_by_noise()
    }

    /// A short name for labels, legends and file names.
    pub fn label(&self) -> String {
        let i = &self.integrator;
        let estimator = match i.kind {
            IntegratorKind::Whitted => format!("whitted d{}", i.whitted.max_depth),
            IntegratorKind::Mcrt => format!(
                "mcrt d{} n{} m{}",
                i.mcrt.max_depth, i.mcrt.shadow_rays, i.mcrt.glossy_rays
            ),
            IntegratorKind::Path => format!(
                "path d{} {:?}",
                depth(i.path.length.max_depth),
                i.path.strategy
            )
            .to_lowercase(),
            IntegratorKind::Light => format!("light d{}", depth(i.light.length.max_depth)),
            IntegratorKind::Radiosity => format!(
                "radiosity {} {}",
                i.radiosity.solver.name(),
                i.radiosity.display.name()
            ),
            // Techniques without a label of their own.
            #[allow(unreachable_patterns)]
            other => other.name().to_string(),
        };
        let d = self.domains;
        let partial = if self.sampler != SamplerKind::Independent && d != Domains::ALL {
            let names: Vec<&str> = [
                (d.pixel, "pixel"),
                (d.lens, "lens"),
                (d.time, "time"),
                (d.light, "light"),
                (d.bsdf, "bsdf"),
            ]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, n)| *n)
            .collect();
            format!(" [{}]", names.join("+"))
        } else {
            String::new()
        };
        let adaptive = if self.spreads_by_noise() {
            " adaptive"
        } else {
            ""
        };
        let filter = match self.filter_sampling {
            FilterSampling::Splat => "",
            FilterSampling::Importance => " filter-is",
        };
        let sampler = self.fixed_sampler().unwrap_or(self.sampler);
        format!("{estimator} {}{partial}{adaptive}{filter}", sampler.name())
    }

    /// The sampler the technique uses whatever the session's is: radiosity's
    /// lookup displays antialias with Sobol points (`display_sampler`).
    pub fn fixed_sampler(&self) -> Option<SamplerKind> {
        let i = &self.integrator;
        let lookup = i.kind == IntegratorKind::Radiosity
            && i.radiosity.display != crate::integrator::radiosity::RadiosityDisplay::Gather;
        lookup.then_some(SamplerKind::Sobol)
    }
}

/// Side-by-side layouts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CompareLayout {
    /// One image, A left of a draggable divider and B right of it.
    #[default]
    Split,
    /// Two images next to each other.
    TwoPanes,
}

/// What the image area shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ViewMode {
    #[default]
    Image,
    /// A - B (or the image minus the reference when not comparing).
    Difference,
    /// Per-pixel relative standard error in false colour.
    StandardError,
    /// The image with non-finite samples and fireflies marked.
    Fireflies,
    /// Samples per pixel in false colour (log scale): where adaptive
    /// sampling spends its samples.
    Samples,
}

impl ViewMode {
    pub const ALL: [ViewMode; 5] = [
        ViewMode::Image,
        ViewMode::Difference,
        ViewMode::StandardError,
        ViewMode::Fireflies,
        ViewMode::Samples,
    ];

    pub fn label(self) -> &'static str {
        match self {
            ViewMode::Image => "Image",
            ViewMode::Difference => "Difference",
            ViewMode::StandardError => "Std. error",
            ViewMode::Fireflies => "Fireflies",
            ViewMode::Samples => "Samples",
        }
    }
}

/// Display mapping from radiance to screen colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ToneMap {
    /// Clip at 1, as the reference renders are shown.
    #[default]
    Clamp,
    /// x / (1 + x).
    Reinhard,
    /// The ACES filmic curve fit of Narkowicz (2015).
    Aces,
}

impl ToneMap {
    pub const ALL: [ToneMap; 3] = [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::Aces];
}

/// Settings that change only how the film is shown.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Display {
    /// Stops: radiance is multiplied by 2^exposure.
    pub exposure: f32,
    pub tone_map: ToneMap,
    pub view: ViewMode,
    pub layout: CompareLayout,
    /// Divider position of the split view, as a fraction of the image width.
    pub split: f32,
    /// Relative standard error above which a pixel counts as a firefly.
    pub firefly_threshold: f32,
    /// Plot error against render time instead of samples per pixel.
    pub plot_time: bool,
}

impl Default for Display {
    fn default() -> Self {
        Display {
            exposure: 0.0,
            tone_map: ToneMap::Clamp,
            view: ViewMode::Image,
            layout: CompareLayout::Split,
            split: 0.5,
            firefly_threshold: 0.5,
            plot_time: false,
        }
    }
}

/// All persisted settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    pub scene_path: String,
    pub a: Config,
    pub b: Config,
    pub compare: bool,
    pub lock: Lock,
    /// Stop at this many samples per pixel, unless `unlimited`.
    pub target_spp: u32,
    pub unlimited: bool,
    /// Image size; `None` keeps the scene's.
    pub resolution: Option<(u32, u32)>,
    /// How rays leave surfaces (a fixed epsilon shows its artifacts).
    pub offset: OffsetMode,
    pub reference_path: String,
    pub export_dir: String,
    pub display: Display,
    pub show_help: bool,
    /// The renderer or the Monte Carlo lab.
    pub tab: Tab,
}

/// What the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Tab {
    #[default]
    Renderer,
    /// The Monte Carlo lab; the renderer pauses while it is shown.
    Lab,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            scene_path: "scenes/cornell_box.toml".into(),
            a: Config::default(),
            b: Config {
                sampler: SamplerKind::Sobol,
                ..Config::default()
            },
            compare: false,
            lock: Lock::EqualSpp,
            target_spp: 1024,
            unlimited: false,
            resolution: None,
            offset: OffsetMode::Robust,
            reference_path: String::new(),
            export_dir: "exports".into(),
            display: Display::default(),
            show_help: false,
            tab: Tab::Renderer,
        }
    }
}

impl Settings {
    /// The part of the settings that, when it changes, restarts rendering.
    pub fn render_key(
        &self,
    ) -> (
        Config,
        Option<Config>,
        Lock,
        Option<u32>,
        Option<(u32, u32)>,
        OffsetMode,
    ) {
        (
            self.a,
            self.compare.then_some(self.b),
            self.lock,
            (!self.unlimited).then_some(self.target_spp),
            self.resolution,
            self.offset,
        )
    }
}

/// Where the viewer keeps its settings: `settings.toml` in eframe's storage
/// folder for tracelab (e.g. `~/.local/share/tracelab/`).
pub fn settings_file() -> Option<std::path::PathBuf> {
    eframe::storage_dir("tracelab").map(|d| d.join("settings.toml"))
}

/// Reads saved settings; a missing or unreadable file gives the defaults
/// (a settings file from another version must not stop the viewer).
pub fn load_settings(path: &std::path::Path) -> Settings {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| toml::from_str(&text).ok())
        .unwrap_or_default()
}

/// Writes the settings through a temporary file and a rename, so that an
/// interrupted save never leaves a half-written file in place of a good one
/// (eframe's own storage writes in place).
pub fn save_settings(path: &std::path::Path, settings: &Settings) -> crate::Result<()> {
    let text = toml::to_string(settings)
        .map_err(|e| crate::Error::at(path, None, format!("cannot encode settings: {e}")))?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| crate::Error::at(dir, None, format!("cannot create folder: {e}")))?;
    }
    crate::image::write_atomically(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })
}

/// A depth in a label: Mitsuba's unbounded one as `inf`, fit for file names.
fn depth(max_depth: u32) -> String {
    if max_depth == crate::scene::UNBOUNDED_DEPTH {
        "inf".into()
    } else {
        max_depth.to_string()
    }
}

#[cfg(test)]
mod persistence_tests {
    use super::*;

    #[test]
    fn settings_survive_a_save_and_load() {
        let dir = std::env::temp_dir().join(format!("tracelab-settings-{}", std::process::id()));
        let path = dir.join("settings.toml");
        let mut settings = Settings::default();
        settings.target_spp = 77;
        settings.compare = true;
        settings.resolution = Some((320, 200));
        settings.offset = OffsetMode::Fixed(1e-3);
        settings.a.sampler = SamplerKind::Sobol;
        save_settings(&path, &settings).unwrap();
        assert_eq!(load_settings(&path), settings);
        // No temporary file is left behind.
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("settings.toml")]);
        // A damaged file gives the defaults, not an error.
        std::fs::write(&path, "target_spp = [").unwrap();
        assert_eq!(load_settings(&path), Settings::default());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
