//! Vertex connection and merging (Georgiev, Křivánek, Davidovič & Slusallek
//! 2012; Hachisuka, Pantaleoni & Jensen's unified path sampling is the same
//! idea): bidirectional path tracing and photon mapping combined by
//! multiple importance sampling. Every iteration:
//!
//! 1. traces N light subpaths (one per pixel), splats each vertex seen by
//!    the camera (t = 1) and keeps the non-specular vertices in a hash grid;
//! 2. traces one camera subpath per pixel; at each non-specular vertex it
//!    samples a light (s = 1), connects to every vertex of the light subpath
//!    of its own pixel, and merges with every light vertex within the
//!    iteration's radius (a photon-map lookup, as in SPPM); a camera
//!    subpath that hits a light counts too (s = 0).
//!
//! A merge is a connection whose last segment was not traced but accepted
//! with probability pi r^2 p(x): its density is the connection's times
//! eta = N pi r^2, which is how the two kinds of strategy are weighed. The
//! weights use Georgiev et al.'s recursive quantities dVCM, dVC and dVM
//! (their technical report, "Implementing vertex connection and merging"),
//! kept per subpath vertex in three floats, so that a light vertex in the
//! grid carries what its merges need without its subpath. Densities of
//! Russian roulette are left out of the weights (they only have to sum to
//! one), and light sampling is weighed with the area density of the light
//! point, as in `bdpt`.
//!
//! The radius shrinks as in SPPM, r_i^2 = r_1^2 i^(alpha - 1), so the
//! merges' bias goes to zero. Light and camera subpaths of an iteration see
//! the scene at the shutter's opening, as the photon mappers do.

use super::light::{importance_weight, sample_particle};
use super::photon_map::{self, PARTICLE_CHUNK, PhotonMap, concat};
use super::{MisHeuristic, MultiPassEstimator, PathLength, RayCounts, Settings, Technique};
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::film::splats::{self, PendingSplats, SplatBuffer};
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domain, Sampler, SamplerKind};
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use std::f32::consts::PI;
use strategies::CameraVertex;

mod strategies;
mod vertex;

use vertex::{LightVertex, MergeVertex, pack_shading};

/// Light subpaths per iteration at most: past it, pixels share them (a
/// camera subpath connects to the light subpath of its pixel index modulo
/// this), which bounds the vertices kept per iteration (about 190 bytes
/// each, with their merge copy and grid).
pub const MAX_LIGHT_PATHS: u32 = 1 << 20;

/// Settings of vertex connection and merging.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct VcmSettings {
    #[serde(flatten)]
    pub length: PathLength,
    /// How the strategies combine (`None` reads as power).
    pub mis: MisHeuristic,
    /// The first iteration's merge radius, a fraction of the scene's diagonal.
    pub radius: f32,
    /// r_i^2 = r_1^2 i^(alpha - 1): 0 < alpha <= 1.
    pub alpha: f32,
}

impl Default for VcmSettings {
    fn default() -> Self {
        VcmSettings {
            length: PathLength::default(),
            mis: MisHeuristic::Power,
            radius: 0.002,
            alpha: 2.0 / 3.0,
        }
    }
}

impl Settings for VcmSettings {
    fn validate(&self) -> Result<(), String> {
        self.length.check()?;
        super::sppm::check_radius(self.radius, self.alpha)
    }

    fn length_mut(&mut self) -> Option<&mut PathLength> {
        Some(&mut self.length)
    }

    fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
        Some(&mut self.mis)
    }
}

