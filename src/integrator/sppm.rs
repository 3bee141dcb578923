//! Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008; stochastic,
//! Hachisuka & Jensen 2009) in the probabilistic formulation of Knaus &
//! Zwicker (2011): every iteration shoots a fresh photon map and estimates
//! each pixel from it with a radius that shrinks from iteration to
//! iteration, r_i^2 = r_1^2 i^(alpha - 1). The film averages the iterations,
//! so bias and variance both go to zero (alpha = 2/3 balances them), and
//! no per-pixel statistics have to survive between iterations.
//!
//! Camera rays follow mirrors and glass, and sample rough metals and rough
//! glass (their direct light by MIS, as in path tracing), to the first
//! surface with a diffuse part, as pbrt's SPPM: a narrow lobe reads a
//! photon map with much noise. There, direct light is sampled from the lights (next-event
//! estimation) and everything that arrived after at least one bounce is the
//! density estimate
//!   L = sum_p f(wo, wi_p) Phi_p / (pi r^2 N)
//! over the photons p within r, Phi_p the photon's weight after N photons.
//! Caustics (light through glass onto a diffuse floor) are in that sum, and
//! the density estimate finds them where path tracing rarely does.
//!
//! Photons are found through the hash grid of `photon_map/grid.rs`, built per
//! iteration for that iteration's radius.

use super::light::photon_shading_factor;
use super::options::check_fraction;
use super::photon_map::{self, PhotonMap, Side};
use super::{MultiPassEstimator, RayCounts, Settings, Technique};
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::sampling::hash::hash_combine;
use crate::scene::Scene;
use std::f32::consts::PI;

/// Settings of the progressive photon mapper.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SppmSettings {
    /// Bounces of a full path, as for path tracing.
    pub max_depth: u32,
    /// Photons per iteration (0: one per pixel).
    pub photons: u32,
    /// The first iteration's radius, a fraction of the scene's diagonal.
    pub radius: f32,
    /// r_i^2 = r_1^2 i^(alpha - 1): 0 < alpha <= 1 (1 keeps it fixed, biased).
    pub alpha: f32,
}

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            max_depth: 8,
            photons: 0,
            radius: 0.002,
            alpha: 2.0 / 3.0,
        }
    }
}

/// A radius and its shrinking, as SPPM and VCM take them.
pub(crate) fn check_radius(radius: f32, alpha: f32) -> Result<(), String> {
    check_fraction("radius", radius)?;
    if alpha > 0.0 && alpha <= 1.0 {
        Ok(())
    } else {
        Err(format!("alpha {alpha} is not in (0, 1]"))
    }
}

impl Settings for SppmSettings {
    fn validate(&self) -> Result<(), String> {
        check_radius(self.radius, self.alpha)
    }

    fn deepest(&self) -> u32 {
        super::DEEPEST_WITHOUT_ROULETTE
    }

    fn max_depth_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.max_depth)
    }
}

/// The progressive photon mapper.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonMapper {
    /// Bounces of a full path, as for path tracing.
    pub max_depth: u32,
    /// Photons per iteration (0: one per pixel).
    pub photons: u32,
    /// Radius of the first iteration: a fraction of the scene's diagonal
    /// until [`Technique::for_scene`] turns it into scene units.
    pub radius: f32,
    /// How fast the radius shrinks: r_i^2 = r_1^2 i^(alpha - 1).
    pub alpha: f32,
    /// The first radius in pixels at the median first hit, once
    /// [`Technique::for_scene`] has seen the scene (for the summary).
    pub radius_pixels: Option<f32>,
    /// The frame's width in pixels, with `radius_pixels`.
    pub frame_width: u32,
}

impl Default for PhotonMapper {
    fn default() -> Self {
        PhotonMapper {
            max_depth: 8,
            photons: 0,
            radius: 0.002,
            alpha: 2.0 / 3.0,
            radius_pixels: None,
            frame_width: 0,
        }
    }
}

