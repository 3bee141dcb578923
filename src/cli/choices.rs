//! The render command's choices that clap parses by name (`--strategy`,
//! `--light-sampling`, `--sampler`, ...), and their meaning for the core.

use clap::ValueEnum;
use tracelab::sampling::SamplerKind;

#[derive(ValueEnum, Clone, Copy, Debug)]
pub(crate) enum StrategyArg {
    /// BSDF sampling only.
    Bsdf,
    /// Light sampling only.
    Light,
    /// Both, combined by MIS.
    Mis,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub(crate) enum LightSamplingArg {
    /// Uniform by area: density d^2 / (cos A) in solid angle.
    Area,
    /// Uniform in solid angle: sphere cones, spherical triangles (Arvo).
    SolidAngle,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub(crate) enum GlassShadowsArg {
    Opaque,
    Tinted,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SeenEmittersArg {
    Exact,
    Sampled,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub(crate) enum SamplerArg {
    /// Independent uniform numbers.
    Independent,
    /// Jittered strata in every dimension and pair, shuffled between dimensions.
    Stratified,
    /// Correlated multi-jittered: jittered and Latin hypercube in every pair.
    Multijitter,
    /// Owen-scrambled Sobol, shuffled per dimension pair (path tracing:
    /// for the camera sample and the first two vertices, then independent).
    Sobol,
}

impl SamplerArg {
    pub(crate) fn kind(self) -> SamplerKind {
        match self {
            SamplerArg::Independent => SamplerKind::Independent,
            SamplerArg::Stratified => SamplerKind::Stratified,
            SamplerArg::Multijitter => SamplerKind::MultiJittered,
            SamplerArg::Sobol => SamplerKind::Sobol,
        }
    }
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub(crate) enum MisArg {
    None,
    Balance,
    Power,
}
