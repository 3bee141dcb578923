//! Light tracing (forward ray tracing, "particle tracing"): particles leave
//! the lights, bounce by BSDF sampling, and at every vertex a ray is sent to
//! the eye; the contribution lands on whatever pixel it reaches.
//!
//! With N particles per pass and a particle weight beta (Le cos / p after
//! emission, times f cos / p per bounce), a vertex x adds to the pixel it
//! projects on
//!   beta f(x, w_prev -> w_cam) |cos theta_x| We / p_cam  / N,
//! where We / p_cam = 1 / (A_pixel cos^3 d^2) (see `Camera::connect`). The
//! light point itself connects with Le |cos| / p_position. Specular surfaces
//! cannot connect (their f is a delta), so a mirror seen by the camera stays
//! black: the reason light tracing alone is a poor way to render, except for
//! caustics, which it finds easily.
//!
//! The BSDF is sampled in importance-transport mode: the (eta_i / eta_t)^2
//! radiance scaling at refraction does not apply to particles (Veach's
//! thesis, 5.2).

use super::{PathLength, RayCounts, Settings, SplattingEstimator, Technique, survives_roulette};
use crate::camera::CameraConnection;
use crate::math::{Rgb, ray_between};
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::light::EmissionSample;
use crate::scene::material::Bsdf;
use glam::{Vec2, Vec3A};

/// Settings of the light tracer: how long its particles' paths run.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct LightSettings {
    #[serde(flatten)]
    pub length: PathLength,
}

impl Settings for LightSettings {
    fn validate(&self) -> Result<(), String> {
        self.length.check()
    }

    fn length_mut(&mut self) -> Option<&mut PathLength> {
        Some(&mut self.length)
    }
}

/// The light tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTracer {
    /// Bounces after leaving the light (0 = only lights seen directly).
    pub max_depth: u32,
    pub rr_depth: u32,
    pub russian_roulette: bool,
}

impl Default for LightTracer {
    fn default() -> Self {
        LightTracer {
            max_depth: 8,
            rr_depth: 5,
            russian_roulette: true,
        }
    }
}

/// Where a particle's connection lands: a film position and its contribution
/// (not yet divided by the number of particles).
#[derive(Clone, Copy, Debug)]
pub struct Splat {
    pub film: Vec2,
    pub value: Rgb,
    /// Spread over the pixels the pixel filter covers (a point seen by the
    /// camera); false for an estimate of the traced sample's own pixel
    /// (BDPT's camera strategies) at its camera ray's film position, which
    /// the session adds to that pixel (the ray was drawn through the
    /// filter: filtering it again blurred it and, where the filter's
    /// weights at whole pixels do not sum to 1, scaled it) or splats
    /// through the filter as camera samples are.
    pub filtered: bool,
}

impl Technique for LightTracer {
    const SUMMARY: &'static str =
        "Light (particle) tracing: paths from the lights, every vertex connected to the camera.";

    type Settings = LightSettings;

    fn new(settings: &LightSettings) -> Self {
        LightTracer {
            max_depth: settings.length.max_depth,
            rr_depth: settings.length.rr_depth,
            russian_roulette: settings.length.russian_roulette,
        }
    }

    fn describe(&self) -> String {
        format!(
            "light tracing (max depth {}, rr {})",
            super::options::depth_label(self.max_depth),
            if self.russian_roulette {
                format!("from {}", self.rr_depth)
            } else {
                "off".into()
            }
        )
    }
}

impl SplattingEstimator for LightTracer {
    /// Traces one particle and hands each camera connection to `splat`.
    fn trace(
        &self,
        scene: &Scene,
        _pixel: (u32, u32),
        _camera_filter: crate::filter::PixelFilter,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        splat: impl FnMut(Splat),
    ) {
        // As the path tracer: plain geometry keeps the other cases'
        // queries out of the walk (docs/performance.md).
        if scene.geometry.is_plain() {
            self.trace_particle::<true>(scene, sampler, counts, splat)
        } else {
            self.trace_particle::<false>(scene, sampler, counts, splat)
        }
    }
}

