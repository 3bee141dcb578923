//! Path tracing (Kajiya 1986): one secondary ray per bounce, with next-event
//! estimation (a shadow ray to a sampled light point at every non-specular
//! vertex), BSDF sampling for the next direction, the two combined by multiple
//! importance sampling, and Russian roulette to end long paths without bias.
//!
//! The estimator of L along a camera ray, for vertices x_0 (first hit) .. x_k:
//!   L = Le(x_0) + sum_k beta_k [ w_light * f Le cos / p_light  (shadow ray)
//!                               + w_bsdf * Le(x_{k+1})          (BSDF ray hits a light) ]
//! where beta_k is the product of f cos / p_bsdf (and 1/q of roulette) so far.

use super::{
    CameraEstimator, MisHeuristic, PathLength, RayCounts, Settings, Strategy, Technique,
    survives_roulette,
};
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::bsdf::lambert;
use crate::math::{Frame, Ray, Rgb};
use crate::sampling::warp::square_to_cosine_hemisphere;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::light::LightSample;
use crate::scene::material::{Bsdf, BsdfSample};
use crate::shortcuts::{PrimaryPixel, ShortcutsUsed};
use glam::{Vec2, Vec3A};
use std::f32::consts::FRAC_1_PI;

/// Hears what one path does, for `--debug-sample`. Every method has an
/// empty default and the render uses [`NoObserver`], a zero-sized type, so
/// the observed loop compiles to the plain one.
pub trait PathObserver {
    /// Events in path order: each shadow ray is traced when its light sample
    /// is drawn. Ordinary rendering (false) defers it until the next ray is
    /// known and reports no light samples.
    const IN_ORDER: bool = true;
    /// The path reached vertex `bounce` (0 = first hit) with throughput `beta`.
    fn vertex(&mut self, _bounce: u32, _hit: &SurfaceHit, _beta: Rgb) {}
    /// Emission found at the vertex, its MIS weight and what it added.
    fn emission(&mut self, _emitted: Rgb, _weight: f32, _added: Rgb) {}
    /// A light sample: the point, its pdf (solid angle), the BSDF value, the
    /// MIS weight, whether it is visible and what it added.
    fn light_sample(
        &mut self,
        _ls: &LightSample,
        _f: Rgb,
        _weight: f32,
        _visible: bool,
        _added: Rgb,
    ) {
    }
    /// The sampled continuation.
    fn bsdf_sample(&mut self, _sample: &BsdfSample) {}
    /// Russian roulette with survival probability `q`.
    fn roulette(&mut self, _q: f32, _survived: bool) {}
    /// The last ray left the scene.
    fn escaped(&mut self) {}
}

/// The observer of ordinary rendering: hears nothing.
pub struct NoObserver;

impl PathObserver for NoObserver {
    const IN_ORDER: bool = false;
}

/// A shadow ray still to be traced and what its light sample adds when the
/// light is visible; only these two travel to where it is traced (the light
/// sample itself is for observers, which trace it at once).
struct PendingShadow {
    ray: Ray,
    added: Rgb,
    /// Where `added` is still to be multiplied by the environment's
    /// radiance, its map coordinates ([`Lights::sample_deferred`]).
    environment_uv: Option<Vec2>,
    /// The light the ray ends on.
    light: u32,
}

impl PendingShadow {
    /// Traces the shadow ray: whether the light is visible. Where the scene
    /// knows which triangles can block rays from the origin's voxel to the
    /// light ([`crate::shortcuts::ShadowVoxels`]) only those are tested, and none
    /// where the light is seen whole; the ray counts either way.
    /// `PLAIN` as for [`crate::accel::Geometry::occluded_as`].
    #[inline(always)]
    fn visible<const PLAIN: bool>(&self, scene: &Scene, counts: &mut RayCounts) -> bool {
        counts.shadow += 1;
        match scene.shortcuts.shadow_voxels(self.light) {
            Some(voxels) => !voxels.occluded::<PLAIN>(&scene.geometry, &self.ray),
            None => !scene.geometry.occluded_as::<PLAIN>(&self.ray),
        }
    }

    /// What a deferred light sample adds, if there is one.
    #[inline(always)]
    fn trace<const PLAIN: bool>(
        pending: Option<Self>,
        scene: &Scene,
        counts: &mut RayCounts,
    ) -> Rgb {
        match pending {
            Some(shadow) if shadow.visible::<PLAIN>(scene, counts) => shadow.added(scene),
            _ => Rgb::ZERO,
        }
    }

