//! Photon mapping as Jensen taught it (1996; "Realistic Image Synthesis
//! Using Photon Mapping", 2001): two photon maps, then rendering.
//!
//! - The **global map** holds every photon that lands on a diffuse or
//!   glossy surface; the **caustic map** those that got there through
//!   mirrors and glass alone (L S+ D).
//! - Camera rays follow mirrors and glass, and sample rough metals and
//!   rough glass (their direct light by MIS, as in path tracing), to the
//!   first point x whose surface has a diffuse part. There: emission; direct light by light sampling; caustics by
//!   density estimation in the caustic map,
//!     L_c = sum_{k nearest} f(wo, wi_p) Phi_p / (pi r_k^2 N);
//!   and indirect light by a final gather: a BSDF-sampled ray (through
//!   mirrors and glass) to a diffuse point x', whose reflected radiance is
//!   the same density estimate in the global map.
//!
//! The density estimates blur: their answer is the radiance averaged over a
//! disc holding k photons, so the method is consistent only as the photon
//! count grows with k fixed. Each iteration shoots new maps, so the film
//! converges to the method's answer for this photon count and k, whose
//! distance from the true image (the bias) is plain to see in the error
//! plot's plateau and shrinks with the photon count.

use super::light::photon_shading_factor;
use super::options::check_fraction;
use super::photon_map::{self, MAX_K, Photon, PhotonMap, Side};
use super::{MultiPassEstimator, RayCounts, Settings, Technique};
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::Vec3A;
use std::f32::consts::PI;

/// Settings of Jensen's two-pass photon mapping.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PhotonSettings {
    /// Bounces of a full path, as for path tracing.
    pub max_depth: u32,
    /// Photons per map (0: one per pixel).
    pub photons: u32,
    /// Photons per density estimate (1 to 256).
    pub k: u32,
    /// The largest gather radius, a fraction of the scene's diagonal.
    pub gather_radius: f32,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        PhotonSettings {
            max_depth: 8,
            photons: 0,
            k: 50,
            gather_radius: 0.05,
        }
    }
}

impl Settings for PhotonSettings {
    fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_K as u32).contains(&self.k) {
            return Err(format!("k {} is not in 1..={MAX_K}", self.k));
        }
        check_fraction("gather radius", self.gather_radius)
    }

    fn deepest(&self) -> u32 {
        super::DEEPEST_WITHOUT_ROULETTE
    }

    fn max_depth_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.max_depth)
    }
}

/// Jensen's two-pass photon mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonMap2Pass {
    /// Bounces of a full path, as for path tracing.
    pub max_depth: u32,
    /// Photons shot per iteration (0: one per pixel).
    pub photons: u32,
    /// Photons per density estimate.
    pub k: u32,
    /// The largest gather radius: a fraction of the scene's diagonal until
    /// [`Technique::for_scene`] turns it into scene units (and lowers it to
    /// the radius that holds 4k photons spread evenly).
    pub max_radius: f32,
}

impl Default for PhotonMap2Pass {
    fn default() -> Self {
        PhotonMap2Pass {
            max_depth: 8,
            photons: 0,
            k: 50,
            max_radius: 0.05,
        }
    }
}

impl Technique for PhotonMap2Pass {
    const SUMMARY: &'static str = "Photon mapping (Jensen): a global and a caustic photon map, \
         direct light sampled, caustics by density estimation, indirect light by final gathering; \
         biased, the bias shrinks with the photon count.";

    type Settings = PhotonSettings;

    fn new(settings: &PhotonSettings) -> Self {
        PhotonMap2Pass {
            max_depth: settings.max_depth,
            photons: settings.photons,
            k: settings.k.clamp(1, MAX_K as u32),
            max_radius: settings.gather_radius,
        }
    }

    fn describe(&self) -> String {
        format!(
            "photon map (max depth {}, {} photons, k {}, radius up to {:.3e})",
            self.max_depth,
            photon_map::describe_photons(self.photons),
            self.k,
            self.max_radius
        )
    }

    fn for_scene(self, scene: &Scene) -> Self {
        let photons = photon_map::photons_per_iteration(scene, self.photons);
        let max_radius = photon_map::of_diagonal(scene, self.max_radius);
        // Lookups search a disc that would hold 4k photons were they spread
        // evenly over every surface: where light is brighter the k nearest
        // lie closer, where it is dimmer the estimate keeps this radius. A
        // search out to the largest radius everywhere visited thousands of
        // photons per lookup (Cornell box, 200 000 photons: 127 s for 64
        // iterations).
        let area: f32 = scene.geometry.triangle_area()
            + scene
                .geometry
                .spheres()
                .iter()
                .map(|s| 4.0 * PI * s.radius * s.radius)
                .sum::<f32>();
        let even = (4.0 * self.k as f32 * area / (PI * photons.max(1) as f32)).sqrt();
        PhotonMap2Pass {
            max_radius: if even.is_finite() && even > 0.0 {
                even.min(max_radius)
            } else {
                max_radius
            },
            photons,
            ..self
        }
    }
}

/// One iteration's two maps.
pub struct Maps {
    global: PhotonMap,
    caustic: PhotonMap,
    /// 1 / N: photon weights are per photon shot.
    per_photon: f32,
}

