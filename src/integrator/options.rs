//! What techniques' settings have in common. Each technique owns one
//! settings struct in its own file (defaults, validation, serde for files);
//! [`IntegratorOptions`], generated from the registration list in
//! `mod.rs`, holds one of each and the chosen technique, and is the one
//! form that the CLI, the viewer and an imported file's integrator block
//! all fill in.

use super::{IntegratorKind, IntegratorOptions, MisHeuristic};
use crate::scene::RenderHints;

/// Which sampling strategies the path tracer uses for direct light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// BSDF sampling only: light is found when a bounce hits an emitter.
    Bsdf,
    /// Light sampling only (next-event estimation); hits on emitters after a
    /// diffuse or glossy bounce are ignored.
    Light,
    /// Both, combined by multiple importance sampling.
    #[default]
    Mis,
}

/// How long the paths of a path-building technique run; each such
/// technique keeps its own.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PathLength {
    /// Bounces (1 = direct lighting); Mitsuba's max_depth is one more.
    pub max_depth: u32,
    pub russian_roulette: bool,
    /// Roulette starts after this many bounces (Mitsuba's `rr_depth`).
    pub rr_depth: u32,
}

impl PathLength {
    /// Why this length cannot run: without roulette, a path that total
    /// internal reflection traps would never end.
    pub fn check(&self) -> Result<(), String> {
        if self.max_depth == crate::scene::UNBOUNDED_DEPTH && !self.russian_roulette {
            return Err("a max depth without limit needs Russian roulette to end paths".into());
        }
        Ok(())
    }
}

/// The deepest that techniques without Russian roulette go (Whitted,
/// distribution ray tracing, the photon techniques' specular chains) when
/// a file asks for no limit: light trapped by total internal reflection
/// would otherwise never leave.
pub const DEEPEST_WITHOUT_ROULETTE: u32 = 100;

/// A depth for summaries: Mitsuba's unbounded depth reads as such.
pub(crate) fn depth_label(depth: u32) -> String {
    if depth == crate::scene::UNBOUNDED_DEPTH {
        "no limit".into()
    } else {
        depth.to_string()
    }
}

impl Default for PathLength {
    fn default() -> Self {
        PathLength {
            max_depth: 8,
            russian_roulette: true,
            rr_depth: 5,
        }
    }
}

/// A technique's settings: plain data with defaults, saved and read by
/// serde, checked before a render starts. The accessors give the settings
/// that several techniques share (depth, roulette, MIS) to the CLI, the
/// viewer and imported files without knowing which technique it is.
pub trait Settings:
    Clone
    + Copy
    + std::fmt::Debug
    + PartialEq
    + Default
    + serde::Serialize
    + serde::de::DeserializeOwned
{
    /// Why these settings cannot run, in a sentence naming the setting.
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }
    /// The maximum depth, where the technique has one (its path length's,
    /// where it has that).
    fn max_depth_mut(&mut self) -> Option<&mut u32> {
        self.length_mut().map(|length| &mut length.max_depth)
    }
    /// The deepest paths the technique can make.
    fn deepest(&self) -> u32 {
        u32::MAX
    }
    /// Depth and roulette, where the technique has both.
    fn length_mut(&mut self) -> Option<&mut PathLength> {
        None
    }
    /// The heuristic that combines its strategies, where it has one.
    fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
        None
    }
}

/// Settings of techniques that have none (tests' stand-ins).
impl Settings for () {}

/// A fraction of the scene's diagonal, strictly between 0 and 1.
pub(crate) fn check_fraction(name: &str, value: f32) -> Result<(), String> {
    if value > 0.0 && value < 1.0 {
        Ok(())
    } else {
        Err(format!(
            "{name} {value} is not a fraction in (0, 1) of the scene's size"
        ))
    }
}

/// The heuristic of estimators that always combine strategies (`None` is
/// not one of them).
pub(crate) fn combining(mis: MisHeuristic) -> MisHeuristic {
    if mis == MisHeuristic::None {
        MisHeuristic::Power
    } else {
        mis
    }
}

impl IntegratorOptions {
    /// The default settings of technique `kind`.
    pub fn of(kind: IntegratorKind) -> IntegratorOptions {
        IntegratorOptions {
            kind,
            ..IntegratorOptions::default()
        }
    }

    /// The maximum depth of the chosen technique, where it has one.
    pub fn max_depth(&self) -> Option<u32> {
        self.clone().max_depth_mut().map(|d| *d)
    }