    /// What the light adds where the shadow ray is clear.
    #[inline(always)]
    fn added(&self, scene: &Scene) -> Rgb {
        self.added
            * scene
                .lights
                .deferred_radiance(self.environment_uv, Rgb::ONE)
    }
}

/// Settings of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PathSettings {
    #[serde(flatten)]
    pub length: PathLength,
    /// Which strategies find direct light.
    pub strategy: Strategy,
    /// How they combine under [`Strategy::Mis`] (`None` reads as power).
    pub mis: MisHeuristic,
    /// The general loop even where a specialised one applies.
    pub general: bool,
    /// Emitters seen directly integrated exactly over each pixel where
    /// that is possible (`crate::accel::seen_emitters`); off, camera rays
    /// sample them like everything else.
    pub exact_seen_emitters: bool,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            length: PathLength::default(),
            strategy: Strategy::Mis,
            mis: MisHeuristic::Power,
            general: false,
            exact_seen_emitters: true,
        }
    }
}

impl Settings for PathSettings {
    fn validate(&self) -> Result<(), String> {
        self.length.check()
    }

    fn length_mut(&mut self) -> Option<&mut PathLength> {
        Some(&mut self.length)
    }

    fn mis_mut(&mut self) -> Option<&mut MisHeuristic> {
        Some(&mut self.mis)
    }
}

/// The path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTracer {
    /// Maximum number of bounces: 0 = only emitters seen directly, 1 = direct
    /// lighting. Mitsuba's `max_depth` counts path segments, one more.
    pub max_depth: u32,
    /// Roulette starts after this many bounces (Mitsuba's `rr_depth`, default 5).
    pub rr_depth: u32,
    /// Russian roulette on or off (off: every path runs to `max_depth`).
    pub russian_roulette: bool,
    /// Next-event estimation: sample a light at every non-specular vertex.
    pub nee: bool,
    /// How NEE and BSDF sampling share direct light when NEE is on.
    pub mis: MisHeuristic,
    /// Use the general loop even where the scene allows a specialised one
    /// (for measuring what specialisation saves).
    pub general: bool,
    /// Emission seen directly is integrated exactly over the pixel where the
    /// scene knows it ([`PrimaryPixel::seen_emission`]) instead of sampled.
    pub exact_seen_emitters: bool,
}

impl Default for PathTracer {
    fn default() -> Self {
        PathTracer {
            max_depth: 8,
            rr_depth: 5,
            russian_roulette: true,
            nee: true,
            mis: MisHeuristic::Power,
            general: false,
            exact_seen_emitters: true,
        }
    }
}

impl Technique for PathTracer {
    const SUMMARY: &'static str =
        "Path tracing with next-event estimation, MIS and Russian roulette.";

    type Settings = PathSettings;

    fn new(settings: &PathSettings) -> Self {
        PathTracer {
            max_depth: settings.length.max_depth,
            rr_depth: settings.length.rr_depth,
            russian_roulette: settings.length.russian_roulette,
            nee: settings.strategy != Strategy::Bsdf,
            mis: match settings.strategy {
                Strategy::Light => MisHeuristic::None,
                _ => super::options::combining(settings.mis),
            },
            general: settings.general,
            exact_seen_emitters: settings.exact_seen_emitters,
        }
    }

    fn describe(&self) -> String {
        format!(
            "path (max depth {}, nee {}, mis {:?}, rr {})",
            super::options::depth_label(self.max_depth),
            if self.nee { "on" } else { "off" },
            self.mis,
            if self.russian_roulette {
                format!("from {}", self.rr_depth)
            } else {
                "off".into()
            }
        )
    }
}

impl CameraEstimator for PathTracer {
    /// One radiance sample along `ray`, by the loop specialised for what
    /// the scene uses (see [`crate::scene::Features`]). `pixel`: what is
    /// known of the camera ray's pixel ([`crate::shortcuts::PrimaryCandidates`]).
    #[inline]
    fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        self.radiance_observed(scene, ray, pixel, sampler, counts, &mut NoObserver)
    }

    fn is_general(&self) -> bool {
        self.general
    }

    fn shortcuts_used(&self) -> ShortcutsUsed {
        ShortcutsUsed {
            primary_candidates: !self.general,
            seen_emitters: Some(self.exact_seen_emitters),
            shadow_voxels: true,
        }
    }
}

