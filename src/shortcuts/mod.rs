//! The small-scene shortcuts: what a renderer can know in advance about the
//! rays of a small scene, so that it tests less. Each answers exactly what
//! the full test would (the same watertight test on fewer triangles), and
//! each applies only where its preconditions hold and its cost is capped:
//!
//! | shortcut | what it knows | preconditions | caps |
//! |---|---|---|---|
//! | camera candidates ([`PrimaryCandidates`]) | per pixel, the triangles its camera rays can hit | a static soup (at most [`crate::accel::SOUP_MAX_TRIANGLES`] triangles, no spheres, nothing moving); a pinhole camera; camera rays through their pixel's square ([`CameraSampling`]: the box filter, or samples splatted through a wider one); no triangle reaching behind the eye's image plane | build: 24 overlap tests per pixel; lists: 8 bytes per pixel on average (plus 4 per pixel for where each starts); at most half of the pixels over 16 candidates |
//! | lights seen directly ([`seen_emitters`]) | per pixel, the emission it sees, integrated exactly over the pixel | the camera candidates; the box filter; flat emitters of constant radiance; per pixel, no other candidate that could hide part of the emitter | those of the candidates (the values are stored only for pixels that see a light) |
//! | shadow voxels ([`ShadowVoxels`]) | per voxel of the scene's box (16 along its longest side), the few triangles that can block shadow rays to one flat light | a static soup; a triangle or parallelogram light; at most 8 lights; robust ray offsets (per ray: both ends inside the soup's box) | at most 3 occluders listed per voxel, else the voxel takes the full test |
//!
//! Nothing here grows with pixels x triangles: the candidate lists are
//! counted before they are allocated and refused past their caps, with the
//! reason ([`NotApplied`]) reported by the CLI's summary and the viewer.
//! The camera lists depend on the camera, so they are built lazily, once per
//! camera, by the first render pass that needs them (on a render thread,
//! never the viewer's); the shadow voxels depend only on the geometry and
//! are built with the scene.

pub mod primary_candidates;
pub mod projection;
pub mod seen_emitters;
pub mod shadow_voxels;

pub use primary_candidates::{PrimaryCandidates, PrimaryPixel};
pub use shadow_voxels::ShadowVoxels;

use crate::accel::{Geometry, SOUP_MAX_TRIANGLES};
use crate::camera::Camera;
use crate::math::Rgb;
use glam::Vec3A;
use std::fmt;
use std::sync::{Arc, OnceLock};

/// Lights up to this many get [`ShadowVoxels`] (each costs a build at load).
const MAX_VOXEL_LIGHTS: usize = 8;

/// Which shortcuts an estimator reads, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShortcutsUsed {
    /// Camera rays test their pixel's candidates.
    pub primary_candidates: bool,
    /// Lights seen directly: integrated exactly where known (`Some(true)`),
    /// or sampled by choice (`Some(false)`); `None`: not an estimator that can.
    pub seen_emitters: Option<bool>,
    /// Shadow rays to flat lights test their voxel's occluders.
    pub shadow_voxels: bool,
}

/// Where a render's camera samples lie and how its film weighs them, which
/// decides what the camera lists may be used for: they hold for rays
/// through their pixel's square, and the emission they know is integrated
/// over that square, as the box filter weighs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraSampling {
    /// Uniform in the pixel, the box filter: the lists and the seen emission.
    BoxFilter,
    /// In the pixel, weighed by a wider filter (splatted samples, or a
    /// deterministic ray through the centre): the lists alone.
    InPixel,
    /// Drawn from a filter wider than the pixel: rays leave its square.
    FromFilter,
}

impl CameraSampling {
    /// The sampling of a render through `filter` whose samples are
    /// `splatted` through it, or `deterministic` (pixel centres).
    pub fn of(filter: crate::filter::PixelFilter, splatted: bool, deterministic: bool) -> Self {
        match filter {
            crate::filter::PixelFilter::Box => CameraSampling::BoxFilter,
            _ if splatted || deterministic => CameraSampling::InPixel,
            _ => CameraSampling::FromFilter,
        }
    }

