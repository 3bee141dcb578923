//! Photons and the map that finds them (`grid.rs`), shared by the photon
//! mappers (`photon.rs`, Jensen's two-pass method; `sppm.rs`, progressive)
//! and by vertex connection and merging (`vcm/`, for its light vertices).

mod grid;
mod sort;

pub use grid::{MAX_K, PhotonMap, Side, Stored};

use super::RayCounts;
use super::light::importance_weight;
use super::mis::MisHeuristic;
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domain, Sampler, SamplerKind};
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::{Vec2, Vec3A};
use rayon::prelude::*;

/// A photon: where it landed, where it came from, and what it carries.
#[derive(Clone, Copy, Debug)]
pub struct Photon {
    pub point: Vec3A,
    /// Unit direction back towards where the photon came from.
    pub wi: Vec3A,
    /// The surface's normal on the side the photon arrived, so that photons
    /// on the far side of a thin wall do not count.
    pub normal: Vec3A,
    /// Its weight (flux) after N photons were shot: divide by N.
    pub power: Rgb,
    /// Bounces since the light (0: straight from it), so that a lookup
    /// keeps the paths within the depth.
    pub bounces: u32,
}

// 80 bytes: packed in 64 with the normal unaligned (a Vec3 beside the
// bounces), Jensen's lookups took 30% longer on the Cornell box.
const _: () = assert!(std::mem::size_of::<Photon>() == 80);

/// How a photon got where it is: bounces since the light, and whether
/// every one of them was specular (a caustic photon, L S+ D).
#[derive(Clone, Copy, Debug)]
pub struct PhotonPath {
    pub bounces: u32,
    pub specular_only: bool,
}

impl Stored for Photon {
    #[inline]
    fn position(&self) -> Vec3A {
        self.point
    }
    #[inline]
    fn facing(&self) -> Vec3A {
        self.normal
    }
}

/// `fraction` of the scene's bounding-box diagonal, in scene units (the
/// fraction itself where the scene has no finite size), so that radii do
/// not depend on the scene's units.
pub fn of_diagonal(scene: &Scene, fraction: f32) -> f32 {
    let bounds = scene.geometry.bounds();
    let diagonal = (bounds.max - bounds.min).length();
    if diagonal.is_finite() && diagonal > 0.0 {
        fraction * diagonal
    } else {
        fraction
    }
}

/// The width of one pixel at the camera's median first hit (8 × 8 rays
/// through pixel centres), in scene units; `None` where no ray hits.
pub fn pixel_footprint(scene: &Scene) -> Option<f32> {
    const GRID: u32 = 8;
    let camera = &scene.camera;
    let mut widths = Vec::with_capacity((GRID * GRID) as usize);
    for k in 0..GRID * GRID {
        let film = Vec2::new(
            ((k % GRID) as f32 + 0.5) * camera.width as f32 / GRID as f32,
            ((k / GRID) as f32 + 0.5) * camera.height as f32 / GRID as f32,
        );
        let ray = camera.generate_ray(film, Vec2::splat(0.5));
        let next = camera.generate_ray(film + Vec2::X, Vec2::splat(0.5));
        if let Some(hit) = scene.geometry.intersect(&ray) {
            // The angle between neighbouring pixels' rays, times the distance.
            widths.push(hit.t * (next.direction - ray.direction).length());
        }
    }
    widths.sort_by(f32::total_cmp);
    widths.get(widths.len() / 2).copied()
}

/// " (about N pixels at the median first hit)", and a warning where the
/// radius covers more than an eighth of the frame: merging then blurs what
/// the camera sees (a narrow spot's footprint seen close up lost 96% of
/// its light in VCM at the default radius).
pub fn describe_radius_in_pixels(scene_width: u32, radius_pixels: Option<f32>) -> String {
    match radius_pixels {
        Some(n) if n > scene_width as f32 / 8.0 => format!(
            " (about {n:.0} pixels at the median first hit: more than an eighth of the \
             frame, so merging blurs what is in view; a smaller --radius fits this view)"
        ),
        Some(n) => format!(" (about {n:.1} pixels at the median first hit)"),
        None => String::new(),
    }
}

