//! Techniques that solve the rendering equation, one file each, behind one
//! interface. A technique is one of four kinds, each driven by the
//! render session (`Session`) through the same pass API:
//!
//! - a **camera estimator** ([`CameraEstimator`]) returns a radiance value
//!   per camera sample (Whitted, MC ray tracing, path tracing, ambient
//!   occlusion);
//! - a **splatting estimator** ([`SplattingEstimator`]) traces paths whose
//!   contributions land anywhere on the film (light tracing);
//! - a **multi-pass estimator** ([`MultiPassEstimator`]) builds shared data
//!   once per pass (a photon map), then estimates per camera sample from it;
//! - a **solver** ([`Solver`]) runs solve steps and shows an image of its
//!   solution (radiosity).
//!
//! Each kind is a closed enum generated from the registration list at the
//! bottom of this file, dispatched once per sample (never inside a bounce
//! loop) and never by a virtual call. Adding a technique is its own file,
//! one line in that list and its controls; `docs/design.md` lists the files.

pub mod ambient_occlusion;
pub mod bdpt;
mod camera_ray;
pub mod light;
pub mod mcrt;
pub mod mis;
pub mod options;
pub mod path;
pub mod photon;
pub mod photon_map;
pub mod radiosity;
pub mod sppm;
pub mod strategy_images;
pub mod vcm;
pub mod whitted;

pub use bdpt::Bdpt;
pub use camera_ray::{camera_ray, camera_ray_through, sample_time};
pub use light::{LightTracer, Splat};
pub use mcrt::McRayTracer;
pub use mis::MisHeuristic;
pub use options::{DEEPEST_WITHOUT_ROULETTE, PathLength, Settings, Strategy};
pub use path::PathTracer;
pub use whitted::{GlassShadows, WhittedTracer};

use crate::filter::PixelFilter;
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::shortcuts::{PrimaryPixel, ShortcutsUsed};

/// Rays cast, by kind; kept per thread and summed after each tile. For light
/// tracing, `camera` counts the rays leaving the lights (the primary rays)
/// and `shadow` the connections to the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub camera: u64,
    pub shadow: u64,
    pub bounce: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.bounce
    }
}

/// Russian roulette (after the first `rr_depth` bounces): the path survives
/// with probability q = min(max(beta) * scale, 0.95) (Mitsuba's choice) and
/// is reweighted by 1/q, which keeps the estimate unbiased while paths that
/// carry little energy end early. `scale` takes out of beta what does not
/// make a path worth less: the 1/eta^2 of radiance inside glass (Mitsuba
/// multiplies by eta^2), or a light path's starting power, so that the
/// scene's units do not decide. Returns false when the path ends.
#[inline]
pub(crate) fn survives_roulette(beta: &mut Rgb, scale: f32, u: f32) -> bool {
    let q = (beta.max_element() * scale).min(0.95);
    if u >= q {
        return false;
    }
    *beta /= q;
    true
}

/// What every technique has, whatever its kind.
pub trait Technique: Sized + Send + Sync {
    /// One sentence for the command line's help: what the technique does.
    const SUMMARY: &'static str;
    /// The settings it is made from, its own struct in its own file.
    type Settings: Settings;
    /// The technique with `settings`.
    fn new(settings: &Self::Settings) -> Self;
    /// Short description with the settings, for summaries and metadata.
    fn describe(&self) -> String;
    /// The settings resolved for `scene` (pbrt's preprocess): a distance
    /// given as a fraction of the scene's size becomes one in its units, so
    /// that no result depends on them. The session calls it once.
    fn for_scene(self, _scene: &Scene) -> Self {
        self
    }
}

/// An estimator of the radiance arriving along a camera ray.
pub trait CameraEstimator: Technique {
    /// One radiance sample along the camera ray `ray`; counts the rays it
    /// casts after the camera ray into `counts`. `pixel`: what is known in
    /// advance about the ray's pixel ([`crate::shortcuts::PrimaryCandidates`]).
    fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb;

    /// True when every sample of a pixel gives the same value (one ray
    /// through the pixel centre), so one sample per pixel is the image.
    fn is_deterministic(&self) -> bool {
        false
    }