    /// Whether camera rays may test their pixel's candidates only.
    pub fn lists_apply(self) -> bool {
        self != CameraSampling::FromFilter
    }

    /// Whether a pixel's seen emission may replace its sampled emission.
    pub fn seen_emission_applies(self) -> bool {
        self == CameraSampling::BoxFilter
    }
}

/// Why a shortcut does not apply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NotApplied {
    /// The scene has spheres (the soup's one-by-one test covers triangles).
    Spheres,
    /// Something moves while the shutter is open.
    Motion,
    /// Opacity masks: a ray may pass the triangle a list names.
    Masks,
    /// More triangles than a soup holds: the BVH already tests few.
    ManyTriangles(usize),
    /// No triangle at all (spheres alone, or nothing).
    NoTriangles,
    /// Instanced geometry: the lists name the geometry's own triangles.
    Instances,
    /// A thin lens: camera rays leave from anywhere on the lens.
    ThinLens,
    /// A pixel filter wider than the pixel: camera rays leave its square
    /// (drawn from the filter), or the film weighs a pixel's samples by
    /// where they lie (splatted).
    WideFilter,
    /// A triangle reaches behind the eye's image plane (unbounded projection).
    BehindEye,
    /// The build would take this many overlap tests per pixel, or most
    /// pixels would list too many triangles to save anything.
    Crowded { tests_per_pixel: f64 },
    /// The lists would take this many bytes, past their cap.
    Memory { bytes: u64 },
    /// The light is not flat (a sphere or a point).
    NotFlat,
    /// More lights than get voxels.
    ManyLights(usize),
    /// Switched off (to measure what it saves), or made for another camera.
    SwitchedOff,
}

impl fmt::Display for NotApplied {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NotApplied::Spheres => write!(f, "the scene has spheres"),
            NotApplied::Motion => write!(f, "something moves"),
            NotApplied::Masks => write!(f, "the scene has opacity masks"),
            NotApplied::Instances => write!(f, "the scene has instances"),
            NotApplied::ManyTriangles(n) => write!(
                f,
                "{n} triangles, more than {SOUP_MAX_TRIANGLES}: the BVH decides"
            ),
            NotApplied::NoTriangles => write!(f, "the scene has no triangles"),
            NotApplied::ThinLens => write!(f, "thin lens"),
            NotApplied::WideFilter => write!(f, "the pixel filter is wider than a pixel"),
            NotApplied::BehindEye => write!(f, "a triangle reaches behind the eye"),
            NotApplied::Crowded { tests_per_pixel } => write!(
                f,
                "triangles overlap {tests_per_pixel:.1} times per pixel: lists would save nothing"
            ),
            NotApplied::Memory { bytes } => write!(
                f,
                "the lists would need {:.0} MB, past their cap",
                *bytes as f64 * 1e-6
            ),
            NotApplied::NotFlat => write!(f, "not a flat light"),
            NotApplied::ManyLights(n) => {
                write!(f, "{n} lights, more than {MAX_VOXEL_LIGHTS}")
            }
            NotApplied::SwitchedOff => write!(f, "switched off"),
        }
    }
}

/// The shortcuts of one scene and camera.
#[derive(Clone, Debug, Default)]
pub struct Shortcuts {
    /// The camera rays' candidate lists (with the emission each pixel sees),
    /// built on first use for the camera they were made for.
    primary: Arc<OnceLock<Result<Arc<PrimaryCandidates>, NotApplied>>>,
    /// Per light, its shadow voxels, or why it has none.
    shadow_voxels: Arc<[Result<ShadowVoxels, NotApplied>]>,
}

