//! Ambient occlusion: how much of the hemisphere above the first hit is open,
//! weighted by the cosine, within a distance. A standard debug view (pbrt-v4's
//! `ambientocclusion`, Blender's AO pass) that shows geometry and contact
//! without any light: a plane under an open sky is 1, a corner darkens.
//!
//!   AO(x) = 1/pi * integral over the hemisphere of V(x, w, d) cos(theta) dw,
//!
//! where V is 1 when nothing lies within distance d along w. With directions
//! drawn by the cosine density p(w) = cos(theta) / pi, each sample is just
//! V: the estimator is the fraction of unblocked cosine samples, a Bernoulli
//! variable of variance AO (1 - AO). Camera rays that hit nothing give 0.

use super::{CameraEstimator, RayCounts, Settings, Technique};
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::warp::square_to_cosine_hemisphere;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::shortcuts::{PrimaryPixel, ShortcutsUsed};

/// Settings of the ambient occlusion estimator.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct AoSettings {
    /// Occluders count within this fraction of the scene's bounding-box
    /// diagonal (0: no limit).
    pub distance: f32,
}

impl Default for AoSettings {
    fn default() -> Self {
        AoSettings { distance: 0.1 }
    }
}

impl Settings for AoSettings {
    fn validate(&self) -> Result<(), String> {
        if self.distance >= 0.0 && self.distance.is_finite() {
            Ok(())
        } else {
            Err(format!(
                "ambient occlusion distance {} is not a fraction >= 0 of the scene's size",
                self.distance
            ))
        }
    }
}

/// The ambient occlusion estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    /// Occluders farther than this fraction of the scene's bounding-box
    /// diagonal do not count (0: no limit). A fraction, so that the image
    /// does not depend on the scene's units.
    pub relative_distance: f32,
    /// [`AmbientOcclusion::relative_distance`] in the scene's units
    /// (infinite without a limit), set by [`Technique::for_scene`].
    distance: f32,
}

impl Default for AmbientOcclusion {
    fn default() -> Self {
        AmbientOcclusion::with_relative_distance(0.1)
    }
}

impl AmbientOcclusion {
    /// Occluders count within `fraction` of the scene's diagonal (0: all).
    pub fn with_relative_distance(fraction: f32) -> Self {
        AmbientOcclusion {
            relative_distance: fraction.max(0.0),
            distance: f32::INFINITY,
        }
    }
}

impl Technique for AmbientOcclusion {
    const SUMMARY: &'static str = "Ambient occlusion: the cosine-weighted open fraction of the hemisphere at the first hit, within a distance.";

    type Settings = AoSettings;

    fn new(settings: &AoSettings) -> Self {
        AmbientOcclusion::with_relative_distance(settings.distance)
    }

    fn describe(&self) -> String {
        if self.relative_distance > 0.0 {
            format!(
                "ambient occlusion (distance {} of the scene's diagonal)",
                self.relative_distance
            )
        } else {
            "ambient occlusion (no distance limit)".into()
        }
    }

    fn for_scene(self, scene: &Scene) -> Self {
        let bounds = scene.geometry.bounds();
        let diagonal = (bounds.max - bounds.min).length();
        let distance = if self.relative_distance > 0.0 && diagonal.is_finite() {
            self.relative_distance * diagonal
        } else {
            f32::INFINITY
        };
        AmbientOcclusion { distance, ..self }
    }
}

impl CameraEstimator for AmbientOcclusion {
    fn shortcuts_used(&self) -> ShortcutsUsed {
        ShortcutsUsed {
            primary_candidates: true,
            ..ShortcutsUsed::default()
        }
    }

    fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let u = sampler.next_2d_for(Domain::Bsdf);
        let Some(hit) = scene
            .geometry
            .intersect_maybe_among::<false>(&ray, pixel.candidates)
        else {
            return Rgb::ZERO;
        };
        // The hemisphere on the side the camera sees.
        let normal = if hit.normal.dot(ray.direction) > 0.0 {
            -hit.normal
        } else {
            hit.normal
        };
        let direction = Frame::from_normal(normal).to_world(square_to_cosine_hemisphere(u));
        let mut probe = hit.spawn_ray(direction);
        probe.t_max = self.distance;
        counts.shadow += 1;
        if scene.geometry.occluded(&probe) {
            Rgb::ZERO
        } else {
            Rgb::ONE
        }
    }
}