impl PathTracer {
    /// [`PathTracer::radiance`], telling `observer` about every vertex.
    ///
    /// Where the pixel's directly seen emission is known, integrated over
    /// the pixel, every sample adds it and the camera ray's own hit on an
    /// emitter adds nothing: the pixel's mean is unchanged, and what varied
    /// with where in the pixel the ray went (an emitter's rim) does not.
    #[inline]
    pub fn radiance_observed<O: PathObserver>(
        &self,
        scene: &Scene,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Rgb {
        let f = scene.features;
        // The general loop tests everything, as a renderer without the
        // lists would; it still integrates seen emitters, so that its image
        // stays the specialised loop's.
        let p = PrimaryPixel {
            candidates: pixel.candidates.filter(|_| !self.general),
            seen_emission: pixel.seen_emission.filter(|_| self.exact_seen_emitters),
        };
        // The Lambertian-only loop measured 3.3-3.9% faster on the Cornell
        // box; a loop without specular branches for glossy scenes -2.3 to
        // +0.9%, dropped. Geometry without masks, instances or moving
        // objects: the glossy room 7.6% -> 0.5% more instructions than
        // before those features (docs/performance.md).
        let (lambert, plain) = (!self.general && f.diffuse_only(), scene.geometry.is_plain());
        let traced = match (lambert, plain) {
            (true, true) => self.trace::<true, true, O>(scene, ray, p, sampler, counts, observer),
            (true, false) => self.trace::<true, false, O>(scene, ray, p, sampler, counts, observer),
            (false, true) => self.trace::<false, true, O>(scene, ray, p, sampler, counts, observer),
            (false, false) => {
                self.trace::<false, false, O>(scene, ray, p, sampler, counts, observer)
            }
        };
        match p.seen_emission {
            Some(emission) => emission + traced,
            None => traced,
        }
    }

    /// The path loop. `DIFFUSE_ONLY`: every BSDF is Lambertian, so the
    /// Lambertian code is inline and no branch is specular. `PLAIN`: the
    /// geometry is [`crate::accel::Geometry::is_plain`]. `pixel`: the
    /// camera ray's candidates, and whether its emission is accounted for
    /// outside the loop.
    fn trace<const DIFFUSE_ONLY: bool, const PLAIN: bool, O: PathObserver>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        observer: &mut O,
    ) -> Rgb {
        let (mut radiance, mut beta) = (Rgb::ZERO, Rgb::ONE);
        // 1 / the (eta_i / eta_t)^2 factors in beta: roulette reads beta
        // without them, as if the path were outside the glass.
        let mut eta_scale = 1.0f32;
        // The camera ray behaves like a specular bounce: emission it finds is
        // counted in full because no light sample could have found it.
        let mut specular_bounce = true;
        let (mut prev_bsdf_pdf, mut prev_point) = (0.0, ray.origin);
        let mut bounces = 0;
        let mut candidates = pixel.candidates;
        let seen_known = pixel.seen_emission.is_some();
        loop {
            let u = VertexNumbers::draw(sampler, bounces, scene.lights.has_choice());
            if !DIFFUSE_ONLY && self.nee {
                scene.lights.prefetch_sample(u.light_select, u.light);
            }
            // The camera ray tests only its pixel's candidates, if known.
            let hit = scene
                .geometry
                .intersect_maybe_among::<PLAIN>(&ray, candidates.take());
            let Some(hit) = hit else {
                observer.escaped();
                // Light from infinity, weighed against its light samples.
                if let Some(env) = scene.lights.environment() {
                    let towards = env.towards(ray.direction);
                    let weight = self.found_light_weight(specular_bounce, prev_bsdf_pdf, || {
                        scene.lights.environment_pdf_towards(towards)
                    });
                    radiance += beta * env.le_towards(towards) * weight;
                }
                break;
            };
            observer.vertex(bounces, &hit, beta);
            // The material's texels arrive while the light sample, which
            // needs no BSDF, is made.
            scene.prefetch_bsdf(&hit);
            let wo_world = -ray.direction;
            if hit.light != NO_LIGHT && !(seen_known && bounces == 0) {
                let emitted = scene.emitted(&hit, wo_world);
                if emitted.max_element() > 0.0 {
                    let weight = self.found_light_weight(specular_bounce, prev_bsdf_pdf, || {
                        scene
                            .lights
                            .pdf(hit.light, prev_point, hit.point, hit.normal)
                    });
                    radiance += beta * emitted * weight;
                    observer.emission(emitted, weight, beta * emitted * weight);
                }
            }
            if bounces >= self.max_depth {
                break;
            }
            let light_sample = if self.nee && !(!DIFFUSE_ONLY && scene.bsdf_is_specular(&hit)) {
                scene
                    .lights
                    .sample_deferred(hit.point, u.light_select, u.light)
            } else {
                None
            };
            let bsdf = scene.bsdf_at(&hit);
            if bsdf.is_black() {
                break;
            }
            let frame = scene.shading_frame(&hit);
            let wo = frame.to_local(wo_world);
            let u_lobe = u.lobe(sampler, &bsdf);

            // Next-event estimation. The shadow ray is traced once the next
            // ray is known, beside its traversal: the two are independent,
            // and the core overlaps them (Cornell box, 2 threads: Sobol 3.46
            // -> 3.61 M paths/s, independent 3.81 -> 4.10). An observer
            // hears of it in path order; the image is the same either way.
            let mut pending = None;
            if let Some(light_sample) = light_sample {
                let light =
                    self.weigh_light::<DIFFUSE_ONLY>(light_sample, &hit, &frame, &bsdf, wo, beta);
                if let Some((shadow, mut ls, f, weight)) = light {
                    if O::IN_ORDER {
                        let visible = shadow.visible::<PLAIN>(scene, counts);
                        let added = if visible {
                            shadow.added(scene)
                        } else {
                            Rgb::ZERO
                        };
                        ls.radiance = scene
                            .lights
                            .deferred_radiance(shadow.environment_uv, ls.radiance);
                        observer.light_sample(&ls, f, weight, visible, added);
                        radiance += added;
                    } else {
                        pending = Some(shadow);
                    }
                }
            }

            // The next ray, or None where the path ends here.
            let next = 'next: {
                let Some(sample) = sample::<DIFFUSE_ONLY>(&bsdf, wo, u_lobe, u.bsdf) else {
                    break 'next None;
                };
                observer.bsdf_sample(&sample);
                beta *= sample.weight;
                specular_bounce = !DIFFUSE_ONLY && sample.specular;
                // Only refraction scales radiance by (eta_i / eta_t)^2.
                if !DIFFUSE_ONLY && sample.wi.z * wo.z < 0.0 {
                    eta_scale /= bsdf.refraction_scale(wo, sample.wi);
                }
                (prev_bsdf_pdf, prev_point) = (sample.pdf, hit.point);
                bounces += 1;
                if !self.survives(bounces, &mut beta, eta_scale, &u, sampler, observer) {
                    break 'next None;
                }
                counts.bounce += 1;
                Some(hit.spawn_ray(frame.to_world(sample.wi)))
            };
            // Whether or not the path goes on, its light sample counts.
            radiance += PendingShadow::trace::<PLAIN>(pending, scene, counts);
            let Some(next) = next else {
                break;
            };
            ray = next;
        }
        radiance
    }

    /// The MIS weight of light found by a BSDF-sampled ray (or the camera
    /// ray) against the light sample that could have found it, whose
    /// solid-angle density `light_pdf` gives.
    #[inline(always)]
    fn found_light_weight(
        &self,
        specular_bounce: bool,
        bsdf_pdf: f32,
        light_pdf: impl FnOnce() -> f32,
    ) -> f32 {
        if specular_bounce || !self.nee {
            1.0
        } else if self.mis == MisHeuristic::None {
            // Light sampling alone accounts for this path.
            0.0
        } else {
            self.mis.weight(bsdf_pdf, light_pdf())
        }
    }

    /// A light sample made at `hit` (with its deferred environment
    /// coordinates): its shadow ray and what it adds where the light is
    /// visible (throughput `beta`), then for observers the sample, the
    /// BSDF's value towards it and its MIS weight against BSDF sampling;
    /// `None` where it adds nothing.
    #[inline(always)]
    fn weigh_light<const DIFFUSE_ONLY: bool>(
        &self,
        (ls, deferred): (LightSample, Option<Vec2>),
        hit: &SurfaceHit,
        frame: &Frame,
        bsdf: &Bsdf,
        wo: Vec3A,
        beta: Rgb,
    ) -> Option<(PendingShadow, LightSample, Rgb, f32)> {
        let wi = frame.to_local(ls.wi);
        let f = eval::<DIFFUSE_ONLY>(bsdf, wo, wi);
        if f.max_element() <= 0.0 {
            return None;
        }
        let weight = if ls.delta || self.mis == MisHeuristic::None {
            1.0
        } else {
            self.mis.weight(ls.pdf, pdf::<DIFFUSE_ONLY>(bsdf, wo, wi))
        };
        let shadow = PendingShadow {
            ray: ls.shadow_ray_from(hit),
            added: beta * f * ls.radiance * (wi.z.abs() * weight / ls.pdf),
            environment_uv: deferred,
            light: ls.light,
        };
        Some((shadow, ls, f, weight))
    }

    /// Russian roulette after `bounces` (where it applies), then whether
    /// the path still carries anything.
    #[inline(always)]
    fn survives<O: PathObserver>(
        &self,
        bounces: u32,
        beta: &mut Rgb,
        eta_scale: f32,
        u: &VertexNumbers,
        sampler: &mut Sampler,
        observer: &mut O,
    ) -> bool {
        if self.russian_roulette && bounces > self.rr_depth {
            let q = (beta.max_element() * eta_scale).min(0.95);
            let u_roulette = sampler.get_1d_for(u.dim + 4, Domain::Other);
            let survived = survives_roulette(beta, eta_scale, u_roulette);
            observer.roulette(q, survived);
            if !survived {
                return false;
            }
        }
        beta.max_element() > 0.0
    }
}