impl LightTracer {
    /// [`SplattingEstimator::trace`]; `PLAIN` as for
    /// [`crate::accel::Geometry::intersect_as`].
    fn trace_particle<const PLAIN: bool>(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        mut splat: impl FnMut(Splat),
    ) {
        sampler.start_particle(scene.camera.width * scene.camera.height);
        let emission = sample_particle(scene, sampler);
        let u_lens = sampler.next_2d_for(Domain::Lens);
        let time = super::sample_time(scene, sampler, false);
        let Some(emission) = emission else {
            return;
        };
        let camera = &scene.camera;

        // The light point seen directly: Le |cos| / p_position * We / p_cam.
        // Point and spot lights are not seen, as no camera ray can hit them
        // (path tracing's and Mitsuba's image).
        let delta_position = emission.normal == Vec3A::ZERO;
        if let Some(c) = camera
            .connect(emission.point, u_lens)
            .filter(|_| !delta_position)
        {
            let le = emission.emitted_towards(c.wi);
            if le.max_element() > 0.0
                && sees_lens::<PLAIN>(
                    scene,
                    emission.point,
                    emission.error,
                    emission.normal,
                    &c,
                    time,
                    counts,
                )
            {
                let value = le * (emission.cos_at_light(c.wi) * c.weight / emission.pdf_position);
                splat(Splat {
                    film: c.film,
                    value,
                    filtered: true,
                });
            }
        }

        let mut beta = emission.throughput;
        // Roulette reads beta relative to the particle's starting weight
        // (whose size is the light's power in the scene's units).
        let roulette_scale = 1.0 / emission.throughput.max_element();
        let mut ray = emission.ray().at_time(time);
        counts.camera += 1;
        let mut bounces = 0;
        while bounces < self.max_depth {
            let Some(hit) = scene.geometry.intersect_as::<PLAIN>(&ray) else {
                break;
            };
            let bsdf = scene.bsdf_at(&hit);
            if bsdf.is_black() {
                break;
            }
            let frame = scene.shading_frame(&hit);
            let ng = frame.to_local(hit.normal);
            // Direction back towards where the particle came from.
            let w_prev = frame.to_local(-ray.direction);
            let u_lens = sampler.next_2d_for(Domain::Lens);
            let u_lobe = sampler.next_1d_for(Domain::Bsdf);
            let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
            let u_roulette = sampler.next_1d();

            if !bsdf.is_specular()
                && let Some(c) = camera.connect(hit.point, u_lens)
            {
                let w_cam = frame.to_local(c.wi);
                let f = bsdf.eval(w_cam, w_prev) * shading_correction(w_prev, w_cam, ng);
                if f.max_element() > 0.0
                    && sees_lens::<PLAIN>(scene, hit.point, hit.error, hit.normal, &c, time, counts)
                {
                    splat(Splat {
                        film: c.film,
                        value: beta * f * (w_cam.z.abs() * c.weight),
                        filtered: true,
                    });
                }
            }

            let Some(sample) = bsdf.sample(w_prev, u_lobe, u_bsdf) else {
                break;
            };
            beta *= importance_weight(bsdf, w_prev, sample.wi, ng, sample.weight);
            bounces += 1;
            if self.russian_roulette
                && bounces > self.rr_depth
                && !survives_roulette(&mut beta, roulette_scale, u_roulette)
            {
                break;
            }
            if beta.max_element() <= 0.0 {
                break;
            }
            let wi_world = frame.to_world(sample.wi);
            ray = hit.spawn_ray(wi_world);
            counts.bounce += 1;
        }
    }
}

/// Casts the connection from a surface point to the lens point (a shadow
/// ray, counted) and says whether nothing is in between. `PLAIN` as for
/// [`crate::accel::Geometry::occluded_as`].
#[inline]
pub(super) fn sees_lens<const PLAIN: bool>(
    scene: &Scene,
    point: Vec3A,
    error: Vec3A,
    normal: Vec3A,
    connection: &CameraConnection,
    time: f32,
    counts: &mut RayCounts,
) -> bool {
    counts.shadow += 1;
    let ray = ray_between(
        point,
        error,
        normal,
        connection.lens_point,
        Vec3A::ZERO,
        Vec3A::ZERO,
    )
    .at_time(time);
    !scene.geometry.occluded_as::<PLAIN>(&ray)
}

/// A particle's start: a light, a point on it and a direction, from three
/// dimensions of the sampler's light domain, which every particle tracer
/// (light tracing, BDPT's light subpaths, photons, VCM) draws first and in
/// this order.
#[inline]
pub(super) fn sample_particle(scene: &Scene, sampler: &mut Sampler) -> Option<EmissionSample> {
    let u_select = sampler.next_1d_for(Domain::Light);
    let u_position = sampler.next_2d_for(Domain::Light);
    let u_direction = sampler.next_2d_for(Domain::Light);
    scene
        .lights
        .sample_emission(u_select, u_position, u_direction)
}

/// The sample weight f cos / p in importance transport: as for radiance,
/// except that refraction does not scale by (eta_i / eta_t)^2, and that
/// with shading normals the adjoint BSDF carries
/// [`shading_correction`] (`ng`: the geometric normal in the shading frame).
#[inline]
pub(super) fn importance_weight(
    bsdf: Bsdf,
    wo: Vec3A,
    wi: Vec3A,
    ng: Vec3A,
    radiance_weight: Rgb,
) -> Rgb {
    radiance_weight * (shading_correction(wo, wi, ng) / bsdf.refraction_scale(wo, wi))
}

/// Veach's correction of the adjoint BSDF for shading normals (thesis,
/// 5.3): |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|), directions in the shading
/// frame (ns = +z), `wo` towards the light. 1 where ns = ng.
#[inline]
pub fn shading_correction(wo: Vec3A, wi: Vec3A, ng: Vec3A) -> f32 {
    if ng == Vec3A::Z {
        return 1.0;
    }
    let denominator = wo.dot(ng).abs() * wi.z.abs();
    if denominator > 0.0 {
        wo.z.abs() * wi.dot(ng).abs() / denominator
    } else {
        0.0
    }
}

/// The factor |wi·ns| / |wi·ng| by which a density estimate (photons
/// arriving along `wi`, flux per geometric area) turns into the shading
/// integral: 1 where ns = ng.
#[inline]
pub fn photon_shading_factor(wi: Vec3A, ng: Vec3A) -> f32 {
    if ng == Vec3A::Z {
        return 1.0;
    }
    let c = wi.dot(ng).abs();
    if c > 0.0 { wi.z.abs() / c } else { 0.0 }
}