/// Vertex connection and merging.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vcm {
    /// Bounces of a full path, as for path tracing.
    pub max_depth: u32,
    /// Roulette on both subpaths after this many bounces of each.
    pub rr_depth: u32,
    pub russian_roulette: bool,
    /// How the strategies are combined (balance or power).
    pub mis: MisHeuristic,
    /// Merge radius of the first iteration: a fraction of the scene's
    /// diagonal until [`Technique::for_scene`] makes it scene units.
    pub radius: f32,
    /// How fast the radius shrinks: r_i^2 = r_1^2 i^(alpha - 1).
    pub alpha: f32,
    /// The first radius in pixels at the median first hit, once
    /// [`Technique::for_scene`] has seen the scene (for the summary).
    pub radius_pixels: Option<f32>,
    /// The frame's width in pixels, with `radius_pixels`.
    pub frame_width: u32,
}

impl Default for Vcm {
    fn default() -> Self {
        Vcm {
            max_depth: 8,
            rr_depth: 5,
            russian_roulette: true,
            mis: MisHeuristic::Power,
            radius: 0.002,
            alpha: 2.0 / 3.0,
            radius_pixels: None,
            frame_width: 0,
        }
    }
}

impl Technique for Vcm {
    const SUMMARY: &'static str = "Vertex connection and merging: bidirectional path tracing and \
         progressive photon mapping in one estimator, every strategy weighted by multiple \
         importance sampling.";

    type Settings = VcmSettings;

    fn new(settings: &VcmSettings) -> Self {
        Vcm {
            // Light vertices count their segments in 16 bits; roulette
            // ends paths thousands of segments before.
            max_depth: settings.length.max_depth.min(u32::from(u16::MAX) - 1),
            rr_depth: settings.length.rr_depth,
            russian_roulette: settings.length.russian_roulette,
            mis: super::options::combining(settings.mis),
            radius: settings.radius,
            alpha: settings.alpha,
            radius_pixels: None,
            frame_width: 0,
        }
    }

    fn describe(&self) -> String {
        format!(
            "vcm (max depth {}, mis {:?}, radius {:.3e}{}, alpha {:.2}, rr {})",
            super::options::depth_label(self.max_depth),
            self.mis,
            self.radius,
            photon_map::describe_radius_in_pixels(self.frame_width, self.radius_pixels),
            self.alpha,
            if self.russian_roulette {
                format!("from {}", self.rr_depth)
            } else {
                "off".into()
            }
        )
    }

    fn for_scene(self, scene: &Scene) -> Self {
        let radius = photon_map::of_diagonal(scene, self.radius);
        Vcm {
            radius,
            radius_pixels: photon_map::pixel_footprint(scene).map(|w| radius / w),
            frame_width: scene.camera.width,
            ..self
        }
    }
}

/// One iteration: the light subpaths' vertices (those of subpath i are
/// `vertices[starts[i]..starts[i + 1]]`), their grid, the splats of the
/// light vertices the camera sees, and the iteration's MIS constants.
pub struct Iteration {
    starts: Vec<u32>,
    vertices: Vec<LightVertex>,
    map: PhotonMap<MergeVertex>,
    light_image: SplatBuffer,
    paths: u32,
    radius: f32,
    /// mis(eta) and mis(1 / eta), eta = N pi r^2.
    vm_factor: f32,
    vc_factor: f32,
    time: f32,
}

/// What a subpath carries between vertices: its weight and the recursive
/// MIS quantities.
#[derive(Clone, Copy)]
struct Walk {
    beta: Rgb,
    /// beta relative to where the subpath started, without the radiance
    /// scaling of refraction: what roulette reads (as in `bdpt`).
    relative: Rgb,
    d_vcm: f32,
    d_vc: f32,
    d_vm: f32,
}

/// One scattering event at a surface, from the sampled BSDF.
struct Scatter {
    wi: Vec3A,
    pdf: f32,
    pdf_reverse: f32,
    specular: bool,
    cos: f32,
}

impl Vcm {
    #[inline]
    fn mis(&self, x: f32) -> f32 {
        match self.mis {
            MisHeuristic::Balance => x,
            _ => x * x,
        }
    }

    /// The radius of iteration `pass` (0, 1, ...).
    pub fn radius_at(&self, pass: u32) -> f32 {
        self.radius * ((pass + 1) as f32).powf((self.alpha - 1.0) * 0.5)
    }

