//! Bidirectional path tracing (Veach 1997, ch. 10; Lafortune & Willems
//! 1993): per sample, a camera subpath z_0 .. z_{t-1} and a light subpath
//! y_0 .. y_{s-1}, and every way (s, t) of joining them into a full path:
//!
//! - s = 0: the camera subpath hits a light by itself;
//! - s = 1: its vertex z_{t-1} samples a point on a light (next-event
//!   estimation, with the path tracer's light sampling);
//! - t = 1: the light vertex y_{s-1} is connected to the lens and lands
//!   anywhere on the film (light tracing);
//! - otherwise y_{s-1} and z_{t-1} are joined by a shadow ray.
//!
//! A path of k bounces can be made by k + 2 strategies (fewer where a vertex
//! is specular, which no connection can reach); they are combined by
//! multiple importance sampling. The weight of strategy s is
//! 1 / sum_i (p_i / p_s)^beta, and the ratios p_i / p_s are walked vertex by
//! vertex from each subpath's stored forward and reverse densities (area
//! measure), which stays finite for long paths where products of densities
//! would not (the ratio walk of pbrt-v4's `MISWeight`; Georgiev's recursive
//! quantities compute the same sums). The weights only have to sum to one
//! over the strategies that can make a path, so strategy s = 1 is weighted
//! with the density of choosing its light point by area, as the light
//! subpath chooses it, even where light sampling picks it by solid angle.
//!
//! One light subpath per camera sample: over a pass of W x H pixels at n
//! samples each, the camera sees every pixel n times and the film receives
//! N = W H n light paths, so the film-wide camera density
//! ([`crate::camera::Camera::pdf_direction`]) is the right one to weigh
//! t = 1 against the others. Every contribution is a splat of the session's
//! splatting pass, which divides by N: a camera strategy's estimate for its
//! own pixel is multiplied by W H.
//!
//! [`BdptSettings::light_paths`] adds light subpaths (of a few bounces)
//! that only light tracing (t = 1) uses: with m of them in all, each t = 1
//! contribution of the paths they can make counts 1 / m, and its density
//! counts m times in every weight (Veach's multi-sample combination,
//! sum_i n_i p_i); light tracing's count noise falls m times for the
//! price of short subpaths and their lens connections alone.

use super::light::{sees_lens, shading_correction};
use super::{MisHeuristic, PathLength, RayCounts, Settings, Splat, SplattingEstimator, Technique};
use crate::accel::NO_LIGHT;
use crate::filter::PixelFilter;
use crate::math::{Rgb, ray_between};
use crate::sampling::Sampler;
use crate::scene::Scene;
use glam::{Vec2, Vec3A};
use std::cell::RefCell;

mod mis;
mod vertex;
mod walk;

use mis::light_direction_pdf;
use vertex::{Kind, Subpath, Vertex, emission_of, origin_density};

/// The deepest path bidirectional path tracing makes: subpaths live in
/// per-thread buffers of this capacity, so that a sample allocates nothing.
pub const MAX_BOUNCES: u32 = 32;
const MAX_VERTICES: usize = MAX_BOUNCES as usize + 2;

/// Settings of the bidirectional path tracer.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct BdptSettings {
    /// Depth at most [`MAX_BOUNCES`].
    #[serde(flatten)]
    pub length: PathLength,
    /// How the strategies combine (`None` reads as power).
    pub mis: MisHeuristic,
    /// Light subpaths per camera sample, 1 to [`MAX_LIGHT_PATHS`]: the
    /// first is joined to the camera subpath by every strategy, the others
    /// only to the lens (light tracing). More pay where light tracing
    /// carries the image and its particles are cheap (a lamp inside its
    /// shade); elsewhere they cost time for nothing.
    pub light_paths: u32,
    /// Bounces of the light subpaths after the first.
    pub light_path_bounces: u32,
}

/// The most light subpaths per camera sample.
pub const MAX_LIGHT_PATHS: u32 = 64;

impl Default for BdptSettings {
    fn default() -> Self {
        BdptSettings {
            length: PathLength::default(),
            mis: MisHeuristic::default(),
            light_paths: 1,
            light_path_bounces: 2,
        }
    }
}

