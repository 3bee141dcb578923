//! Whitted ray tracing (1980): deterministic "backward" ray tracing.
//!
//! At every hit: emission, direct light from each light treated as a point
//! (area lights at their centroid, with the intensity of a Lambertian emitter,
//! I = Le A cos), one hard shadow ray per light, an optional constant ambient
//! term, and recursion along the perfect mirror and refraction directions
//! (Snell, Fresnel-weighted) up to a depth. Diffuse interreflection, soft
//! shadows and caustics are missing by construction: that is the point of
//! showing it next to the path tracer.
//!
//!   L(x, wo) = Le + sum_lights f(wo, wl) I cos / d^2 V + ka albedo
//!            + R L(x, reflect(wo)) + (1 - R) T L(x, refract(wo))

use super::{CameraEstimator, RayCounts, Settings, Technique};
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::math::{Frame, Ray, Rgb, offset_ray_origin, ray_between};
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::scene::light::{Light, PlanarEmitter};
use crate::scene::material::Bsdf;
use crate::shortcuts::PrimaryPixel;
use glam::Vec3A;

/// How shadow rays treat glass in their way (the classic shortcuts: no
/// refraction of the light, no caustics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GlassShadows {
    /// Glass blocks light like any other surface.
    #[default]
    Opaque,
    /// Light passes through glass, multiplied by its tint at every crossing.
    Tinted,
}

/// Settings of the Whitted ray tracer.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct WhittedSettings {
    /// Maximum number of specular bounces after the first hit.
    pub max_depth: u32,
    /// Constant ambient radiance (grey), times the diffuse albedo.
    pub ambient: f32,
    pub glass_shadows: GlassShadows,
    /// The general code even where a specialised one applies.
    pub general: bool,
}

impl Default for WhittedSettings {
    fn default() -> Self {
        WhittedSettings {
            max_depth: 8,
            ambient: 0.0,
            glass_shadows: GlassShadows::Opaque,
            general: false,
        }
    }
}

impl Settings for WhittedSettings {
    fn validate(&self) -> Result<(), String> {
        if self.ambient >= 0.0 && self.ambient.is_finite() {
            Ok(())
        } else {
            Err(format!("ambient {} is not a radiance >= 0", self.ambient))
        }
    }

    fn deepest(&self) -> u32 {
        super::DEEPEST_WITHOUT_ROULETTE
    }

    fn max_depth_mut(&mut self) -> Option<&mut u32> {
        Some(&mut self.max_depth)
    }
}

/// The Whitted ray tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhittedTracer {
    /// Maximum number of specular bounces after the first hit.
    pub max_depth: u32,
    /// Constant ambient radiance, multiplied by the diffuse albedo.
    pub ambient: Rgb,
    pub glass_shadows: GlassShadows,
    /// Trace tinted shadow rays surface by surface even in a scene without
    /// glass (for measuring what skipping them saves).
    pub general: bool,
}

impl Default for WhittedTracer {
    fn default() -> Self {
        WhittedTracer {
            max_depth: 8,
            ambient: Rgb::ZERO,
            glass_shadows: GlassShadows::Opaque,
            general: false,
        }
    }
}

/// Most glass surfaces a tinted shadow ray passes before it gives up.
const MAX_GLASS_CROSSINGS: u32 = 16;

impl Technique for WhittedTracer {
    const SUMMARY: &'static str =
        "Whitted ray tracing: point-light direct light, hard shadows, mirror and glass recursion.";

    type Settings = WhittedSettings;

    fn new(settings: &WhittedSettings) -> Self {
        WhittedTracer {
            max_depth: settings.max_depth,
            ambient: Rgb::splat(settings.ambient.max(0.0)),
            glass_shadows: settings.glass_shadows,
            general: settings.general,
        }
    }

    fn describe(&self) -> String {
        format!(
            "whitted (max depth {}, ambient {:?}, glass shadows {:?})",
            self.max_depth,
            self.ambient.to_array(),
            self.glass_shadows
        )
    }
}

impl CameraEstimator for WhittedTracer {
    /// Radiance along `ray`; deterministic, so one sample per pixel is enough.
    fn radiance(
        &self,
        scene: &Scene,
        ray: Ray,
        _pixel: PrimaryPixel<'_>,
        _sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        self.trace(scene, ray, 0, counts)
    }

    fn is_deterministic(&self) -> bool {
        true
    }

    fn is_general(&self) -> bool {
        self.general
    }
}

