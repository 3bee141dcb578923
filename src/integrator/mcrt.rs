//! Monte Carlo (distribution) ray tracing (Cook, Porter & Carpenter 1984):
//! at every hit, N shadow rays to sampled light points and M rays sampled
//! from the BSDF, each of which recurses. The tree of rays grows as M^D with
//! the depth D, which is why path tracing (M = 1) replaced it.
//!
//! The two sample sets are combined by the multi-sample MIS of Veach
//! (balance or power heuristic with sample counts): with densities p_l, p_b,
//!   L(x) = (1/N) sum_i w_l f Le cos / p_l  +  (1/M) sum_j f cos / p_b [w_b Le(y_j) + L(y_j)]
//!   w_l = (N p_l)^b / ((N p_l)^b + (M p_b)^b),   w_b likewise.
//! `max_depth` counts bounces, as in the other estimators: the hits of
//! levels 0..D-1 take light samples (light of 1..D bounces), and BSDF rays
//! leave all but the last level. There none are cast (M = 0), so light
//! samples carry all of the last bounce's light (BSDF rays remain where no
//! light sample can be taken: specular surfaces, or N = 0). Cook's tree of
//! two branching levels (the classic 186-ray example) is D = 3.

use super::{CameraEstimator, MisHeuristic, RayCounts, Settings, Technique};
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::math::{Ray, Rgb};
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::shortcuts::{PrimaryPixel, ShortcutsUsed};

/// Settings of the branching ray tracer.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct McrtSettings {
    /// Bounces: 1 = direct lighting only.
    pub max_depth: u32,
    /// Light samples (shadow rays) per hit: N.
    pub shadow_rays: u32,
    /// BSDF samples per hit, each recursing: M.
    pub glossy_rays: u32,
    /// How the two sample sets combine (`None` reads as power).
    pub mis: MisHeuristic,
    /// Emitters seen directly integrated exactly over each pixel where
    /// that is possible (`crate::accel::seen_emitters`).
    pub exact_seen_emitters: bool,
}

impl Default for McrtSettings {
    fn default() -> Self {
        McrtSettings {
            max_depth: 8,
            shadow_rays: 1,
            glossy_rays: 1,
            mis: MisHeuristic::Power,
            exact_seen_emitters: true,
        }
    }
}

impl Settings for McrtSettings {
    fn validate(&self) -> Result<(), String> {
        if self.shadow_rays + self.glossy_rays == 0 {
            return Err("shadow rays and glossy rays cannot both be 0".into());
        }
        Ok(())
    }

    fn deepest(&self) -> u32 {
        super::DEEPEST_WITHOUT_ROULETTE
    }

    fn max_depth_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.max_depth)
    }

    fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
        Some(&mut self.mis)
    }
}

/// The branching ray tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct McRayTracer {
    /// Bounces: 1 = direct lighting only.
    pub max_depth: u32,
    /// Light samples (shadow rays) per hit.
    pub shadow_rays: u32,
    /// BSDF samples (secondary rays) per hit, each recursing.
    pub glossy_rays: u32,
    pub mis: MisHeuristic,
    /// Emission seen directly is integrated exactly over the pixel where the
    /// scene knows it (as the path tracer does), instead of sampled.
    pub exact_seen_emitters: bool,
}

impl Default for McRayTracer {
    fn default() -> Self {
        McRayTracer {
            max_depth: 2,
            shadow_rays: 5,
            glossy_rays: 5,
            mis: MisHeuristic::Power,
            exact_seen_emitters: true,
        }
    }
}

/// Multi-sample MIS weight of a strategy with `n_a` samples of density `pdf_a`
/// against one with `n_b` samples of density `pdf_b`.
#[inline]
fn multi_sample_weight(heuristic: MisHeuristic, n_a: u32, pdf_a: f32, n_b: u32, pdf_b: f32) -> f32 {
    if n_b == 0 {
        return 1.0;
    }
    heuristic.weight(n_a as f32 * pdf_a, n_b as f32 * pdf_b)
}

impl Technique for McRayTracer {
    const SUMMARY: &'static str =
        "Monte Carlo (distribution) ray tracing: N shadow rays and M branching BSDF rays per hit.";

    type Settings = McrtSettings;

    fn new(settings: &McrtSettings) -> Self {
        McRayTracer {
            max_depth: settings.max_depth,
            shadow_rays: settings.shadow_rays,
            glossy_rays: settings.glossy_rays,
            mis: super::options::combining(settings.mis),
            exact_seen_emitters: settings.exact_seen_emitters,
        }
    }

    fn describe(&self) -> String {
        format!(
            "mcrt (max depth {}, shadow rays {}, glossy rays {}, mis {:?})",
            self.max_depth, self.shadow_rays, self.glossy_rays, self.mis
        )
    }
}