    /// Bytes an iteration holds besides the film: its splat buffer and the
    /// light vertices with their grid, for the typical four stored vertices
    /// per light subpath (roulette ends most before the depth limit).
    pub fn memory_per_iteration(scene: &Scene, threads: usize) -> u64 {
        let pixels = u64::from(scene.camera.width) * u64::from(scene.camera.height);
        let light_image = splats::SPLAT_BYTES * splats::shard_count(pixels, threads) as u64;
        let per_vertex = (std::mem::size_of::<LightVertex>()
            + std::mem::size_of::<MergeVertex>()
            + std::mem::size_of::<Vec3>()
            + 4) as u64;
        pixels * light_image + u64::from(Self::light_paths(scene)) * (4 * per_vertex + 4)
    }

    /// The light subpaths of an iteration: as many as pixels, at most
    /// [`MAX_LIGHT_PATHS`].
    pub fn light_paths(scene: &Scene) -> u32 {
        (scene.camera.width * scene.camera.height).clamp(1, MAX_LIGHT_PATHS)
    }

    /// The next surface along `ray`, with the walk's quantities moved to it:
    /// from the previous vertex's solid angle into this one's area (the
    /// distance squared over the |cos| of arrival; the cosine alone where
    /// the ray left a light at infinity, `parallel`, by area already).
    #[inline]
    fn advance(
        &self,
        scene: &Scene,
        ray: &Ray,
        parallel: bool,
        walk: &mut Walk,
    ) -> Option<SurfaceHit> {
        let hit = scene.geometry.intersect(ray)?;
        let c = self.mis(hit.normal.dot(ray.direction).abs());
        if !parallel {
            walk.d_vcm *= self.mis((hit.point - ray.origin).length_squared());
        }
        walk.d_vcm /= c;
        walk.d_vc /= c;
        walk.d_vm /= c;
        Some(hit)
    }

    /// Leaving a surface by `scatter`: the update of Georgiev et al.'s
    /// quantities (their report, eqs. 34-38 in ratio form).
    #[inline]
    fn leave(&self, walk: &mut Walk, scatter: &Scatter, iteration: &Iteration) {
        if scatter.specular {
            walk.d_vcm = 0.0;
            walk.d_vc *= self.mis(scatter.cos);
            walk.d_vm *= self.mis(scatter.cos);
        } else {
            let g = self.mis(scatter.cos / scatter.pdf);
            let reverse = self.mis(scatter.pdf_reverse);
            walk.d_vc = g * (walk.d_vc * reverse + walk.d_vcm + iteration.vm_factor);
            walk.d_vm = g * (walk.d_vm * reverse + walk.d_vcm * iteration.vc_factor + 1.0);
            walk.d_vcm = self.mis(1.0 / scatter.pdf);
        }
    }

    /// Samples the BSDF at `frame` for `wo` (local); roulette after
    /// `bounces` bounces. `None` ends the subpath.
    #[allow(clippy::too_many_arguments)]
    fn scatter(
        &self,
        bsdf: Bsdf,
        wo: Vec3A,
        ng: Vec3A,
        importance: bool,
        bounces: u32,
        walk: &mut Walk,
        sampler: &mut Sampler,
    ) -> Option<Scatter> {
        let u_lobe = sampler.next_1d_for(Domain::Bsdf);
        let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
        let u_roulette = sampler.next_1d_for(Domain::Other);
        let sample = bsdf.sample(wo, u_lobe, u_bsdf)?;
        let weight = if importance {
            importance_weight(bsdf, wo, sample.wi, ng, sample.weight)
        } else {
            walk.relative /= bsdf.refraction_scale(wo, sample.wi);
            sample.weight
        };
        walk.beta *= weight;
        walk.relative *= weight;
        if self.russian_roulette && bounces > self.rr_depth {
            let q = walk.relative.max_element().min(1.0);
            if u_roulette >= q {
                return None;
            }
            walk.beta /= q;
            walk.relative /= q;
        }
        if !(walk.beta.max_element() > 0.0) {
            return None;
        }
        let (pdf, pdf_reverse) = if sample.specular {
            (1.0, 1.0)
        } else {
            (sample.pdf, bsdf.pdf(sample.wi, wo))
        };
        Some(Scatter {
            wi: sample.wi,
            pdf,
            pdf_reverse,
            specular: sample.specular,
            // The densities' conversions to area take the geometric cosine.
            cos: sample.wi.dot(ng).abs(),
        })
    }