/// The photons to shoot per iteration: `photons`, or one per pixel for 0.
pub fn photons_per_iteration(scene: &Scene, photons: u32) -> u32 {
    if photons == 0 {
        scene.camera.width * scene.camera.height
    } else {
        photons
    }
}

/// Says how many photons an iteration shoots, for summaries.
pub fn describe_photons(photons: u32) -> String {
    if photons == 0 {
        "one per pixel".to_string()
    } else {
        photons.to_string()
    }
}

/// Shoots `count` photons (randomness from `key` and each photon's index,
/// so the maps do not depend on the schedule), following each for up to
/// `max_bounces` bounces, and sorts the photons that land on non-specular
/// surfaces into two lists by `keep`: (first list, second list).
pub fn shoot(
    scene: &Scene,
    count: u32,
    key: u64,
    max_bounces: u32,
    keep: impl Fn(PhotonPath) -> (bool, bool) + Sync,
    counts: &mut RayCounts,
) -> (Vec<Photon>, Vec<Photon>) {
    let chunks = count.div_ceil(PARTICLE_CHUNK);
    let key = hash_combine(key, 0x5048_4f54_4f4e);
    let results: Vec<(Vec<Photon>, Vec<Photon>, u64)> = (0..chunks)
        .into_par_iter()
        .map(|chunk| {
            let mut sampler = Sampler::new(SamplerKind::Independent, key, 0);
            let (mut first, mut second) = (Vec::new(), Vec::new());
            let mut rays = RayCounts::default();
            let end = ((chunk + 1) * PARTICLE_CHUNK).min(count);
            for index in chunk * PARTICLE_CHUNK..end {
                sampler.start(index, 0);
                trace_photon(
                    scene,
                    &mut sampler,
                    max_bounces,
                    &mut rays,
                    |photon, path| {
                        let (a, b) = keep(path);
                        if a {
                            first.push(photon);
                        }
                        if b {
                            second.push(photon);
                        }
                    },
                );
            }
            (first, second, rays.bounce)
        })
        .collect();
    counts.bounce += results.iter().map(|r| r.2).sum::<u64>();
    let first = concat(&results.iter().map(|r| r.0.as_slice()).collect::<Vec<_>>());
    let second = concat(&results.iter().map(|r| r.1.as_slice()).collect::<Vec<_>>());
    (first, second)
}

/// Particles (photons, VCM's light paths) traced per parallel task: small
/// enough that the last tasks of a pass leave few of 16 threads idle, large
/// enough that a task's set-up is nothing beside its paths.
pub(crate) const PARTICLE_CHUNK: u32 = 1024;

/// The parts one after another, copied in parallel: at 16 threads a serial
/// copy of a pass's photons or light vertices would be a large share of the
/// pass.
pub(crate) fn concat<T: Copy + Send + Sync>(parts: &[&[T]]) -> Vec<T> {
    let total = parts.iter().map(|p| p.len()).sum();
    let mut out = Vec::with_capacity(total);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let mut places = Vec::with_capacity(parts.len());
    for part in parts {
        let (place, tail) = rest.split_at_mut(part.len());
        places.push(place);
        rest = tail;
    }
    places.into_par_iter().zip(parts).for_each(|(place, part)| {
        for (slot, &item) in place.iter_mut().zip(part.iter()) {
            slot.write(item);
        }
    });
    // SAFETY: the places cover the first `total` slots, each written above.
    unsafe { out.set_len(total) };
    out
}