impl Settings for BdptSettings {
    fn validate(&self) -> Result<(), String> {
        self.length.check()?;
        if !(1..=MAX_LIGHT_PATHS).contains(&self.light_paths) {
            return Err(format!(
                "light paths {} is not between 1 and {MAX_LIGHT_PATHS}",
                self.light_paths
            ));
        }
        if self.light_path_bounces > MAX_BOUNCES {
            return Err(format!(
                "light path bounces {} is more than bidirectional path tracing's {MAX_BOUNCES}",
                self.light_path_bounces
            ));
        }
        if self.length.max_depth > MAX_BOUNCES {
            return Err(format!(
                "max depth {} is more than bidirectional path tracing's {MAX_BOUNCES}",
                self.length.max_depth
            ));
        }
        Ok(())
    }

    fn deepest(&self) -> u32 {
        MAX_BOUNCES
    }

    fn length_mut(&mut self) -> Option<&mut PathLength> {
        Some(&mut self.length)
    }

    fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
        Some(&mut self.mis)
    }
}

/// The bidirectional path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bdpt {
    /// Bounces of a full path (1 = direct lighting), as for path tracing;
    /// at most [`MAX_BOUNCES`].
    pub max_depth: u32,
    /// Roulette on both subpaths after this many bounces of each.
    pub rr_depth: u32,
    pub russian_roulette: bool,
    /// How the strategies are combined (balance or power).
    pub mis: MisHeuristic,
    /// Light subpaths per camera sample: the first is joined to the camera
    /// subpath by every strategy, the others only to the lens (t = 1).
    pub light_paths: u32,
    /// The most vertices (the light point included) of those others.
    pub light_path_vertices: usize,
    /// For tests only: the strategy (s, t) whose MIS weight is replaced by
    /// 1, so that its paths are counted twice, as a bug would count them.
    pub faulty_strategy: Option<(u32, u32)>,
}

impl Default for Bdpt {
    fn default() -> Self {
        Bdpt {
            max_depth: 8,
            rr_depth: 5,
            russian_roulette: true,
            mis: MisHeuristic::Power,
            light_paths: 1,
            light_path_vertices: 3,
            faulty_strategy: None,
        }
    }
}

impl Technique for Bdpt {
    const SUMMARY: &'static str = "Bidirectional path tracing: camera and light subpaths joined by \
         every strategy, weighted by multiple importance sampling.";

    type Settings = BdptSettings;

    fn new(settings: &BdptSettings) -> Self {
        Bdpt {
            max_depth: settings.length.max_depth.min(MAX_BOUNCES),
            rr_depth: settings.length.rr_depth,
            russian_roulette: settings.length.russian_roulette,
            mis: super::options::combining(settings.mis),
            light_paths: settings.light_paths.clamp(1, MAX_LIGHT_PATHS),
            light_path_vertices: settings.light_path_bounces.min(MAX_BOUNCES) as usize + 1,
            faulty_strategy: None,
        }
    }

    fn describe(&self) -> String {
        let light_paths = if self.light_paths > 1 {
            format!(
                ", light paths {} ({} bounces)",
                self.light_paths,
                self.light_path_vertices - 1
            )
        } else {
            String::new()
        };
        format!(
            "bdpt (max depth {}, mis {:?}{light_paths}, rr {})",
            self.max_depth,
            self.mis,
            if self.russian_roulette {
                format!("from {}", self.rr_depth)
            } else {
                "off".into()
            }
        )
    }
}

thread_local! {
    /// The two subpaths of the sample being traced, kept per render thread
    /// so that a sample neither allocates nor clears kilobytes of stack
    /// (fixed arrays on the stack measured 5.7% of the time in memmove).
    static SUBPATHS: RefCell<(Subpath, Subpath)> = RefCell::new((
        Subpath::with_capacity(MAX_VERTICES),
        Subpath::with_capacity(MAX_VERTICES),
    ));
}

/// One contribution of one strategy: where it lands on the film, and its
/// value with and without the MIS weight (not yet divided by the number of
/// light paths of the pass).
#[derive(Clone, Copy, Debug)]
pub struct Contribution {
    pub s: u32,
    pub t: u32,
    pub film: Vec2,
    pub weighted: Rgb,
    pub unweighted: Rgb,
}

/// Which way a subpath carries its weight: radiance towards the camera
/// (refraction scales by (eta_i / eta_t)^2) or importance towards the lights
/// (it does not; Veach's thesis, 5.2).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Transport {
    Radiance,
    Importance,
}