    /// Traces light subpath `index`: its non-specular vertices go to
    /// `vertices`, the camera's view of each to `light_image`.
    #[allow(clippy::too_many_arguments)]
    fn trace_light_path(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        vertices: &mut Vec<LightVertex>,
        splats: &mut PendingSplats,
    ) {
        let Some(emission) = sample_particle(scene, sampler) else {
            return;
        };
        // From infinity the particle starts on a disc facing the scene
        // (normal = direction): light sampling picks its direction alone,
        // with the density of the disc's point divided out (SmallVCM).
        let infinite = scene.lights.is_infinite(emission.light);
        let delta_light =
            emission.normal == Vec3A::ZERO || scene.lights.is_directional(emission.light);
        let cos_light = if delta_light {
            1.0
        } else {
            emission.normal.dot(emission.direction).abs()
        };
        let emission_pdf = emission.pdf_position * emission.pdf_direction;
        let d_vc = if delta_light {
            0.0
        } else {
            self.mis(cos_light / emission_pdf)
        };
        let d_vcm = if infinite {
            self.mis(1.0 / scene.lights.disc_density(emission.light))
        } else {
            self.mis(1.0 / emission.pdf_direction)
        };
        let mut walk = Walk {
            beta: emission.throughput,
            relative: Rgb::ONE,
            d_vcm,
            d_vc,
            d_vm: d_vc * iteration.vc_factor,
        };
        if !delta_light && !infinite {
            self.light_point_to_camera(scene, iteration, &emission, sampler, counts, splats);
        }
        let mut ray = emission.ray().at_time(iteration.time);
        counts.bounce += 1;
        for segments in 1..=self.max_depth {
            // The disc's density by area is the hit's up to the cosine.
            let parallel = infinite && segments == 1;
            let Some(hit) = self.advance(scene, &ray, parallel, &mut walk) else {
                break;
            };
            let wo_world = -ray.direction;
            let bsdf = scene.bsdf_at(&hit);
            if bsdf.is_black() {
                break;
            }
            let frame = scene.shading_frame(&hit);
            let shading = frame.n;
            if !bsdf.is_specular() {
                let vertex = LightVertex {
                    point: hit.point,
                    error: hit.error,
                    normal: hit.normal,
                    packed_shading: pack_shading(shading, hit.normal),
                    wo: wo_world,
                    beta: walk.beta,
                    material: hit.material,
                    uv: scene.geometry.uv(&hit),
                    segments: segments as u16,
                    turn: scene.shading_turn(&hit, shading),
                    d_vcm: walk.d_vcm,
                    d_vc: walk.d_vc,
                    d_vm: walk.d_vm,
                };
                self.connect_to_camera(scene, iteration, &vertex, sampler, counts, splats);
                vertices.push(vertex);
            }
            if segments == self.max_depth {
                break;
            }
            let Some(scatter) = self.scatter(
                bsdf,
                frame.to_local(wo_world),
                normal_in(&frame, hit.normal, shading),
                true,
                segments,
                &mut walk,
                sampler,
            ) else {
                break;
            };
            self.leave(&mut walk, &scatter, iteration);
            ray = hit.spawn_ray(frame.to_world(scatter.wi));
            counts.bounce += 1;
        }
    }
}

impl MultiPassEstimator for Vcm {
    type Pass = Iteration;

