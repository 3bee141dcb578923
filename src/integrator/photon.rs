//! Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008; stochastic,
//! Hachisuka & Jensen 2009) in the probabilistic formulation of Knaus &
//! Zwicker (2011): every iteration shoots a fresh photon map and estimates
//! each pixel from it with a radius that shrinks from iteration to
//! iteration, r_i^2 = r_1^2 i^(alpha - 1). The film averages the iterations,
//! so bias and variance both go to zero (alpha = 2/3 balances them), and
//! no per-pixel statistics have to survive between iterations.
//!
//! Camera rays follow mirrors and glass to the first diffuse or glossy
//! surface. There, direct light is sampled from the lights (next-event
//! estimation) and everything that arrived after at least one bounce is the
//! density estimate
//!   L = sum_p f(wo, wi_p) Phi_p / (pi r^2 N)
//! over the photons p within r, Phi_p the photon's weight after N photons.
//! Caustics (light through glass onto a diffuse floor) are in that sum, and
//! the density estimate finds them where path tracing rarely does.
//!
//! Photons are found through a hash grid of cells of side 2r built per
//! iteration (a counting sort of photon indices by cell): lookups are all
//! of one radius and the map is rebuilt every iteration, so a k-d tree's
//! k-nearest queries and balancing buy nothing here (SmallVCM does the
//! same).

use super::light::importance_weight;
use super::{IntegratorOptions, MultiPassEstimator, RayCounts, Technique};
use crate::accel::NO_LIGHT;
use crate::math::{Frame, Ray, Rgb, offset_ray_origin, ray_between};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domain, Sampler, SamplerKind};
use crate::scene::Scene;
use glam::Vec3A;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Settings of the progressive photon mapper.
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
}

impl Default for PhotonMapper {
    fn default() -> Self {
        PhotonMapper {
            max_depth: 8,
            photons: 0,
            radius: 0.002,
            alpha: 2.0 / 3.0,
        }
    }
}

impl Technique for PhotonMapper {
    const SUMMARY: &'static str = "Progressive photon mapping: direct light by light sampling, \
         the rest by density estimation in a photon map whose radius shrinks every iteration.";

    fn from_options(options: &IntegratorOptions) -> Self {
        PhotonMapper {
            max_depth: options.max_depth,
            photons: options.photons,
            radius: options.photon_radius,
            alpha: options.photon_alpha,
        }
    }

    fn describe(&self) -> String {
        format!(
            "photon mapping (max depth {}, {} photons per iteration, radius {:.3e}, alpha {:.2})",
            self.max_depth,
            if self.photons == 0 {
                "one per pixel".to_string()
            } else {
                self.photons.to_string()
            },
            self.radius,
            self.alpha
        )
    }

    fn for_scene(self, scene: &Scene) -> Self {
        let bounds = scene.geometry.bounds();
        let diagonal = (bounds.max - bounds.min).length();
        let photons = if self.photons == 0 {
            scene.camera.width * scene.camera.height
        } else {
            self.photons
        };
        PhotonMapper {
            radius: if diagonal.is_finite() && diagonal > 0.0 {
                self.radius * diagonal
            } else {
                self.radius
            },
            photons,
            ..self
        }
    }
}

/// A photon: where it landed, where it came from, and what it carries.
#[derive(Clone, Copy, Debug)]
struct Photon {
    point: Vec3A,
    /// Unit direction back towards where the photon came from.
    wi: Vec3A,
    /// The surface's normal, so that photons on the far side of a thin
    /// wall do not count.
    normal: Vec3A,
    power: Rgb,
}

/// One iteration's photons in a hash grid of cells of side 2r: a query
/// point's sphere of radius r touches at most 2 x 2 x 2 cells.
pub struct PhotonMap {
    photons: Vec<Photon>,
    /// Photon indices sorted by cell hash; `starts[h]..starts[h + 1]`
    /// are those of hash h.
    order: Vec<u32>,
    starts: Vec<u32>,
    cell: f32,
    radius: f32,
    /// 1 / (pi r^2 N): turns a sum of photon weights into radiance.
    normalisation: f32,
}

impl PhotonMap {
    fn hash(&self, c: [i32; 3]) -> usize {
        let h = (c[0] as u32).wrapping_mul(73856093)
            ^ (c[1] as u32).wrapping_mul(19349663)
            ^ (c[2] as u32).wrapping_mul(83492791);
        h as usize % (self.starts.len() - 1)
    }

    fn cell_of(&self, p: Vec3A) -> [i32; 3] {
        let c = (p / self.cell).floor();
        [c.x as i32, c.y as i32, c.z as i32]
    }