impl SplattingEstimator for Bdpt {
    fn trace(
        &self,
        scene: &Scene,
        pixel: (u32, u32),
        camera_filter: PixelFilter,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        mut splat: impl FnMut(Splat),
    ) {
        // Every camera strategy (t > 1) lands on this sample's own pixel: one
        // splat of their sum instead of one atomic add each (8% of the time
        // on SmallVCM's scene went to those adds).
        let mut own_pixel = Rgb::ZERO;
        let film = self.trace_strategies(scene, pixel, camera_filter, sampler, counts, |c| {
            if c.t > 1 {
                own_pixel += c.weighted;
            } else {
                splat(Splat {
                    film: c.film,
                    value: c.weighted,
                    filtered: true,
                })
            }
        });
        // Even when black: splatted through the filter, its weight counts.
        splat(Splat {
            film,
            value: own_pixel,
            filtered: false,
        });
    }
}

impl Bdpt {
    /// Traces one sample of pixel `pixel`, its camera ray's film position
    /// drawn from `camera_filter`, and hands every strategy's contribution
    /// to `contribute` (the strategy images read them all; camera
    /// strategies land at the pixel's centre). Returns that film position.
    pub fn trace_strategies(
        &self,
        scene: &Scene,
        (x, y): (u32, u32),
        camera_filter: PixelFilter,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        mut contribute: impl FnMut(Contribution),
    ) -> Vec2 {
        let camera = &scene.camera;
        let (ray, camera_film) =
            super::camera_ray_through(scene, sampler, x, y, false, false, camera_filter);
        let time = ray.time;
        counts.camera += 1;
        let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        // A camera strategy's value is its pixel's estimate; the splat
        // buffer divides by W H n, the pixel's samples are n.
        let pixel_scale = camera.width as f32 * camera.height as f32;

        let max_depth = self.max_depth.min(MAX_BOUNCES) as usize;
        let mut subpaths = SUBPATHS.with(|cell| cell.take());
        let (camera_path, light_path) = &mut subpaths;
        camera_path.clear();
        light_path.clear();
        camera_path.push(Vertex {
            kind: Kind::Camera,
            point: ray.origin,
            beta: Rgb::ONE,
            pdf_fwd: 1.0,
            ..Vertex::EMPTY
        });
        let pdf_direction = camera.pdf_direction(ray.direction);
        self.random_walk(
            scene,
            ray,
            Rgb::ONE,
            pdf_direction,
            Transport::Radiance,
            max_depth + 2,
            sampler,
            counts,
            camera_path,
        );

        let pixels = camera.width * camera.height;
        let particles = self.light_paths.max(1);
        sampler.start_particle_of(pixels, 0, particles);
        self.light_subpath(scene, time, max_depth + 1, sampler, counts, light_path);

        self.prepare_mis(&mut camera_path.vertices, &mut light_path.vertices);
        let (cam, light) = (&*camera_path, &*light_path);
        for t in 1..=cam.len() {
            for s in 0..=light.len() {
                if s + t < 2 || s + t - 2 > max_depth {
                    continue;
                }
                let Some(joint) = self.connect(scene, cam, light, s, t, time, counts) else {
                    continue;
                };
                let weight = if self.faulty_strategy == Some((s as u32, t as u32)) {
                    1.0
                } else {
                    self.mis_weight(&cam.vertices, &light.vertices, s, t, &joint)
                };
                let value = joint.value;
                let (film, scale) = match joint.film {
                    Some(f) => (f, self.lens_share(s)),
                    None => (film, pixel_scale),
                };
                contribute(Contribution {
                    s: s as u32,
                    t: t as u32,
                    film,
                    weighted: value * (weight * scale),
                    unweighted: value * scale,
                });
            }
        }
        // The extra particles: light subpaths seen by the lens alone.
        for j in 1..particles {
            light_path.clear();
            sampler.start_particle_of(pixels, j, particles);
            let vertices = self.light_path_vertices.min(max_depth + 1);
            self.light_subpath(scene, time, vertices, sampler, counts, light_path);
            self.prepare_mis(&mut [], &mut light_path.vertices);
            for s in 1..=light_path.len().min(max_depth + 1) {
                let Some(joint) = self.connect(scene, camera_path, light_path, s, 1, time, counts)
                else {
                    continue;
                };
                let weight =
                    self.mis_weight(&camera_path.vertices, &light_path.vertices, s, 1, &joint);
                let scale = self.lens_share(s);
                contribute(Contribution {
                    s: s as u32,
                    t: 1,
                    film: joint.film.unwrap_or(film),
                    weighted: joint.value * (weight * scale),
                    unweighted: joint.value * scale,
                });
            }
        }
        SUBPATHS.with(|cell| cell.replace(subpaths));
        camera_film
    }