    /// Which small-scene shortcuts it reads (`crate::shortcuts`), for the
    /// reports of what applies.
    fn shortcuts_used(&self) -> ShortcutsUsed {
        ShortcutsUsed::default()
    }

    /// True when the estimator runs its general code even where the scene
    /// allows a specialised one (for measuring what specialisation saves):
    /// camera rays then draw a time even in a static scene.
    fn is_general(&self) -> bool {
        false
    }
}

/// An estimator whose paths start at the lights and whose contributions
/// land anywhere on the film.
pub trait SplattingEstimator: Technique {
    /// Traces one path for a sample of pixel `pixel` (which a light path
    /// may ignore) and hands each contribution that reaches the film to
    /// `splat`, not yet divided by the number of paths of the pass. A
    /// camera ray's film position is drawn from `camera_filter` (the box
    /// where the session splats the pixel's own estimates through the
    /// scene's filter).
    fn trace(
        &self,
        scene: &Scene,
        pixel: (u32, u32),
        camera_filter: PixelFilter,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        splat: impl FnMut(Splat),
    );
}

/// An estimator that builds data shared by all pixels once per pass (a
/// photon map), then estimates radiance per camera sample from it.
pub trait MultiPassEstimator: Technique {
    /// What a pre-pass builds and the pass's camera samples read.
    type Pass: Send + Sync;
    /// Runs the pre-pass of pass number `pass` (0, 1, ...); may use rayon,
    /// as it runs on the session's threads. Randomness must come from
    /// (`seed`, `pass`) alone so images stay independent of the schedule;
    /// `sampler` is the session's, which a pre-pass may follow.
    fn prepare(
        &self,
        scene: &Scene,
        pass: u32,
        seed: u64,
        sampler: crate::sampling::SamplerKind,
        counts: &mut RayCounts,
    ) -> Self::Pass;
    /// One radiance sample along a camera ray through pixel `pixel`,
    /// reading this pass's data.
    fn radiance(
        &self,
        scene: &Scene,
        pass: &Self::Pass,
        ray: Ray,
        pixel: (u32, u32),
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb;
}

/// A solver: improves a solution by steps, and shows it through camera rays.
pub trait Solver: Technique {
    /// The solution and whatever the steps need between calls.
    type State: Send + Sync + 'static;
    /// The initial state (meshing, form factors); errors name what failed.
    fn init(&self, scene: &Scene) -> crate::Result<Self::State>;
    /// Runs up to `steps` solve steps; may use rayon.
    fn step(
        &self,
        scene: &Scene,
        state: &mut Self::State,
        steps: u32,
        counts: &mut RayCounts,
    ) -> SolverProgress;
    /// One radiance sample of the current solution along a camera ray of
    /// `pixel` (whose seen emission, where known, the display adds itself).
    fn radiance(
        &self,
        scene: &Scene,
        state: &Self::State,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb;
    /// What the user should know about how the scene was taken (surfaces
    /// left out, materials approximated), one line each.
    fn notes(&self, _state: &Self::State) -> Vec<String> {
        Vec::new()
    }
    /// Samples per pixel of one image of the solution (ray-cast display
    /// with antialiasing, say); 1 for a deterministic display.
    fn display_spp(&self) -> u32;
    /// The sampler of a display whose only noise is the pixel's coverage (a
    /// lookup of the solution): stratified antialiasing needs a quarter of
    /// the rays of independent samples for the same edge noise. `None`
    /// follows the session's sampler.
    fn display_sampler(&self) -> Option<crate::sampling::SamplerKind> {
        None
    }
}

/// Where a solver stands after a batch of steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolverProgress {
    /// Steps run so far.
    pub steps: u64,
    /// The solver's own error estimate (a residual, or the unshot power
    /// over the emitted power), comparable between steps.
    pub residual: f64,
    /// No further step changes the solution.
    pub converged: bool,
    /// The solver's unknowns and couplings (radiosity: leaf elements and
    /// links), for reports; 0 where they mean nothing.
    pub elements: u64,
    pub links: u64,
    /// Bytes the solver's model takes (elements, links, matrix).
    pub memory: u64,
    /// Seconds spent setting up and solving so far, without drawing images.
    pub solve_seconds: f64,
    /// Seconds spent preparing the display from the solution so far (the
    /// smooth display's vertex values), without drawing images.
    pub display_seconds: f64,
}

/// What a session can say about a technique's error without a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ErrorEstimate {
    /// Root mean square standard error of the pixel means.
    Sampling(f64),
    /// A deterministic estimator: no sampling noise to estimate.
    Deterministic,
    /// A solver's residual ([`SolverProgress::residual`]).
    Residual(f64),
    /// Not yet known (fewer than two samples).
    Unknown,
}