/// Traces one photon from the lights and hands every landing on a
/// non-specular surface to `store`, with how it got there.
fn trace_photon(
    scene: &Scene,
    sampler: &mut Sampler,
    max_bounces: u32,
    counts: &mut RayCounts,
    mut store: impl FnMut(Photon, PhotonPath),
) {
    let Some(emission) = super::light::sample_particle(scene, sampler) else {
        return;
    };
    let roulette_scale = 1.0 / emission.throughput.max_element();
    let mut beta = emission.throughput;
    let mut ray = emission.ray().at_time(scene.camera.shutter_open);
    counts.bounce += 1;
    let mut specular_only = true;
    for bounces in 0..=max_bounces {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            break;
        };
        let bsdf = scene.bsdf_at(&hit);
        if bsdf.is_black() {
            break;
        }
        let frame = scene.shading_frame(&hit);
        let ng = frame.to_local(hit.normal);
        let wo = frame.to_local(-ray.direction);
        let u_lobe = sampler.next_1d_for(Domain::Bsdf);
        let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
        let u_roulette = sampler.next_1d();
        if !bsdf.is_specular() {
            let facing = if hit.normal.dot(ray.direction) < 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            store(
                Photon {
                    point: hit.point,
                    wi: -ray.direction,
                    power: beta,
                    normal: facing,
                    bounces,
                },
                PhotonPath {
                    bounces,
                    specular_only,
                },
            );
            specular_only = false;
        }
        if bounces == max_bounces {
            break;
        }
        let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
            break;
        };
        beta *= importance_weight(bsdf, wo, sample.wi, ng, sample.weight);
        // Roulette from the first bounce: a photon is cheap and the map
        // only needs its density right.
        if !super::survives_roulette(&mut beta, roulette_scale, u_roulette) {
            break;
        }
        ray = hit.spawn_ray(frame.to_world(sample.wi));
        counts.bounce += 1;
    }
}

/// Where a camera ray of a photon mapper is estimated: its first hit on a
/// surface with a diffuse part ([`Bsdf::gathers_photons`]).
pub struct DiffuseHit {
    pub hit: SurfaceHit,
    /// The weight of the chain of mirrors, glass and glossy surfaces
    /// before it.
    pub beta: Rgb,
    /// The bounces of that chain.
    pub bounces: u32,
    pub bsdf: Bsdf,
    pub frame: Frame,
    /// Direction to the camera side, local.
    pub wo: Vec3A,
    /// The normal on the side the ray arrived from.
    pub facing: Vec3A,
    /// Random numbers for a BSDF sample at the hit.
    pub u_lobe: f32,
    pub u_bsdf: Vec2,
}

/// Follows a camera ray by sampling the surfaces that do not gather
/// photons (a chain of at most `max_depth` bounces) to its first one that
/// does; returns the light found on the way and the hit, if the ray got
/// there. On a glossy surface of the chain direct light is a light sample
/// and the light its BSDF sample finds, weighed against each other by the
/// power heuristic, as in path tracing.
pub fn camera_to_diffuse(
    scene: &Scene,
    mut ray: Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    counts: &mut RayCounts,
) -> (Rgb, Option<DiffuseHit>) {
    let mut beta = Rgb::ONE;
    let mut emitted = Rgb::ZERO;
    // The density and origin of the glossy sample that led here; None
    // after the camera or a Dirac bounce, where no light sample competes.
    let mut glossy: Option<(f32, Vec3A)> = None;
    for bounces in 0..=max_depth {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            if let Some(env) = scene.lights.environment() {
                let towards = env.towards(ray.direction);
                let weight =
                    found_light_weight(glossy, |_| scene.lights.environment_pdf_towards(towards));
                emitted += beta * env.le_towards(towards) * weight;
            }
            break;
        };
        let wo_world = -ray.direction;
        if hit.light != NO_LIGHT {
            let weight = found_light_weight(glossy, |from| {
                (scene.lights).pdf(hit.light, from, hit.point, hit.normal)
            });
            emitted += beta * scene.emitted(&hit, wo_world) * weight;
        }
        let bsdf = scene.bsdf_at(&hit);
        if bsdf.is_black() {
            break;
        }
        let frame = scene.shading_frame(&hit);
        let wo = frame.to_local(wo_world);
        let u_lobe = sampler.next_1d_for(Domain::Bsdf);
        let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
        // A smooth coating over the surface (plastic) is followed as a
        // Dirac bounce as often as the BSDF picks it; otherwise the
        // surface gathers, both divided by their probabilities.
        let coat = bsdf.delta_probability(wo);
        if bsdf.gathers_photons() && u_lobe >= coat {
            let facing = if hit.normal.dot(wo_world) > 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            let diffuse = DiffuseHit {
                hit,
                beta: beta / (1.0 - coat),
                bounces,
                bsdf,
                frame,
                wo,
                facing,
                // What is left of the number, for a BSDF sample at the hit.
                u_lobe: (u_lobe - coat) / (1.0 - coat),
                u_bsdf,
            };
            return (emitted, Some(diffuse));
        }
        if bounces == max_depth {
            break;
        }
        if !bsdf.is_specular() && !bsdf.gathers_photons() {
            emitted += beta * light_sample(scene, &hit, &frame, &bsdf, wo, true, sampler, counts);
        }
        let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
            break;
        };
        beta *= sample.weight;
        glossy = (!sample.specular).then_some((sample.pdf, hit.point));
        ray = hit.spawn_ray(frame.to_world(sample.wi));
        counts.bounce += 1;
    }
    (emitted, None)
}