/// The numbers of one path vertex. Every vertex consumes the same five
/// dimensions (light choice, light point, lobe, BSDF direction, roulette),
/// so stratified samplers keep dimensions aligned across samples. Those
/// that do not depend on the hit are drawn before the ray is traced: their
/// hash chains then overlap with the traversal instead of stalling the
/// light sample after it.
struct VertexNumbers {
    dim: u32,
    light_select: f32,
    light: Vec2,
    bsdf: Vec2,
}

impl VertexNumbers {
    /// Draws the numbers of vertex `bounces`. One light needs no choice
    /// (the Cornell box): skipping that number leaves the image
    /// bit-identical.
    #[inline(always)]
    fn draw(sampler: &mut Sampler, bounces: u32, light_choice: bool) -> Self {
        sampler.enter_path_vertex(bounces);
        let dim = sampler.reserve(5);
        VertexNumbers {
            dim,
            light_select: if light_choice {
                sampler.get_1d_for(dim, Domain::Light)
            } else {
                0.0
            },
            light: sampler.get_2d_for(dim + 1, Domain::Light),
            bsdf: sampler.get_2d_for(dim + 3, Domain::Bsdf),
        }
    }

    /// The lobe's number, drawn only where there is a lobe to choose.
    #[inline(always)]
    fn lobe(&self, sampler: &Sampler, bsdf: &Bsdf) -> f32 {
        if matches!(bsdf, Bsdf::Diffuse { .. }) {
            0.0
        } else {
            sampler.get_1d_for(self.dim + 2, Domain::Bsdf)
        }
    }
}