/// The four kinds of technique.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TechniqueKind {
    Camera,
    Splatting,
    MultiPass,
    Solver,
}

/// Generates, from one list of techniques by kind: [`IntegratorKind`] (the
/// names the CLI and the viewer offer), one enum per kind that dispatches
/// statically to the techniques' trait methods, and
/// [`IntegratorOptions::build`].
macro_rules! register_techniques {
    (
        camera { $($cv:ident($ct:ty, $cf:ident) = $cname:literal, $clabel:literal;)* }
        splatting { $($sv:ident($st:ty, $sf:ident) = $sname:literal, $slabel:literal;)* }
        multi_pass { $($mv:ident($mt:ty, $mf:ident) = $mname:literal, $mlabel:literal;)* }
        solver { $($xv:ident($xt:ty, $xf:ident) = $xname:literal, $xlabel:literal;)* }
    ) => {
        /// The chosen technique and every technique's settings (each
        /// keeps its own while another is chosen, as the viewer's A and B
        /// do); a file's `[integrator]` table in the same form.
        #[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
        #[serde(default)]
        pub struct IntegratorOptions {
            pub kind: IntegratorKind,
            $(pub $cf: <$ct as Technique>::Settings,)*
            $(pub $sf: <$st as Technique>::Settings,)*
            $(pub $mf: <$mt as Technique>::Settings,)*
            $(pub $xf: <$xt as Technique>::Settings,)*
        }

        /// Which technique, by name.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
        pub enum IntegratorKind {
            $(#[serde(rename = $cname)] $cv,)*
            $(#[serde(rename = $sname)] $sv,)*
            $(#[serde(rename = $mname)] $mv,)*
            $(#[serde(rename = $xname)] $xv,)*
        }

        impl IntegratorKind {
            /// Every registered technique, in registration order.
            pub const ALL: &'static [IntegratorKind] = &[
                $(IntegratorKind::$cv,)* $(IntegratorKind::$sv,)*
                $(IntegratorKind::$mv,)* $(IntegratorKind::$xv,)*
            ];

            /// Short name, as the command line spells it.
            pub fn name(self) -> &'static str {
                match self {
                    $(IntegratorKind::$cv => $cname,)* $(IntegratorKind::$sv => $sname,)*
                    $(IntegratorKind::$mv => $mname,)* $(IntegratorKind::$xv => $xname,)*
                }
            }

            /// Name for menus.
            pub fn label(self) -> &'static str {
                match self {
                    $(IntegratorKind::$cv => $clabel,)* $(IntegratorKind::$sv => $slabel,)*
                    $(IntegratorKind::$mv => $mlabel,)* $(IntegratorKind::$xv => $xlabel,)*
                }
            }

            /// One sentence on what the technique does ([`Technique::SUMMARY`]).
            pub fn summary(self) -> &'static str {
                match self {
                    $(IntegratorKind::$cv => <$ct as Technique>::SUMMARY,)*
                    $(IntegratorKind::$sv => <$st as Technique>::SUMMARY,)*
                    $(IntegratorKind::$mv => <$mt as Technique>::SUMMARY,)*
                    $(IntegratorKind::$xv => <$xt as Technique>::SUMMARY,)*
                }
            }

            /// Which kind of technique it is.
            pub fn technique(self) -> TechniqueKind {
                match self {
                    $(IntegratorKind::$cv => TechniqueKind::Camera,)*
                    $(IntegratorKind::$sv => TechniqueKind::Splatting,)*
                    $(IntegratorKind::$mv => TechniqueKind::MultiPass,)*
                    $(IntegratorKind::$xv => TechniqueKind::Solver,)*
                }
            }
        }

        impl IntegratorOptions {
            /// The configured technique.
            pub fn build(&self) -> Integrator {
                match self.kind {
                    $(IntegratorKind::$cv =>
                        Integrator::Camera(CameraIntegrator::$cv(<$ct>::new(&self.$cf))),)*
                    $(IntegratorKind::$sv =>
                        Integrator::Splatting(SplattingIntegrator::$sv(<$st>::new(&self.$sf))),)*
                    $(IntegratorKind::$mv =>
                        Integrator::MultiPass(MultiPassIntegrator::$mv(<$mt>::new(&self.$mf))),)*
                    $(IntegratorKind::$xv =>
                        Integrator::Solver(SolverIntegrator::$xv(<$xt>::new(&self.$xf))),)*
                }
            }

            /// [`Settings::validate`] of the chosen technique's settings.
            pub fn validate(&self) -> Result<(), String> {
                match self.kind {
                    $(IntegratorKind::$cv => self.$cf.validate(),)*
                    $(IntegratorKind::$sv => self.$sf.validate(),)*
                    $(IntegratorKind::$mv => self.$mf.validate(),)*
                    $(IntegratorKind::$xv => self.$xf.validate(),)*
                }
            }

            /// [`Settings::max_depth_mut`] of the chosen technique.
            pub fn max_depth_mut(&mut self) -> Option<&mut u32> {
                match self.kind {
                    $(IntegratorKind::$cv => self.$cf.max_depth_mut(),)*
                    $(IntegratorKind::$sv => self.$sf.max_depth_mut(),)*
                    $(IntegratorKind::$mv => self.$mf.max_depth_mut(),)*
                    $(IntegratorKind::$xv => self.$xf.max_depth_mut(),)*
                }
            }

            /// [`Settings::deepest`] of the chosen technique.
            pub fn deepest(&self) -> u32 {
                match self.kind {
                    $(IntegratorKind::$cv => self.$cf.deepest(),)*
                    $(IntegratorKind::$sv => self.$sf.deepest(),)*
                    $(IntegratorKind::$mv => self.$mf.deepest(),)*
                    $(IntegratorKind::$xv => self.$xf.deepest(),)*
                }
            }

            /// [`Settings::length_mut`] of the chosen technique.
            pub fn length_mut(&mut self) -> Option<&mut PathLength> {
                match self.kind {
                    $(IntegratorKind::$cv => self.$cf.length_mut(),)*
                    $(IntegratorKind::$sv => self.$sf.length_mut(),)*
                    $(IntegratorKind::$mv => self.$mf.length_mut(),)*
                    $(IntegratorKind::$xv => self.$xf.length_mut(),)*
                }
            }

            /// [`Settings::mis_mut`] of the chosen technique.
            pub fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
                match self.kind {
                    $(IntegratorKind::$cv => self.$cf.mis_mut(),)*
                    $(IntegratorKind::$sv => self.$sf.mis_mut(),)*
                    $(IntegratorKind::$mv => self.$mf.mis_mut(),)*
                    $(IntegratorKind::$xv => self.$xf.mis_mut(),)*
                }
            }
        }

        /// A configured camera estimator.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum CameraIntegrator { $($cv($ct),)* }

        $(impl From<$ct> for Integrator {
            fn from(estimator: $ct) -> Integrator {
                Integrator::Camera(CameraIntegrator::$cv(estimator))
            }
        })*

        $(impl From<$st> for Integrator {
            fn from(estimator: $st) -> Integrator {
                Integrator::Splatting(SplattingIntegrator::$sv(estimator))
            }
        })*

        impl CameraIntegrator {
            /// [`CameraEstimator::radiance`] of the configured estimator.
            #[inline]
            pub fn radiance(
                &self,
                scene: &Scene,
                ray: Ray,
                pixel: PrimaryPixel<'_>,
                sampler: &mut Sampler,
                counts: &mut RayCounts,
            ) -> Rgb {
                match self { $(CameraIntegrator::$cv(e) => e.radiance(scene, ray, pixel, sampler, counts),)* }
            }

            fn kind(&self) -> IntegratorKind {
                match self { $(CameraIntegrator::$cv(_) => IntegratorKind::$cv,)* }
            }

            fn describe(&self) -> String {
                match self { $(CameraIntegrator::$cv(e) => e.describe(),)* }
            }

            fn for_scene(self, scene: &Scene) -> Self {
                match self { $(CameraIntegrator::$cv(e) => CameraIntegrator::$cv(e.for_scene(scene)),)* }
            }

            /// [`CameraEstimator::is_deterministic`].
            pub fn is_deterministic(&self) -> bool {
                match self { $(CameraIntegrator::$cv(e) => e.is_deterministic(),)* }
            }

            /// [`CameraEstimator::shortcuts_used`].
            pub fn shortcuts_used(&self) -> ShortcutsUsed {
                match self { $(CameraIntegrator::$cv(e) => e.shortcuts_used(),)* }
            }

            /// [`CameraEstimator::is_general`].
            pub fn is_general(&self) -> bool {
                match self { $(CameraIntegrator::$cv(e) => e.is_general(),)* }
            }

        }

        /// A configured splatting estimator.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum SplattingIntegrator { $($sv($st),)* }

        impl SplattingIntegrator {
            /// [`SplattingEstimator::trace`] of the configured estimator.
            #[inline]
            pub fn trace(
                &self,
                scene: &Scene,
                pixel: (u32, u32),
                camera_filter: PixelFilter,
                sampler: &mut Sampler,
                counts: &mut RayCounts,
                splat: impl FnMut(Splat),
            ) {
                match self { $(SplattingIntegrator::$sv(e) => e.trace(scene, pixel, camera_filter, sampler, counts, splat),)* }
            }

            /// True when some of its contributions are estimates of the
            /// traced sample's own pixel (BDPT's camera strategies).
            pub fn has_camera_strategies(&self) -> bool {
                matches!(self.kind(), IntegratorKind::Bdpt)
            }

            fn kind(&self) -> IntegratorKind {
                match self { $(SplattingIntegrator::$sv(_) => IntegratorKind::$sv,)* }
            }

            fn describe(&self) -> String {
                match self { $(SplattingIntegrator::$sv(e) => e.describe(),)* }
            }

            fn for_scene(self, scene: &Scene) -> Self {
                match self { $(SplattingIntegrator::$sv(e) => SplattingIntegrator::$sv(e.for_scene(scene)),)* }
            }
        }

        /// A configured multi-pass estimator (photon mapping registers here).
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum MultiPassIntegrator { $($mv($mt),)* }

        // While a kind has no technique its enum is empty and these are unreachable.
        #[allow(unused_variables, unreachable_code)]
        impl MultiPassIntegrator {
            /// Calls `visit` with the configured estimator's concrete type,
            /// so the session's pass loop is compiled for it.
            pub fn visit<V: MultiPassVisitor>(&self, visit: V) -> V::Output {
                match *self { $(MultiPassIntegrator::$mv(ref e) => visit.visit(e),)* }
            }

            fn kind(&self) -> IntegratorKind {
                match *self { $(MultiPassIntegrator::$mv(_) => IntegratorKind::$mv,)* }
            }

            fn describe(&self) -> String {
                match *self { $(MultiPassIntegrator::$mv(ref e) => e.describe(),)* }
            }

            fn for_scene(self, scene: &Scene) -> Self {
                match self { $(MultiPassIntegrator::$mv(e) => MultiPassIntegrator::$mv(e.for_scene(scene)),)* }
            }
        }

        /// A configured solver (radiosity registers here).
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum SolverIntegrator { $($xv($xt),)* }

        #[allow(unused_variables, unreachable_code)]
        impl SolverIntegrator {
            /// Calls `visit` with the configured solver's concrete type.
            pub fn visit<V: SolverVisitor>(&self, visit: V) -> V::Output {
                match *self { $(SolverIntegrator::$xv(ref e) => visit.visit(e),)* }
            }

            fn kind(&self) -> IntegratorKind {
                match *self { $(SolverIntegrator::$xv(_) => IntegratorKind::$xv,)* }
            }

            fn describe(&self) -> String {
                match *self { $(SolverIntegrator::$xv(ref e) => e.describe(),)* }
            }

            fn for_scene(self, scene: &Scene) -> Self {
                match self { $(SolverIntegrator::$xv(e) => SolverIntegrator::$xv(e.for_scene(scene)),)* }
            }
        }
    };
}