    /// What one light subpath's t = 1 contribution of s light vertices
    /// counts for: 1 / n where every one of the n particles makes that
    /// strategy, else 1.
    #[inline]
    fn lens_share(&self, s: usize) -> f32 {
        if self.light_paths > 1 && s <= self.light_path_vertices {
            1.0 / self.light_paths as f32
        } else {
            1.0
        }
    }

    /// Strategy (s, t) for this pair of subpaths: its unweighted value and
    /// what its MIS weight needs, or `None` where it contributes nothing.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &self,
        scene: &Scene,
        cam: &Subpath,
        light: &Subpath,
        s: usize,
        t: usize,
        time: f32,
        counts: &mut RayCounts,
    ) -> Option<Connection> {
        let (cam, cam_local) = (cam.vertices.as_slice(), cam.local.as_slice());
        let (light, light_local) = (light.vertices.as_slice(), light.local.as_slice());
        if s == 0 {
            // The camera subpath found a light by itself.
            let pt = &cam[t - 1];
            if pt.light == NO_LIGHT || !(pt.kind == Kind::Surface || pt.infinite) {
                return None;
            }
            let value = pt.beta * pt.emitted;
            if !(value.max_element() > 0.0) {
                return None;
            }
            let pm = &cam[t - 2];
            let pt_rev = if pt.infinite {
                origin_density(scene, pt.light, -pt.normal)
            } else {
                scene.lights.emission_pdf(pt.light, pt.normal, pt.wo).0
            };
            return Some(Connection {
                value,
                film: None,
                sampled_light: None,
                pt_rev,
                pt_minus_rev: light_direction_pdf(scene, pt, pm),
                qs_rev: 0.0,
                qs_minus_rev: 0.0,
            });
        }
        if t == 1 {
            // The light vertex seen by the camera: a splat where it lands.
            let qs = &light[s - 1];
            // A vertex connects if any of its lobes is not a delta, however
            // its own path went on (pbrt-v4's IsConnectible).
            // Nor is a point or spot light seen (no camera ray hits one).
            if (qs.kind == Kind::Surface && qs.bsdf.is_specular())
                || qs.infinite
                || (qs.kind == Kind::Light && qs.normal == Vec3A::ZERO)
            {
                return None;
            }
            let c = scene.camera.connect(qs.point, qs.u_connect)?;
            let (f, pdf_back) = qs.scatter(scene, c.wi, &light_local[s - 1]);
            let value = qs.beta * f * (qs.shading_cos(c.wi) * c.weight);
            if !(value.max_element() > 0.0)
                || !sees_lens::<false>(scene, qs.point, qs.error, qs.normal, &c, time, counts)
            {
                return None;
            }
            let lens = Vertex {
                kind: Kind::Camera,
                point: c.lens_point,
                ..Vertex::EMPTY
            };
            return Some(Connection {
                value,
                film: Some(c.film),
                qs_rev: lens.area_density_at(scene.camera.pdf_direction(-c.wi), qs),
                qs_minus_rev: pdf_back * light_local[s - 1].to_previous,
                // The lens point's own densities are never read.
                pt_rev: 0.0,
                pt_minus_rev: 0.0,
                sampled_light: None,
            });
        }
        let pt = &cam[t - 1];
        if pt.kind != Kind::Surface || pt.bsdf.is_specular() {
            return None;
        }
        let pl = &cam_local[t - 1];
        if s == 1 {
            // Next-event estimation from z_{t-1}. The environment's
            // radiance is looked up behind a clear shadow ray.
            let (mut ls, deferred) =
                scene
                    .lights
                    .sample_as_emitted_deferred(pt.point, pt.u_select, pt.u_connect)?;
            let (f, pdf_forward, pdf_reverse) =
                pt.bsdf.eval_with_pdfs(pl.wo, pl.frame.to_local(ls.wi));
            let beta_f = pt.beta * f;
            let scale = pl.shading_cos(ls.wi) / ls.pdf;
            if !((beta_f * ls.radiance * scale).max_element() > 0.0) {
                return None;
            }
            counts.shadow += 1;
            let shadow = ray_between(pt.point, pt.error, pt.normal, ls.point, ls.error, ls.normal)
                .at_time(time);
            if scene.geometry.occluded(&shadow) {
                return None;
            }
            ls.radiance = scene.lights.deferred_radiance(deferred, ls.radiance);
            let value = beta_f * ls.radiance * scale;
            if !(value.max_element() > 0.0) {
                return None;
            }
            let (pdf_position, pdf_emission) =
                scene.lights.emission_pdf(ls.light, ls.normal, -ls.wi);
            let (emitted, two_sided) = emission_of(scene, ls.light, ls.point, ls.normal);
            let infinite = scene.lights.is_infinite(ls.light);
            let sampled = Vertex {
                kind: Kind::Light,
                point: ls.point,
                error: ls.error,
                normal: if infinite { -ls.wi } else { ls.normal },
                pdf_fwd: if infinite {
                    origin_density(scene, ls.light, ls.wi)
                } else {
                    pdf_position
                },
                delta_light: ls.delta,
                infinite,
                light: ls.light,
                emitted,
                two_sided,
                ..Vertex::EMPTY
            };
            let pt_rev = if infinite {
                scene.lights.disc_density(ls.light) * pt.cos(ls.wi)
            } else {
                sampled.area_density_at(pdf_emission, pt)
            };
            return Some(Connection {
                value,
                film: None,
                pt_rev,
                pt_minus_rev: pdf_reverse * pl.to_previous,
                qs_rev: pt.area_density_at(pdf_forward, &sampled),
                qs_minus_rev: 0.0,
                sampled_light: Some(SampledLight {
                    pdf_fwd: sampled.pdf_fwd,
                    delta: sampled.delta_light,
                }),
            });
        }
        // Both subpaths end on surfaces: a shadow ray joins them. One
        // evaluation at each end gives f and the densities both ways.
        let qs = &light[s - 1];
        if qs.bsdf.is_specular() {
            return None;
        }
        let d = pt.point - qs.point;
        let dist2 = d.length_squared();
        if !(dist2 > 0.0) {
            return None;
        }
        let w = d / dist2.sqrt();
        let (f_pt, pdf_pt, pdf_pt_reverse) = pt.bsdf.eval_with_pdfs(pl.wo, pl.frame.to_local(-w));
        let ql = &light_local[s - 1];
        let qs_w = ql.frame.to_local(w);
        let (f_qs, pdf_qs, pdf_qs_reverse) = qs.bsdf.eval_adjoint_with_pdfs(ql.wo, qs_w);
        let f_qs = f_qs * shading_correction(ql.wo, qs_w, ql.normal);
        let g = ql.shading_cos(w) * pl.shading_cos(w) / dist2;
        let value = qs.beta * f_qs * f_pt * pt.beta * g;
        if !(value.max_element() > 0.0) {
            return None;
        }
        counts.shadow += 1;
        let shadow =
            ray_between(qs.point, qs.error, qs.normal, pt.point, pt.error, pt.normal).at_time(time);
        if scene.geometry.occluded(&shadow) {
            return None;
        }
        Some(Connection {
            value,
            film: None,
            sampled_light: None,
            // Densities per area at the far end of the shadow ray: cos / d².
            pt_rev: pdf_qs * pt.normal.dot(w).abs() / dist2,
            pt_minus_rev: pdf_pt_reverse * pl.to_previous,
            qs_rev: pdf_pt * qs.normal.dot(w).abs() / dist2,
            qs_minus_rev: pdf_qs_reverse * ql.to_previous,
        })
    }
}

/// What [`Bdpt::connect`] found for one strategy: the unweighted value,
/// where it lands (t = 1), the light point that strategy s = 1 sampled, and the
/// reverse densities (area) of the vertices next to the connection in the
/// joined path: z_{t-1} and z_{t-2} sampled from the light side, y_{s-1}
/// and y_{s-2} from the camera side.
struct Connection {
    value: Rgb,
    film: Option<Vec2>,
    sampled_light: Option<SampledLight>,
    pt_rev: f32,
    pt_minus_rev: f32,
    qs_rev: f32,
    qs_minus_rev: f32,
}

/// What the MIS weight reads of the light point that strategy s = 1
/// sampled itself, in place of the light subpath's y_0.
#[derive(Clone, Copy)]
struct SampledLight {
    pdf_fwd: f32,
    delta: bool,
}
