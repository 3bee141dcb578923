//! The technique's flags, shared by `render` and flattened into it: each
//! flag given sets the setting of that name in the chosen technique's own
//! settings struct (`tracelab::integrator::*Settings`), where the defaults
//! and the checks live; a flag the chosen technique does not have is an
//! error, not silently ignored.

use super::choices::*;
use super::radiosity::RadiosityFlags;
use super::{IntegratorArg, integrator_kind};
use clap::Args;
use tracelab::integrator::{
    GlassShadows, IntegratorKind, IntegratorOptions, MisHeuristic, Strategy,
};
use tracelab::scene::RenderHints;
use tracelab::{Error, Result};

#[derive(Args, Debug)]
pub struct TechniqueFlags {
    /// Technique (default: the scene file's integrator, else path).
    #[arg(long, value_enum)]
    pub(crate) integrator: Option<IntegratorArg>,
    /// Maximum bounces (1 = direct lighting); Mitsuba's max_depth is one
    /// more (default: the scene file's, else 8).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Russian roulette starts after this many bounces (default: the scene
    /// file's, else 5).
    #[arg(long)]
    rr_depth: Option<u32>,
    /// Turn Russian roulette off.
    #[arg(long)]
    no_rr: bool,
    /// Turn next-event estimation (light sampling) off: the same as --strategy bsdf.
    #[arg(long, conflicts_with = "strategy")]
    no_nee: bool,
    /// Path tracing: sample the BSDF, the lights, or both with MIS.
    #[arg(long, value_enum)]
    strategy: Option<StrategyArg>,
    /// How light and BSDF samples are combined (none = light sampling
    /// only) [default: power].
    #[arg(long, value_enum)]
    mis: Option<MisArg>,
    /// MC ray tracing: light samples (shadow rays) per hit [default: 1].
    #[arg(long)]
    shadow_rays: Option<u32>,
    /// MC ray tracing: BSDF samples (branching rays) per hit [default: 1].
    #[arg(long)]
    glossy_rays: Option<u32>,
    /// Ambient occlusion: occluders count within this fraction of the
    /// scene's bounding-box diagonal (0: no limit) [default: 0.1].
    #[arg(long)]
    ao_distance: Option<f32>,
    /// BDPT: light subpaths per camera sample, the ones after the first
    /// joined to the lens only (light tracing) [default: 1].
    #[arg(long)]
    light_paths: Option<u32>,
    /// BDPT: bounces of the light subpaths after the first [default: 2].
    #[arg(long)]
    light_path_bounces: Option<u32>,
    /// Photon mapping: photons per iteration (0: one per pixel) [default: 0].
    #[arg(long)]
    photons: Option<u32>,
    /// Progressive photon mapping and VCM: gather (merge) radius of the
    /// first iteration, as a fraction of the scene's bounding-box diagonal
    /// [default: 0.002].
    #[arg(long)]
    radius: Option<f32>,
    /// Progressive photon mapping and VCM: the radius shrinks as
    /// r_i^2 = r_1^2 i^(alpha - 1) (0 < alpha <= 1; 1 keeps it fixed, a
    /// biased estimate) [default: 2/3].
    #[arg(long)]
    alpha: Option<f32>,
    /// Photon mapping (Jensen): photons per density estimate (1 to 256)
    /// [default: 50].
    #[arg(long)]
    k: Option<u32>,
    /// Photon mapping (Jensen): the largest gather radius, as a fraction of
    /// the scene's bounding-box diagonal [default: 0.05].
    #[arg(long)]
    gather_radius: Option<f32>,
    #[command(flatten)]
    pub(crate) radiosity: RadiosityFlags,
    /// Path tracing and Whitted: run the general code, not the code
    /// specialised for the scene's features (to measure what that saves).
    #[arg(long)]
    general: bool,
    /// Path and MC ray tracing: emitters seen directly through a pixel are
    /// integrated exactly over it where nothing can hide them (`exact`), or
    /// sampled by the camera rays like everything else (`sampled`)
    /// [default: exact].
    #[arg(long, value_enum)]
    seen_emitters: Option<SeenEmittersArg>,
    /// Whitted: constant ambient radiance times the diffuse albedo [default: 0].
    #[arg(long)]
    ambient: Option<f32>,
    /// Whitted: shadow rays through glass are blocked, or tinted by the
    /// glass [default: opaque].
    #[arg(long, value_enum)]
    glass_shadows: Option<GlassShadowsArg>,
}