/// Receives a multi-pass estimator as its concrete type.
pub trait MultiPassVisitor {
    type Output;
    fn visit<E: MultiPassEstimator>(self, estimator: &E) -> Self::Output;
}

/// Receives a solver as its concrete type.
pub trait SolverVisitor {
    type Output;
    fn visit<S: Solver>(self, solver: &S) -> Self::Output;
}

/// A configured technique of any kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    Camera(CameraIntegrator),
    Splatting(SplattingIntegrator),
    MultiPass(MultiPassIntegrator),
    Solver(SolverIntegrator),
}

// Arms of kinds without a registered technique are unreachable.
#[allow(unreachable_code)]
impl Integrator {
    /// Which technique.
    pub fn kind(&self) -> IntegratorKind {
        match self {
            Integrator::Camera(e) => e.kind(),
            Integrator::Splatting(e) => e.kind(),
            Integrator::MultiPass(e) => e.kind(),
            Integrator::Solver(e) => e.kind(),
        }
    }

    /// Which kind of technique.
    pub fn technique(&self) -> TechniqueKind {
        match self {
            Integrator::Camera(_) => TechniqueKind::Camera,
            Integrator::Splatting(_) => TechniqueKind::Splatting,
            Integrator::MultiPass(_) => TechniqueKind::MultiPass,
            Integrator::Solver(_) => TechniqueKind::Solver,
        }
    }