    fn build(photons: Vec<Photon>, radius: f32, emitted: u32) -> PhotonMap {
        let buckets = photons.len().next_power_of_two().max(1);
        let mut map = PhotonMap {
            order: vec![0; photons.len()],
            starts: vec![0; buckets + 1],
            photons: Vec::new(),
            cell: 2.0 * radius,
            radius,
            normalisation: 1.0 / (PI * radius * radius * emitted.max(1) as f32),
        };
        let hashes: Vec<usize> = photons
            .iter()
            .map(|p| map.hash(map.cell_of(p.point)))
            .collect();
        for &h in &hashes {
            map.starts[h + 1] += 1;
        }
        for i in 1..map.starts.len() {
            map.starts[i] += map.starts[i - 1];
        }
        let mut next = map.starts.clone();
        for (i, &h) in hashes.iter().enumerate() {
            map.order[next[h] as usize] = i as u32;
            next[h] += 1;
        }
        map.photons = photons;
        map
    }

    /// Photons stored.
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    /// True when no photon was stored.
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// Calls `visit` with every photon within the radius of `point` on the
    /// side of the surface that `normal` faces.
    #[inline]
    fn for_each_near(&self, point: Vec3A, normal: Vec3A, mut visit: impl FnMut(&Photon)) {
        if self.photons.is_empty() {
            return;
        }
        // The 2 x 2 x 2 cells nearest the point cover its sphere.
        let base = (point / self.cell - Vec3A::splat(0.5)).floor();
        let r2 = self.radius * self.radius;
        let mut seen = [usize::MAX; 8];
        for k in 0..8 {
            let c = [
                base.x as i32 + (k & 1),
                base.y as i32 + ((k >> 1) & 1),
                base.z as i32 + ((k >> 2) & 1),
            ];
            let h = self.hash(c);
            // Two cells may share a hash; visit each bucket once.
            if seen[..k as usize].contains(&h) {
                continue;
            }
            seen[k as usize] = h;
            for &i in &self.order[self.starts[h] as usize..self.starts[h + 1] as usize] {
                let p = &self.photons[i as usize];
                if (p.point - point).length_squared() <= r2 && p.normal.dot(normal) > 0.0 {
                    visit(p);
                }
            }
        }
    }
}

impl PhotonMapper {
    /// The radius of iteration `pass` (0, 1, ...).
    pub fn radius_at(&self, pass: u32) -> f32 {
        self.radius * ((pass + 1) as f32).powf((self.alpha - 1.0) * 0.5)
    }

    /// Traces photon `index` of an iteration and stores where it lands on
    /// non-specular surfaces after at least one bounce (direct light is
    /// sampled at the camera's hit instead).
    fn trace_photon(&self, scene: &Scene, sampler: &mut Sampler, store: &mut Vec<Photon>, counts: &mut RayCounts) {
        let u_select = sampler.next_1d_for(Domain::Light);
        let u_position = sampler.next_2d_for(Domain::Light);
        let u_direction = sampler.next_2d_for(Domain::Light);
        let Some(emission) = scene
            .lights
            .sample_emission(u_select, u_position, u_direction)
        else {
            return;
        };
        let roulette_scale = 1.0 / emission.throughput.max_element();
        let mut beta = emission.throughput;
        let mut ray = Ray::new(
            offset_ray_origin(emission.point, emission.error, emission.normal, emission.direction),
            emission.direction,
        )
        .at_time(scene.camera.shutter_open);
        counts.bounce += 1;
        // A photon's hit after k bounces lights paths of k + 1 bounces and
        // more from the camera's first diffuse hit: k < max_depth.
        for bounces in 0..self.max_depth {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                break;
            };
            let bsdf = scene.materials[hit.material as usize].bsdf;
            if bsdf.is_black() {
                break;
            }
            let frame = Frame::from_normal(hit.normal);
            let wo = frame.to_local(-ray.direction);
            let u_lobe = sampler.next_1d_for(Domain::Bsdf);
            let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
            let u_roulette = sampler.next_1d();
            if !bsdf.is_specular() && bounces > 0 {
                let facing = if wo.z > 0.0 { hit.normal } else { -hit.normal };
                store.push(Photon {
                    point: hit.point,
                    wi: -ray.direction,
                    normal: facing,
                    power: beta,
                });
            }
            let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
                break;
            };
            beta *= importance_weight(bsdf, wo, sample.wi, sample.weight);
            // Roulette from the first bounce: a photon is cheap and the
            // map only needs its density right.
            if !super::survives_roulette(&mut beta, roulette_scale, u_roulette) {
                break;
            }
            ray = hit.spawn_ray(frame.to_world(sample.wi));
            counts.bounce += 1;
        }
    }
}