impl WhittedTracer {
    fn trace(&self, scene: &Scene, ray: Ray, depth: u32, counts: &mut RayCounts) -> Rgb {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            // The environment as a background; it lights nothing (no point
            // stands for it).
            return scene
                .lights
                .environment()
                .map_or(Rgb::ZERO, |e| e.le(ray.direction));
        };
        let wo_world = -ray.direction;
        let mut radiance = if hit.light != NO_LIGHT {
            scene.emitted(&hit, wo_world)
        } else {
            Rgb::ZERO
        };
        let frame = scene.shading_frame(&hit);
        let wo = frame.to_local(wo_world);
        // Diffuse lobes: direct light from each light as a point, plus the
        // ambient term; ideal lobes (a rough one read as its smooth limit)
        // recurse.
        let bsdf = scene.bsdf_at(&hit);
        if let Some((diffuse, _)) = bsdf.diffuse_albedo() {
            radiance += self.direct(scene, &hit, &frame, wo, bsdf, counts);
            radiance += self.ambient * diffuse;
        }
        if depth < self.max_depth {
            for (wi, weight) in bsdf.ideal_events(wo) {
                if weight.max_element() > 0.0 {
                    radiance +=
                        weight * self.follow(scene, &hit, frame.to_world(wi), depth, counts);
                }
            }
        }
        radiance
    }

    /// Recurses along a specular direction.
    fn follow(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        direction: Vec3A,
        depth: u32,
        counts: &mut RayCounts,
    ) -> Rgb {
        counts.bounce += 1;
        self.trace(scene, hit.spawn_ray(direction), depth + 1, counts)
    }

    /// Direct light from every light, each treated as a point.
    fn direct(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        frame: &Frame,
        wo: Vec3A,
        bsdf: Bsdf,
        counts: &mut RayCounts,
    ) -> Rgb {
        let mut sum = Rgb::ZERO;
        for (i, light) in scene.lights.as_slice().iter().enumerate() {
            let (position, shadow_target, intensity) = point_equivalent(light, hit.point);
            // A textured light shines with its texture's mean.
            let intensity = intensity * scene.lights.texture_mean(i);
            let to_light = position - hit.point;
            let dist2 = to_light.length_squared();
            if intensity.max_element() <= 0.0 || dist2 <= 0.0 {
                continue;
            }
            let wl = to_light / dist2.sqrt();
            let wi = frame.to_local(wl);
            let f = bsdf.eval(wo, wi);
            if f.max_element() <= 0.0 {
                continue;
            }
            let ray = ray_between(
                hit.point,
                hit.error,
                hit.normal,
                shadow_target,
                Vec3A::ZERO,
                Vec3A::ZERO,
            )
            .at_time(hit.time);
            let visibility = self.transmittance(scene, ray, counts);
            sum += f * intensity * visibility * (wi.z.abs() / dist2);
        }
        sum
    }

    /// Fraction of light passing along a shadow ray: 0 or 1, or the product
    /// of glass tints with [`GlassShadows::Tinted`]. Without glass in the
    /// scene a tinted shadow ray is an any-hit query, which may stop at the
    /// first blocker, instead of a walk from surface to surface.
    fn transmittance(&self, scene: &Scene, mut ray: Ray, counts: &mut RayCounts) -> Rgb {
        counts.shadow += 1;
        let through_glass = self.glass_shadows == GlassShadows::Tinted
            && (scene.features.dielectric || self.general);
        if !through_glass {
            return if scene.geometry.occluded(&ray) {
                Rgb::ZERO
            } else {
                Rgb::ONE
            };
        }
        let mut tint = Rgb::ONE;
        for _ in 0..MAX_GLASS_CROSSINGS {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return tint;
            };
            let Bsdf::Dielectric { tint: glass, .. } = scene.materials[hit.material as usize].bsdf
            else {
                return Rgb::ZERO;
            };
            tint *= glass;
            // Continue from the far side of the glass surface to the same end.
            let end = ray.at(ray.t_max);
            let origin = offset_ray_origin(hit.point, hit.error, hit.normal, ray.direction);
            let remaining = (end - origin).dot(ray.direction);
            if remaining <= 0.0 {
                return tint;
            }
            ray = Ray {
                origin,
                t_max: remaining,
                ..ray
            };
            counts.shadow += 1;
        }
        Rgb::ZERO
    }
}

/// A light as a point: its position, where shadow rays towards it end, and
/// its intensity towards `reference`. An area light of radiance Le and area A
/// is a Lambertian emitter with intensity Le A cos(theta) about its normal,
/// placed at its centroid; a sphere shows a disc of area pi r^2 from anywhere.
fn point_equivalent(light: &Light, reference: Vec3A) -> (Vec3A, Vec3A, Rgb) {
    match *light {
        Light::Point {
            position,
            intensity,
        } => (position, position, intensity),
        Light::Spot {
            position,
            intensity,
            cone,
        } => (
            position,
            position,
            intensity * cone.falloff((reference - position).normalize_or_zero()),
        ),
        Light::Directional {
            direction,
            irradiance,
            center,
            radius,
        } => {
            // A point far against the light whose intensity gives E there.
            let distance = crate::scene::light::beyond_bounds(reference, center, radius);
            let position = reference - direction * distance;
            (position, position, irradiance * distance * distance)
        }
        Light::Triangle(p) => planar_point(&p, p.p0 + (p.e1 + p.e2) / 3.0, reference),
        Light::Parallelogram(p) => planar_point(&p, p.p0 + (p.e1 + p.e2) * 0.5, reference),
        Light::Sphere {
            center,
            radius,
            radiance,
            ..
        } => {
            // Shadow rays stop at the near side of the sphere, not inside it.
            let surface = center + radius * (reference - center).normalize_or_zero();
            let intensity = radiance * (std::f32::consts::PI * radius * radius);
            (center, surface, intensity)
        }
    }
}

/// A flat emitter as a point at `centre`: a Lambertian emitter's intensity
/// Le A cos towards `reference`.
fn planar_point(p: &PlanarEmitter, centre: Vec3A, reference: Vec3A) -> (Vec3A, Vec3A, Rgb) {
    let cos = p.normal.dot((reference - centre).normalize_or_zero());
    let cos = if p.two_sided { cos.abs() } else { cos.max(0.0) };
    (centre, centre, p.radiance * (p.area * cos))
}