    /// Short description for summaries and file names.
    pub fn describe(&self) -> String {
        match self {
            Integrator::Camera(e) => e.describe(),
            Integrator::Splatting(e) => e.describe(),
            Integrator::MultiPass(e) => e.describe(),
            Integrator::Solver(e) => e.describe(),
        }
    }

    /// Short name, as the command line spells it.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The settings resolved for `scene` ([`Technique::for_scene`]).
    pub fn for_scene(self, scene: &Scene) -> Integrator {
        match self {
            Integrator::Camera(e) => Integrator::Camera(e.for_scene(scene)),
            Integrator::Splatting(e) => Integrator::Splatting(e.for_scene(scene)),
            Integrator::MultiPass(e) => Integrator::MultiPass(e.for_scene(scene)),
            Integrator::Solver(e) => Integrator::Solver(e.for_scene(scene)),
        }
    }

    /// True when every sample of a pixel gives the same value, so one sample
    /// per pixel is the image and there is no sampling noise.
    pub fn is_deterministic(&self) -> bool {
        matches!(self, Integrator::Camera(e) if e.is_deterministic())
    }

    /// Which small-scene shortcuts it reads.
    pub fn shortcuts_used(&self) -> ShortcutsUsed {
        match self {
            Integrator::Camera(e) => e.shortcuts_used(),
            _ => ShortcutsUsed::default(),
        }
    }
}