impl MultiPassEstimator for PhotonMapper {
    type Pass = PhotonMap;

    fn prepare(&self, scene: &Scene, pass: u32, seed: u64, counts: &mut RayCounts) -> PhotonMap {
        const CHUNK: u32 = 4096;
        let key = hash_combine(seed, 0x5048_4f54_4f4e ^ u64::from(pass));
        let chunks = self.photons.div_ceil(CHUNK);
        let (photons, traced): (Vec<Vec<Photon>>, Vec<RayCounts>) = (0..chunks)
            .into_par_iter()
            .map(|chunk| {
                let mut sampler = Sampler::new(SamplerKind::Independent, key, 0);
                let mut store = Vec::new();
                let mut counts = RayCounts::default();
                let end = ((chunk + 1) * CHUNK).min(self.photons);
                for index in chunk * CHUNK..end {
                    sampler.start(index, 0);
                    self.trace_photon(scene, &mut sampler, &mut store, &mut counts);
                }
                (store, counts)
            })
            .unzip();
        for c in traced {
            counts.bounce += c.bounce;
        }
        PhotonMap::build(photons.concat(), self.radius_at(pass), self.photons)
    }

    fn radiance(
        &self,
        scene: &Scene,
        map: &PhotonMap,
        mut ray: Ray,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let mut beta = Rgb::ONE;
        let mut radiance = Rgb::ZERO;
        // Mirrors and glass are followed from the camera; their chain
        // counts against the depth like any bounce.
        for _ in 0..=self.max_depth {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                break;
            };
            let material = &scene.materials[hit.material as usize];
            let wo_world = -ray.direction;
            if hit.light != NO_LIGHT {
                radiance += beta * material.emitted(hit.normal, wo_world);
            }
            let bsdf = material.bsdf;
            if bsdf.is_black() {
                break;
            }
            let frame = Frame::from_normal(hit.normal);
            let wo = frame.to_local(wo_world);
            let u_lobe = sampler.next_1d_for(Domain::Bsdf);
            let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
            let u_select = sampler.next_1d_for(Domain::Light);
            let u_light = sampler.next_2d_for(Domain::Light);
            if bsdf.is_specular() {
                let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
                    break;
                };
                beta *= sample.weight;
                ray = hit.spawn_ray(frame.to_world(sample.wi));
                counts.bounce += 1;
                continue;
            }
            // Direct light: one light sample.
            if self.max_depth > 0
                && let Some(ls) = scene.lights.sample(hit.point, u_select, u_light)
            {
                let wi = frame.to_local(ls.wi);
                let f = bsdf.eval(wo, wi);
                if f.max_element() > 0.0 {
                    counts.shadow += 1;
                    let shadow = ray_between(
                        hit.point, hit.error, hit.normal, ls.point, ls.error, ls.normal,
                    )
                    .at_time(hit.time);
                    if !scene.geometry.occluded(&shadow) {
                        radiance += beta * f * ls.radiance * (wi.z.abs() / ls.pdf);
                    }
                }
            }
            // Everything after a bounce: the density estimate.
            let facing = if wo.z > 0.0 { hit.normal } else { -hit.normal };
            let mut sum = Rgb::ZERO;
            map.for_each_near(hit.point, facing, |p| {
                sum += bsdf.eval(wo, frame.to_local(p.wi)) * p.power;
            });
            radiance += beta * sum * map.normalisation;
            break;
        }
        radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_finds_exactly_the_photons_within_the_radius() {
        let mut photons = Vec::new();
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..5000 {
            photons.push(Photon {
                point: Vec3A::new(next(), next(), next()) * 3.0 - Vec3A::ONE,
                wi: Vec3A::Z,
                normal: Vec3A::Z,
                power: Rgb::ONE,
            });
        }
        let radius = 0.13;
        let map = PhotonMap::build(photons.clone(), radius, 5000);
        for _ in 0..200 {
            let q = Vec3A::new(next(), next(), next()) * 3.0 - Vec3A::ONE;
            let mut found = 0;
            map.for_each_near(q, Vec3A::Z, |_| found += 1);
            let expected = photons
                .iter()
                .filter(|p| (p.point - q).length_squared() <= radius * radius)
                .count();
            assert_eq!(found, expected, "at {q:?}");
        }
    }

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