/// BSDF evaluation, the Lambertian model inline: the only one where the
/// scene has nothing else, and the most common one where it has.
#[inline(always)]
fn eval<const DIFFUSE_ONLY: bool>(bsdf: &Bsdf, wo: Vec3A, wi: Vec3A) -> Rgb {
    if let Bsdf::Diffuse { albedo } = *bsdf {
        return lambert::eval(albedo, wo, wi);
    }
    bsdf.eval(wo, wi)
}

#[inline(always)]
fn pdf<const DIFFUSE_ONLY: bool>(bsdf: &Bsdf, wo: Vec3A, wi: Vec3A) -> f32 {
    if matches!(bsdf, Bsdf::Diffuse { .. }) {
        if !DIFFUSE_ONLY {
            return lambert::pdf(wo, wi);
        }
        return if wo.z * wi.z > 0.0 {
            wi.z.abs() * FRAC_1_PI
        } else {
            0.0
        };
    }
    bsdf.pdf(wo, wi)
}

#[inline(always)]
fn sample<const DIFFUSE_ONLY: bool>(
    bsdf: &Bsdf,
    wo: Vec3A,
    u_lobe: f32,
    u: Vec2,
) -> Option<BsdfSample> {
    if DIFFUSE_ONLY && let Bsdf::Diffuse { albedo } = *bsdf {
        let mut wi = square_to_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        if wi.z == 0.0 || wo.z == 0.0 {
            return None;
        }
        return Some(BsdfSample {
            wi,
            weight: albedo,
            pdf: wi.z.abs() * FRAC_1_PI,
            specular: false,
        });
    }
    bsdf.sample(wo, u_lobe, u)
}