    fn prepare(
        &self,
        scene: &Scene,
        pass: u32,
        seed: u64,
        sampler: SamplerKind,
        counts: &mut RayCounts,
    ) -> Iteration {
        let paths = Self::light_paths(scene);
        let radius = self.radius_at(pass);
        let eta = paths as f32 * PI * radius * radius;
        let mut iteration = Iteration {
            starts: Vec::new(),
            vertices: Vec::new(),
            map: PhotonMap::build(Vec::new(), radius),
            light_image: SplatBuffer::with_filter(
                scene.camera.width,
                scene.camera.height,
                scene.camera.filter,
            ),
            paths,
            radius,
            vm_factor: self.mis(eta),
            vc_factor: self.mis(1.0 / eta),
            time: scene.camera.shutter_open,
        };
        let key = hash_combine(hash_combine(seed, u64::from(pass)), 0x56_434d);
        // With Sobol the light paths are particles of one net over the
        // render (as BDPT's), otherwise independent per (seed, pass).
        let sobol = sampler == SamplerKind::Sobol;
        let chunks: Vec<(Vec<LightVertex>, Vec<u32>, RayCounts)> = (0..paths
            .div_ceil(PARTICLE_CHUNK))
            .into_par_iter()
            .map(|chunk| {
                let mut sampler = match sobol {
                    true => Sampler::new(SamplerKind::Sobol, seed, 0),
                    false => Sampler::new(SamplerKind::Independent, key, 0),
                };
                let mut vertices = Vec::new();
                let mut ends = Vec::new();
                let mut rays = RayCounts::default();
                let mut splats = PendingSplats::new();
                for index in chunk * PARTICLE_CHUNK..((chunk + 1) * PARTICLE_CHUNK).min(paths) {
                    if sobol {
                        sampler.start(index, pass);
                        sampler.start_particle(paths);
                    } else {
                        sampler.start(index, 0);
                    }
                    self.trace_light_path(
                        scene,
                        &iteration,
                        &mut sampler,
                        &mut rays,
                        &mut vertices,
                        &mut splats,
                    );
                    splats.flush(&iteration.light_image);
                    ends.push(vertices.len() as u32);
                }
                (vertices, ends, rays)
            })
            .collect();
        let mut starts = Vec::with_capacity(paths as usize + 1);
        starts.push(0);
        let mut offset = 0;
        for (chunk, ends, rays) in &chunks {
            starts.extend(ends.iter().map(|e| e + offset));
            offset += chunk.len() as u32;
            counts.bounce += rays.bounce;
            counts.shadow += rays.shadow;
        }
        let vertices = concat(&chunks.iter().map(|c| c.0.as_slice()).collect::<Vec<_>>());
        // Freed before the map is built: two copies of the light vertices at
        // most, not three.
        drop(chunks);
        iteration.starts = starts;
        iteration.map = PhotonMap::converted(&vertices, radius, |v| MergeVertex::from(v));
        iteration.vertices = vertices;
        iteration
    }