impl Default for IntegratorKind {
    fn default() -> Self {
        IntegratorKind::Path
    }
}

impl IntegratorKind {
    /// The technique named `name` (as [`IntegratorKind::name`] spells it).
    pub fn from_name(name: &str) -> Option<IntegratorKind> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// Every name, comma-separated, for error messages and help.
    pub fn names() -> String {
        Self::ALL
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

// The registration list: one line per technique.
register_techniques! {
    camera {
        Whitted(WhittedTracer, whitted) = "whitted", "Whitted ray tracing";
        Mcrt(McRayTracer, mcrt) = "mcrt", "Monte Carlo ray tracing";
        Path(PathTracer, path) = "path", "Path tracing";
        AmbientOcclusion(ambient_occlusion::AmbientOcclusion, ao) = "ao", "Ambient occlusion";
    }
    splatting {
        Light(LightTracer, light) = "light", "Light tracing";
        Bdpt(Bdpt, bdpt) = "bdpt", "Bidirectional path tracing";
    }
    multi_pass {
        Photon(photon::PhotonMap2Pass, photon) = "photon", "Photon mapping (Jensen)";
        Sppm(sppm::PhotonMapper, sppm) = "sppm", "Progressive photon mapping";
        Vcm(vcm::Vcm, vcm) = "vcm", "Vertex connection and merging";
    }
    solver {
        Radiosity(radiosity::Radiosity, radiosity) = "radiosity", "Radiosity";
    }
}