impl Shortcuts {
    /// The shortcuts of a scene, without the camera lists (built lazily).
    /// `flat_lights`: per light, its corners in order where it is flat.
    pub fn new(geometry: &Geometry, flat_lights: &[Option<Vec<Vec3A>>]) -> Shortcuts {
        Shortcuts {
            primary: Arc::new(OnceLock::new()),
            shadow_voxels: shadow_voxels(geometry, flat_lights),
        }
    }

    /// The same shortcuts without the camera lists (to measure them).
    pub fn without_primary_candidates(mut self) -> Shortcuts {
        let off = OnceLock::new();
        let _ = off.set(Err(NotApplied::SwitchedOff));
        self.primary = Arc::new(off);
        self
    }

    /// The same shortcuts without shadow voxels (to measure them).
    pub fn without_shadow_voxels(mut self) -> Shortcuts {
        self.shadow_voxels = self
            .shadow_voxels
            .iter()
            .map(|_| Err(NotApplied::SwitchedOff))
            .collect();
        self
    }

    /// Forgets the camera lists: the camera changed.
    pub fn camera_changed(&mut self) {
        self.primary = Arc::new(OnceLock::new());
    }

    /// The camera rays' candidate lists for `camera`, built on the first
    /// call (so on the thread of the first render pass), with the emission
    /// each pixel sees: `seen_radiance(i)` is what triangle `i` sends towards
    /// the eye when it is a flat light of constant radiance.
    pub fn primary_candidates(
        &self,
        geometry: &Geometry,
        camera: &Camera,
        seen_radiance: impl Fn(usize) -> Option<Rgb>,
    ) -> Result<&PrimaryCandidates, NotApplied> {
        match self.primary.get_or_init(|| {
            static_soup(geometry)?;
            let triangles = geometry.triangles();
            let candidates = PrimaryCandidates::build(camera, triangles)?;
            Ok(Arc::new(
                candidates.with_seen_emitters(triangles, seen_radiance),
            ))
        }) {
            Ok(lists) if lists.is_for(camera) => Ok(lists),
            Ok(_) => Err(NotApplied::SwitchedOff),
            Err(reason) => Err(*reason),
        }
    }

    /// The shadow voxels of light `light`, where it has them.
    #[inline(always)]
    pub fn shadow_voxels(&self, light: u32) -> Option<&ShadowVoxels> {
        self.shadow_voxels.get(light as usize)?.as_ref().ok()
    }

    /// Per light, its shadow voxels or why it has none.
    pub fn all_shadow_voxels(&self) -> &[Result<ShadowVoxels, NotApplied>] {
        &self.shadow_voxels
    }
}

/// What keeps a geometry from the soup-only shortcuts, if anything.
fn static_soup(geometry: &Geometry) -> Result<(), NotApplied> {
    if geometry.has_spheres() {
        Err(NotApplied::Spheres)
    } else if geometry.has_motion() {
        Err(NotApplied::Motion)
    } else if geometry.has_masks() {
        Err(NotApplied::Masks)
    } else if geometry.instance_count() > 0 {
        Err(NotApplied::Instances)
    } else if geometry.triangle_count() == 0 {
        Err(NotApplied::NoTriangles)
    } else if !geometry.is_static_soup() {
        Err(NotApplied::ManyTriangles(geometry.triangle_count()))
    } else {
        Ok(())
    }
}

/// Each flat light's [`ShadowVoxels`], where the geometry allows them.
fn shadow_voxels(
    geometry: &Geometry,
    lights: &[Option<Vec<Vec3A>>],
) -> Arc<[Result<ShadowVoxels, NotApplied>]> {
    if lights.len() > MAX_VOXEL_LIGHTS {
        return lights
            .iter()
            .map(|_| Err(NotApplied::ManyLights(lights.len())))
            .collect();
    }
    lights
        .iter()
        .enumerate()
        .map(|(id, light)| {
            static_soup(geometry)?;
            let corners = light.as_ref().ok_or(NotApplied::NotFlat)?;
            ShadowVoxels::for_light(geometry, id as u32, corners).ok_or(NotApplied::SwitchedOff)
        })
        .collect()
}