    fn radiance(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        ray: Ray,
        (x, y): (u32, u32),
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let camera = &scene.camera;
        let pixel = y * camera.width + x;
        let splatted = Rgb::from_array(
            iteration
                .light_image
                .get(pixel)
                .map(|v| (v / f64::from(iteration.paths)) as f32),
        );
        let subpath = pixel % iteration.paths;
        let light_path = iteration.starts[subpath as usize] as usize
            ..iteration.starts[subpath as usize + 1] as usize;
        let mut ray = ray.at_time(iteration.time);
        let pixels = (camera.width * camera.height) as f32;
        let camera_pdf = camera.pdf_direction(ray.direction) * pixels;
        let mut walk = Walk {
            beta: Rgb::ONE,
            relative: Rgb::ONE,
            d_vcm: self.mis(iteration.paths as f32 / camera_pdf),
            d_vc: 0.0,
            d_vm: 0.0,
        };
        let normalisation =
            1.0 / (PI * iteration.radius * iteration.radius * iteration.paths as f32);
        let mut radiance = Rgb::ZERO;
        for segments in 1..=self.max_depth + 1 {
            let Some(hit) = self.advance(scene, &ray, false, &mut walk) else {
                radiance += walk.beta * self.environment(scene, &ray, segments, &walk);
                break;
            };
            // The merge's reads miss the cache: they are started now and
            // arrive while the light sample and the connections trace.
            iteration.map.prefetch_buckets(hit.point);
            let wo_world = -ray.direction;
            if hit.light != NO_LIGHT {
                let emitted = scene.emitted(&hit, wo_world);
                if emitted.max_element() > 0.0 {
                    // Against light sampling and every longer light subpath;
                    // seen directly, against the light point's splat.
                    let (pdf_position, pdf_direction) =
                        scene.lights.emission_pdf(hit.light, hit.normal, wo_world);
                    let w_camera = self.mis(pdf_position) * walk.d_vcm
                        + self.mis(pdf_position * pdf_direction) * walk.d_vc;
                    let weight = 1.0 / (1.0 + w_camera);
                    radiance += walk.beta * emitted * weight;
                }
            }
            let bsdf = scene.bsdf_at(&hit);
            if bsdf.is_black() || segments > self.max_depth {
                break;
            }
            let frame = scene.shading_frame(&hit);
            let shading = frame.n;
            let wo = frame.to_local(wo_world);
            let at = CameraVertex {
                point: hit.point,
                error: hit.error,
                normal: hit.normal,
                ng: normal_in(&frame, hit.normal, shading),
                frame,
                wo,
                bsdf,
                segments,
            };
            if !bsdf.is_specular() {
                radiance +=
                    walk.beta * self.light_sample(scene, iteration, &at, &walk, sampler, counts);
                iteration.map.prefetch_entries(at.point);
                for light in &iteration.vertices[light_path.clone()] {
                    if u32::from(light.segments) + segments <= self.max_depth {
                        radiance +=
                            walk.beta * self.connect(scene, iteration, &at, &walk, light, counts);
                    }
                }
                let merged = self.merge(iteration, &at, &walk);
                radiance += walk.beta * merged * normalisation;
            }
            let Some(scatter) = self.scatter(bsdf, wo, at.ng, false, segments, &mut walk, sampler)
            else {
                break;
            };
            self.leave(&mut walk, &scatter, iteration);
            ray = hit.spawn_ray(frame.to_world(scatter.wi));
            counts.bounce += 1;
        }
        radiance + splatted
    }
}

impl Vcm {
    /// s = 0 at infinity: the environment where the camera subpath leaves
    /// the scene, weighed against light sampling and the light subpaths
    /// that start on the disc facing it; seen directly, nothing else could
    /// have made it.
    fn environment(&self, scene: &Scene, ray: &Ray, segments: u32, walk: &Walk) -> Rgb {
        let Some(env) = scene.lights.environment() else {
            return Rgb::ZERO;
        };
        let towards = env.towards(ray.direction);
        let le = env.le_towards(towards);
        if segments == 1 {
            return le;
        }
        let direct = scene.lights.environment_pdf_as_emitted_towards(towards);
        let (pdf_position, pdf_direction) =
            scene
                .lights
                .emission_pdf(scene.lights.environment_id(), Vec3A::ZERO, -ray.direction);
        let w_camera =
            self.mis(direct) * walk.d_vcm + self.mis(pdf_position * pdf_direction) * walk.d_vc;
        le / (1.0 + w_camera)
    }
}

/// The geometric normal `ng` in `frame` (the shading normal `ns`'s): exactly
/// +z where the two are one, so that the adjoint's correction is exactly 1.
#[inline]
fn normal_in(frame: &Frame, ng: Vec3A, ns: Vec3A) -> Vec3A {
    if ng == ns {
        Vec3A::Z
    } else {
        frame.to_local(ng)
    }
}