impl TechniqueFlags {
    /// True when a setting's flag was given (not counting `--integrator`).
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub fn any_given(&self) -> bool {
        self.max_depth.is_some()
            || self.rr_depth.is_some()
            || self.no_rr
            || self.no_nee
            || self.strategy.is_some()
            || self.mis.is_some()
            || self.shadow_rays.is_some()
            || self.glossy_rays.is_some()
            || self.ao_distance.is_some()
            || self.light_paths.is_some()
            || self.light_path_bounces.is_some()
            || self.photons.is_some()
            || self.radius.is_some()
            || self.alpha.is_some()
            || self.k.is_some()
            || self.gather_radius.is_some()
            || self.general
            || self.seen_emitters.is_some()
            || self.ambient.is_some()
            || self.glass_shadows.is_some()
            || self.radiosity.any_given()
    }

    /// True when `--max-depth` was given.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub fn depth_given(&self) -> bool {
        self.max_depth.is_some()
    }

    /// The technique's settings: its defaults, then what the scene file's
    /// integrator block asks for (`hints`), then the flags; checked.
    pub fn options(&self, hints: &RenderHints) -> Result<IntegratorOptions> {
        let mut options = IntegratorOptions::default();
        // A technique named here wins over the file's, and takes its depth.
        let kind = self.integrator.map(integrator_kind);
        if let Some(kind) = kind {
            options.kind = kind;
        }
        let taken = options
            .take_hints(hints, kind.is_some())
            .map_err(Error::new)?;
        if !taken.is_empty() {
            eprintln!("from the scene file: {}", taken.join(", "));
        }
        self.apply(&mut options)?;
        options.validate().map_err(Error::new)?;
        Ok(options)
    }

    /// Sets what the flags given name in the chosen technique's settings.
    fn apply(&self, options: &mut IntegratorOptions) -> Result<()> {
        let kind = options.kind;
        let missing = |flag: &str| {
            Error::new(format!(
                "{flag} is not a setting of {} ({})",
                kind.name(),
                kind.label()
            ))
        };
        if let Some(d) = self.max_depth {
            *options
                .max_depth_mut()
                .ok_or_else(|| missing("--max-depth"))? = d;
        }
        if self.rr_depth.is_some() || self.no_rr {
            let length = options
                .length_mut()
                .ok_or_else(|| missing("--rr-depth or --no-rr"))?;
            length.rr_depth = self.rr_depth.unwrap_or(length.rr_depth);
            length.russian_roulette &= !self.no_rr;
        }
        // `--mis none` is path tracing's light sampling; a heuristic
        // elsewhere (where `none` reads as power).
        if let Some(mis) = self.mis {
            let heuristic = options.mis_mut().ok_or_else(|| missing("--mis"))?;
            *heuristic = match mis {
                MisArg::Balance => MisHeuristic::Balance,
                MisArg::None | MisArg::Power => MisHeuristic::Power,
            };
        }
        let strategy = match (self.strategy, self.no_nee, self.mis) {
            (Some(StrategyArg::Mis), _, Some(MisArg::None)) => {
                return Err(Error::new("--strategy mis needs --mis balance or power"));
            }
            (Some(StrategyArg::Bsdf), ..) | (None, true, _) => Some(Strategy::Bsdf),
            (Some(StrategyArg::Light), ..) | (None, false, Some(MisArg::None)) => {
                Some(Strategy::Light)
            }
            (Some(StrategyArg::Mis), ..) => Some(Strategy::Mis),
            (None, false, _) => None,
        };
        let seen_exact = self.seen_emitters.map(|s| s == SeenEmittersArg::Exact);
        match kind {
            IntegratorKind::Path => {
                let path = &mut options.path;
                path.strategy = strategy.unwrap_or(path.strategy);
                path.general |= self.general;
                path.exact_seen_emitters = seen_exact.unwrap_or(path.exact_seen_emitters);
            }
            // `--mis none` only changes path tracing.
            _ if strategy.is_some() && !matches!(self.mis, Some(MisArg::None)) => {
                return Err(missing("--strategy or --no-nee"));
            }
            _ => {}
        }
        match kind {
            IntegratorKind::Mcrt => {
                let mcrt = &mut options.mcrt;
                mcrt.shadow_rays = self.shadow_rays.unwrap_or(mcrt.shadow_rays);
                mcrt.glossy_rays = self.glossy_rays.unwrap_or(mcrt.glossy_rays);
                mcrt.exact_seen_emitters = seen_exact.unwrap_or(mcrt.exact_seen_emitters);
            }
            _ if self.shadow_rays.is_some() || self.glossy_rays.is_some() => {
                return Err(missing("--shadow-rays or --glossy-rays"));
            }
            IntegratorKind::Path => {}
            _ if seen_exact.is_some() => return Err(missing("--seen-emitters")),
            _ => {}
        }
        match kind {
            IntegratorKind::Whitted => {
                let whitted = &mut options.whitted;
                whitted.ambient = self.ambient.unwrap_or(whitted.ambient);
                whitted.general |= self.general;
                if let Some(g) = self.glass_shadows {
                    whitted.glass_shadows = match g {
                        GlassShadowsArg::Opaque => GlassShadows::Opaque,
                        GlassShadowsArg::Tinted => GlassShadows::Tinted,
                    };
                }
            }
            _ if self.ambient.is_some() || self.glass_shadows.is_some() => {
                return Err(missing("--ambient or --glass-shadows"));
            }
            IntegratorKind::Path => {}
            _ if self.general => return Err(missing("--general")),
            _ => {}
        }
        if let Some(d) = self.ao_distance {
            if kind != IntegratorKind::AmbientOcclusion {
                return Err(missing("--ao-distance"));
            }
            options.ao.distance = d;
        }
        match kind {
            IntegratorKind::Bdpt => {
                let bdpt = &mut options.bdpt;
                bdpt.light_paths = self.light_paths.unwrap_or(bdpt.light_paths);
                bdpt.light_path_bounces =
                    self.light_path_bounces.unwrap_or(bdpt.light_path_bounces);
            }
            _ if self.light_paths.is_some() || self.light_path_bounces.is_some() => {
                return Err(missing("--light-paths or --light-path-bounces"));
            }
            _ => {}
        }
        match kind {
            IntegratorKind::Photon => {
                let photon = &mut options.photon;
                photon.photons = self.photons.unwrap_or(photon.photons);
                photon.k = self.k.unwrap_or(photon.k);
                photon.gather_radius = self.gather_radius.unwrap_or(photon.gather_radius);
            }
            IntegratorKind::Sppm => {
                let sppm = &mut options.sppm;
                sppm.photons = self.photons.unwrap_or(sppm.photons);
                sppm.radius = self.radius.unwrap_or(sppm.radius);
                sppm.alpha = self.alpha.unwrap_or(sppm.alpha);
            }
            IntegratorKind::Vcm => {
                let vcm = &mut options.vcm;
                vcm.radius = self.radius.unwrap_or(vcm.radius);
                vcm.alpha = self.alpha.unwrap_or(vcm.alpha);
            }
            _ => {}
        }
        let photon_flags = [
            (
                self.photons.is_some(),
                "--photons",
                [IntegratorKind::Photon, IntegratorKind::Sppm],
            ),
            (self.k.is_some(), "--k", [IntegratorKind::Photon; 2]),
            (
                self.gather_radius.is_some(),
                "--gather-radius",
                [IntegratorKind::Photon; 2],
            ),
            (
                self.radius.is_some(),
                "--radius",
                [IntegratorKind::Sppm, IntegratorKind::Vcm],
            ),
            (
                self.alpha.is_some(),
                "--alpha",
                [IntegratorKind::Sppm, IntegratorKind::Vcm],
            ),
        ];
        if let Some((_, flag, _)) = photon_flags
            .iter()
            .find(|(given, _, kinds)| *given && !kinds.contains(&kind))
        {
            return Err(missing(flag));
        }
        self.radiosity.apply(&mut options.radiosity)?;
        Ok(())
    }
}