impl PhotonMap2Pass {
    /// Reflected radiance at a diffuse or glossy point towards `wo` (local)
    /// from the `k` photons of `map` nearest it that have at most `most`
    /// bounces (the paths the depth allows).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn density_estimate(
        &self,
        map: &PhotonMap,
        point: Vec3A,
        facing: Vec3A,
        frame: &Frame,
        ng: Vec3A,
        bsdf: &Bsdf,
        wo: Vec3A,
        most: u32,
    ) -> Rgb {
        let mut nearest = [(0.0f32, 0u32); MAX_K];
        let side = Side::of(facing, bsdf.is_transmissive());
        let keep = |p: &Photon| p.bounces <= most;
        let (found, r2) = map.nearest(point, side, self.k as usize, keep, &mut nearest);
        if found == 0 || !(r2 > 0.0) {
            return Rgb::ZERO;
        }
        let mut sum = Rgb::ZERO;
        for &(_, index) in &nearest[..found] {
            let p = map.photon(index);
            let wi = frame.to_local(p.wi);
            sum += bsdf.eval(wo, wi) * p.power * photon_shading_factor(wi, ng);
        }
        sum / (PI * r2)
    }

    /// Follows `ray` through at most `max_bounces` mirrors and glass to a
    /// diffuse or glossy point; returns its hit, the direction the ray
    /// arrived in, the weight of the chain and its bounces, or `None` where
    /// the ray escapes or dies. A light it reaches adds nothing: direct
    /// light is sampled at x.
    #[inline]
    fn through_specular(
        &self,
        scene: &Scene,
        mut ray: Ray,
        max_bounces: u32,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Option<(crate::accel::SurfaceHit, Vec3A, Rgb, u32)> {
        let mut beta = Rgb::ONE;
        for bounces in 0..=max_bounces {
            let hit = scene.geometry.intersect(&ray)?;
            let bsdf = scene.bsdf_at(&hit);
            if bsdf.is_black() {
                return None;
            }
            if !bsdf.is_specular() {
                return Some((hit, ray.direction, beta, bounces));
            }
            if bounces == max_bounces {
                return None;
            }
            let frame = scene.shading_frame(&hit);
            let wo = frame.to_local(-ray.direction);
            let u_lobe = sampler.next_1d_for(Domain::Bsdf);
            let u = sampler.next_2d_for(Domain::Bsdf);
            let sample = bsdf.sample(wo, u_lobe, u)?;
            beta *= sample.weight;
            ray = hit.spawn_ray(frame.to_world(sample.wi));
            counts.bounce += 1;
        }
        None
    }
}

impl MultiPassEstimator for PhotonMap2Pass {
    type Pass = Maps;

    fn prepare(
        &self,
        scene: &Scene,
        pass: u32,
        seed: u64,
        _: crate::sampling::SamplerKind,
        counts: &mut RayCounts,
    ) -> Maps {
        // Direct light is sampled at x, so the caustic map holds photons of
        // at least one (specular) bounce; the global map holds all, as the
        // gather reads the whole reflected radiance at x'.
        let (global, caustic) = photon_map::shoot(
            scene,
            self.photons,
            hash_combine(seed, u64::from(pass)),
            self.max_depth,
            |path| (true, path.bounces > 0 && path.specular_only),
            counts,
        );
        Maps {
            global: PhotonMap::build(global, self.max_radius),
            caustic: PhotonMap::build(caustic, self.max_radius),
            per_photon: 1.0 / self.photons.max(1) as f32,
        }
    }

    fn radiance(
        &self,
        scene: &Scene,
        maps: &Maps,
        ray: Ray,
        _pixel: (u32, u32),
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        // Mirrors and glass from the camera; emission seen through them
        // counts in full.
        let (emitted, at) =
            photon_map::camera_to_diffuse(scene, ray, self.max_depth, sampler, counts);
        let Some(x) = at else {
            return emitted;
        };
        if x.bounces >= self.max_depth {
            return emitted;
        }
        // Bounces that paths of the depth leave after x and the chain.
        let left = self.max_depth - 1 - x.bounces;
        let mut radiance = emitted + x.direct_light(scene, sampler, counts);
        // Caustics: the caustic map at x.
        radiance += x.beta
            * self.density_estimate(
                &maps.caustic,
                x.hit.point,
                x.facing,
                &x.frame,
                x.frame.to_local(x.hit.normal),
                &x.bsdf,
                x.wo,
                left,
            )
            * maps.per_photon;
        // Indirect light: a final gather ray reads the global map at x'.
        if left > 0
            && let Some(sample) = x.bsdf.sample(x.wo, x.u_lobe, x.u_bsdf)
            && !sample.specular
        {
            counts.bounce += 1;
            let gather = x.hit.spawn_ray(x.frame.to_world(sample.wi));
            let found = self.through_specular(scene, gather, left - 1, sampler, counts);
            if let Some((y, arrived, chain, bounces)) = found {
                let bsdf_y = scene.bsdf_at(&y);
                let frame_y = scene.shading_frame(&y);
                let wo_y = frame_y.to_local(-arrived);
                let facing_y = if y.normal.dot(arrived) < 0.0 {
                    y.normal
                } else {
                    -y.normal
                };
                let ng_y = frame_y.to_local(y.normal);
                let reflected = self.density_estimate(
                    &maps.global,
                    y.point,
                    facing_y,
                    &frame_y,
                    ng_y,
                    &bsdf_y,
                    wo_y,
                    left - 1 - bounces,
                );
                radiance += x.beta * sample.weight * chain * reflected * maps.per_photon;
            }
        }
        radiance
    }
}