impl Technique for PhotonMapper {
    const SUMMARY: &'static str = "Progressive photon mapping: direct light by light sampling, \
         the rest by density estimation in a photon map whose radius shrinks every iteration.";

    type Settings = SppmSettings;

    fn new(settings: &SppmSettings) -> Self {
        PhotonMapper {
            max_depth: settings.max_depth,
            photons: settings.photons,
            radius: settings.radius,
            alpha: settings.alpha,
            radius_pixels: None,
            frame_width: 0,
        }
    }

    fn describe(&self) -> String {
        format!(
            "photon mapping (max depth {}, {} photons per iteration, radius {:.3e}{}, alpha {:.2})",
            self.max_depth,
            photon_map::describe_photons(self.photons),
            self.radius,
            photon_map::describe_radius_in_pixels(self.frame_width, self.radius_pixels),
            self.alpha
        )
    }

    fn for_scene(self, scene: &Scene) -> Self {
        let radius = photon_map::of_diagonal(scene, self.radius);
        PhotonMapper {
            radius,
            radius_pixels: photon_map::pixel_footprint(scene).map(|w| radius / w),
            frame_width: scene.camera.width,
            photons: photon_map::photons_per_iteration(scene, self.photons),
            ..self
        }
    }
}

/// One iteration's photon map and the factor 1 / (pi r^2 N) that turns a
/// sum of photon weights into radiance.
pub struct Iteration {
    map: PhotonMap,
    normalisation: f32,
}

impl PhotonMapper {
    /// The radius of iteration `pass` (0, 1, ...).
    pub fn radius_at(&self, pass: u32) -> f32 {
        self.radius * ((pass + 1) as f32).powf((self.alpha - 1.0) * 0.5)
    }
}

impl MultiPassEstimator for PhotonMapper {
    type Pass = Iteration;

    fn prepare(
        &self,
        scene: &Scene,
        pass: u32,
        seed: u64,
        _: crate::sampling::SamplerKind,
        counts: &mut RayCounts,
    ) -> Iteration {
        // Direct light is sampled at the camera's hit: the map holds the
        // photons of at least one bounce.
        let (photons, _) = photon_map::shoot(
            scene,
            self.photons,
            hash_combine(seed, u64::from(pass)),
            self.max_depth.saturating_sub(1),
            |path| (path.bounces > 0, false),
            counts,
        );
        let radius = self.radius_at(pass);
        Iteration {
            map: PhotonMap::build(photons, radius),
            normalisation: 1.0 / (PI * radius * radius * self.photons.max(1) as f32),
        }
    }

    fn radiance(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        ray: Ray,
        _pixel: (u32, u32),
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        // Mirrors and glass are followed from the camera; their chain
        // counts against the depth like any bounce.
        let (emitted, at) =
            photon_map::camera_to_diffuse(scene, ray, self.max_depth, sampler, counts);
        let Some(x) = at else {
            return emitted;
        };
        if x.bounces >= self.max_depth {
            return emitted;
        }
        // Everything after a bounce: the density estimate, over the photons
        // whose paths, with x and the chain before it, stay within the depth.
        let most = self.max_depth - 1 - x.bounces;
        let mut sum = Rgb::ZERO;
        let ng = x.frame.to_local(x.hit.normal);
        let side = Side::of(x.facing, x.bsdf.is_transmissive());
        iteration.map.for_each_near(x.hit.point, side, |p| {
            if p.bounces <= most {
                let wi = x.frame.to_local(p.wi);
                sum += x.bsdf.eval(x.wo, wi) * p.power * photon_shading_factor(wi, ng);
            }
        });
        emitted + x.direct_light(scene, sampler, counts) + x.beta * sum * iteration.normalisation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radius_shrinks_as_alpha_says() {
        let pm = PhotonMapper {
            radius: 1.0,
            ..PhotonMapper::default()
        };
        assert_eq!(pm.radius_at(0), 1.0);
        // r_8^2 = 8^(-1/3) = 1/2.
        assert!((pm.radius_at(7).powi(2) - 0.5).abs() < 1e-6);
    }
}