    /// What an imported file's integrator block asks for: the technique
    /// (unless `keep_kind`), its depth and where roulette starts; returns
    /// what was taken, for the user to read.
    pub fn take_hints(
        &mut self,
        hints: &RenderHints,
        keep_kind: bool,
    ) -> Result<Vec<String>, String> {
        let mut taken = Vec::new();
        if let Some(name) = hints.integrator.as_deref().filter(|_| !keep_kind) {
            self.kind = IntegratorKind::from_name(name)
                .ok_or_else(|| format!("the scene asks for an unknown technique \"{name}\""))?;
            taken.push(self.kind.label().to_string());
        }
        let (deepest, label) = (self.deepest(), self.kind.label());
        if let (Some(d), Some(depth)) = (hints.max_depth, self.max_depth_mut()) {
            *depth = d.min(deepest);
            taken.push(if d > deepest {
                let asked = depth_label(d);
                format!("max depth {deepest}, the most of {label} (the file asks for {asked})")
            } else {
                format!("max depth {}", depth_label(d))
            });
        }
        if let (Some(d), Some(length)) = (hints.rr_depth, self.length_mut()) {
            length.rr_depth = d;
            taken.push(format!("roulette from {d}"));
        }
        if let Some(name) = hints
            .strategy
            .as_deref()
            .filter(|_| self.kind == IntegratorKind::Path)
        {
            self.path.strategy = match name {
                "bsdf" => Strategy::Bsdf,
                "light" => Strategy::Light,
                "mis" => Strategy::Mis,
                other => {
                    return Err(format!(
                        "the scene asks for an unknown strategy \"{other}\""
                    ));
                }
            };
            taken.push(format!("strategy {name}"));
        }
        Ok(taken)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_set_the_chosen_techniques_own_depth() {
        let hints = RenderHints {
            integrator: Some("bdpt".into()),
            max_depth: Some(4),
            rr_depth: Some(2),
            ..RenderHints::default()
        };
        let mut options = IntegratorOptions::default();
        let taken = options.take_hints(&hints, false).unwrap();
        assert_eq!(taken.len(), 3, "{taken:?}");
        assert_eq!(options.kind, IntegratorKind::Bdpt);
        assert_eq!(
            (options.bdpt.length.max_depth, options.bdpt.length.rr_depth),
            (4, 2)
        );
        // Path tracing keeps its own.
        assert_eq!(options.path.length, PathLength::default());
        // Ambient occlusion has no depth: nothing is set, nothing said.
        let mut ao = IntegratorOptions::of(IntegratorKind::AmbientOcclusion);
        assert_eq!(ao.take_hints(&hints, true).unwrap(), Vec::<String>::new());
        // An unbounded depth (Mitsuba's -1) is BDPT's deepest, said.
        let unbounded = RenderHints {
            max_depth: Some(crate::scene::UNBOUNDED_DEPTH),
            ..RenderHints::default()
        };
        let mut bdpt = IntegratorOptions::of(IntegratorKind::Bdpt);
        let said = bdpt.take_hints(&unbounded, true).unwrap();
        assert_eq!(bdpt.max_depth(), Some(crate::integrator::bdpt::MAX_BOUNCES));
        assert!(said[0].contains("the file asks for no limit"), "{said:?}");
        assert!(bdpt.validate().is_ok());
        let unknown = RenderHints {
            integrator: Some("volpath2".into()),
            ..RenderHints::default()
        };
        assert!(options.take_hints(&unknown, false).is_err());
    }

    #[test]
    fn settings_read_from_a_file_keep_what_it_leaves_out_at_the_defaults() {
        let options: IntegratorOptions =
            toml::from_str("kind = \"vcm\"\n[vcm]\nmax_depth = 3\nradius = 0.01\n").unwrap();
        assert_eq!(options.kind, IntegratorKind::Vcm);
        assert_eq!(
            (options.vcm.length.max_depth, options.vcm.radius),
            (3, 0.01)
        );
        assert_eq!(options.vcm.length.rr_depth, 5);
        assert_eq!(options.path, IntegratorOptions::default().path);
        let back: IntegratorOptions = toml::from_str(&toml::to_string(&options).unwrap()).unwrap();
        assert_eq!(back, options);
        // Each technique checks its own.
        let mut bad = options;
        bad.vcm.alpha = 1.5;
        assert!(bad.validate().unwrap_err().contains("alpha 1.5"));
    }
}