impl McRayTracer {
    /// Expected rays per camera sample in a closed scene where every ray hits
    /// a non-specular scattering surface, with N > 0:
    /// 1 + sum_{d=0..D-1} M^d N + sum_{d=1..D-1} M^d (saturating at `u64::MAX`).
    pub fn rays_per_sample_closed(&self) -> u64 {
        let (m, n) = (self.glossy_rays as u64, self.shadow_rays as u64);
        let mut total = 1;
        let mut width = 1u64;
        for level in 0..self.max_depth {
            total = width.saturating_mul(n).saturating_add(total);
            if level + 1 < self.max_depth {
                width = width.saturating_mul(m);
                total = total.saturating_add(width);
            }
            if total == u64::MAX || m == 0 {
                break;
            }
        }
        total
    }
}

impl CameraEstimator for McRayTracer {
    /// One radiance sample along the camera ray. The emission its pixel sees
    /// directly, integrated over the pixel where known
    /// ([`PrimaryPixel::seen_emission`]), replaces the camera hit's own
    /// emission, as in the path tracer.
    fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let seen_emission = pixel.seen_emission.filter(|_| self.exact_seen_emitters);
        let Some(hit) = scene.geometry.intersect(&ray) else {
            let background = scene
                .lights
                .environment()
                .map_or(Rgb::ZERO, |e| e.le(ray.direction));
            return seen_emission.unwrap_or(background);
        };
        let emitted = match seen_emission {
            Some(emission) => emission,
            None if hit.light != NO_LIGHT => scene.emitted(&hit, -ray.direction),
            None => Rgb::ZERO,
        };
        emitted + self.scattered(scene, &hit, -ray.direction, 0, sampler, counts)
    }

    fn shortcuts_used(&self) -> ShortcutsUsed {
        ShortcutsUsed {
            seen_emitters: Some(self.exact_seen_emitters),
            ..ShortcutsUsed::default()
        }
    }
}

impl McRayTracer {
    /// Light scattered at `hit` (a vertex of level `level`, 0 at the camera
    /// ray's hit) towards `wo_world`, excluding its emission: light of
    /// bounces `level + 1 ..= max_depth`.
    fn scattered(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        wo_world: glam::Vec3A,
        level: u32,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let bsdf = scene.bsdf_at(&hit);
        if level >= self.max_depth || bsdf.is_black() {
            return Rgb::ZERO;
        }
        let frame = scene.shading_frame(&hit);
        let wo = frame.to_local(wo_world);
        let n_light = if bsdf.is_specular() {
            0
        } else {
            self.shadow_rays
        };
        let last_level = level + 1 == self.max_depth;
        let n_bsdf = if last_level && n_light > 0 {
            0
        } else {
            self.glossy_rays
        };
        let mut radiance = Rgb::ZERO;

        for _ in 0..n_light {
            let u_select = sampler.next_1d_for(Domain::Light);
            let u_light = sampler.next_2d_for(Domain::Light);
            let Some(ls) = scene.lights.sample(hit.point, u_select, u_light) else {
                continue;
            };
            let wi = frame.to_local(ls.wi);
            let f = bsdf.eval(wo, wi);
            if f.max_element() <= 0.0 {
                continue;
            }
            let weight = if ls.delta || self.mis == MisHeuristic::None {
                1.0
            } else {
                multi_sample_weight(self.mis, n_light, ls.pdf, n_bsdf, bsdf.pdf(wo, wi))
            };
            counts.shadow += 1;
            if !scene.geometry.occluded(&ls.shadow_ray_from(hit)) {
                radiance += f * ls.radiance * (wi.z.abs() * weight / (ls.pdf * n_light as f32));
            }
        }

        for _ in 0..n_bsdf {
            let u_lobe = sampler.next_1d_for(Domain::Bsdf);
            let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
            let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
                continue;
            };
            let wi_world = frame.to_world(sample.wi);
            let ray = hit.spawn_ray(wi_world);
            counts.bounce += 1;
            let Some(next) = scene.geometry.intersect(&ray) else {
                if let Some(env) = scene.lights.environment() {
                    let towards = env.towards(wi_world);
                    let weight = if sample.specular || n_light == 0 {
                        1.0
                    } else if self.mis == MisHeuristic::None {
                        0.0
                    } else {
                        let light_pdf = scene.lights.environment_pdf_towards(towards);
                        multi_sample_weight(self.mis, n_bsdf, sample.pdf, n_light, light_pdf)
                    };
                    radiance += sample.weight / n_bsdf as f32 * env.le_towards(towards) * weight;
                }
                continue;
            };
            let beta = sample.weight / n_bsdf as f32;
            if next.light != NO_LIGHT {
                let emitted = scene.emitted(&next, -wi_world);
                if emitted.max_element() > 0.0 {
                    let weight = if sample.specular || n_light == 0 {
                        1.0
                    } else if self.mis == MisHeuristic::None {
                        0.0
                    } else {
                        let light_pdf =
                            scene
                                .lights
                                .pdf(next.light, hit.point, next.point, next.normal);
                        multi_sample_weight(self.mis, n_bsdf, sample.pdf, n_light, light_pdf)
                    };
                    radiance += beta * emitted * weight;
                }
            }
            if !last_level {
                radiance +=
                    beta * self.scattered(scene, &next, -wi_world, level + 1, sampler, counts);
            }
        }
        radiance
    }
}