/// The weight of light that a camera chain found, against the light sample
/// at the glossy vertex `glossy` (its BSDF sample's density and point) that
/// could have found it with the density `light_pdf` gives from there.
#[inline(always)]
fn found_light_weight(glossy: Option<(f32, Vec3A)>, light_pdf: impl FnOnce(Vec3A) -> f32) -> f32 {
    glossy.map_or(1.0, |(pdf, from)| {
        MisHeuristic::Power.weight(pdf, light_pdf(from))
    })
}

/// One light sample's light reflected at `hit` towards `wo`; `weighed`
/// against the BSDF sample that could have found the same light (at a
/// glossy vertex of a camera chain), or alone (where the chain ends).
#[allow(clippy::too_many_arguments)]
fn light_sample(
    scene: &Scene,
    hit: &SurfaceHit,
    frame: &Frame,
    bsdf: &Bsdf,
    wo: Vec3A,
    weighed: bool,
    sampler: &mut Sampler,
    counts: &mut RayCounts,
) -> Rgb {
    let u_select = sampler.next_1d_for(Domain::Light);
    let u_light = sampler.next_2d_for(Domain::Light);
    let Some(ls) = scene.lights.sample(hit.point, u_select, u_light) else {
        return Rgb::ZERO;
    };
    let wi = frame.to_local(ls.wi);
    let f = bsdf.eval(wo, wi);
    if !(f.max_element() > 0.0) {
        return Rgb::ZERO;
    }
    counts.shadow += 1;
    if scene
        .geometry
        .occluded(&ls.shadow_ray_from(hit).at_time(hit.time))
    {
        return Rgb::ZERO;
    }
    let weight = match weighed && !ls.delta {
        true => MisHeuristic::Power.weight(ls.pdf, bsdf.pdf(wo, wi)),
        false => 1.0,
    };
    f * ls.radiance * (wi.z.abs() * weight / ls.pdf)
}

impl DiffuseHit {
    /// Direct light at the hit by one light sample (next-event
    /// estimation), times the chain's weight.
    pub fn direct_light(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let (hit, frame, bsdf) = (&self.hit, &self.frame, &self.bsdf);
        self.beta * light_sample(scene, hit, frame, bsdf, self.wo, false, sampler, counts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concat_keeps_every_part_in_order() {
        let parts: Vec<Vec<u32>> = vec![vec![], vec![1, 2, 3], vec![], vec![4], vec![5, 6]];
        let slices: Vec<&[u32]> = parts.iter().map(Vec::as_slice).collect();
        assert_eq!(concat(&slices), vec![1, 2, 3, 4, 5, 6]);
        assert!(concat::<u32>(&[]).is_empty());
    }
}
