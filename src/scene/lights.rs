//! All lights of a scene, chosen in proportion to their power: the
//! emitters of `light.rs` and the environment, for next-event estimation
//! and for light paths.

use super::environment::Environment;
use super::light::{EmissionSample, Light, LightSample, LightSampling};
use crate::math::{OffsetMode, Rgb};
use crate::sampling::AliasTable;
use glam::{Vec2, Vec3A};
use std::f32::consts::PI;
use std::sync::Arc;

/// All lights of a scene with the power-proportional selection table.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    lights: Vec<Light>,
    /// Light from infinitely far away; its light id is `lights.len()`.
    environment: Option<Arc<Environment>>,
    selection: Option<AliasTable>,
    /// How shadow rays stop short of sampled light points.
    offset: OffsetMode,
}

impl Lights {
    /// Builds the selection table. Lights of zero power can never be chosen.
    pub fn new(lights: Vec<Light>) -> Self {
        Self::with_environment(lights, None)
    }

    /// Lights and an environment, chosen in proportion to their power.
    pub fn with_environment(lights: Vec<Light>, environment: Option<Environment>) -> Self {
        let mut powers: Vec<f32> = lights.iter().map(Light::power).collect();
        if let Some(env) = &environment {
            powers.push(env.power());
        }
        let selection = AliasTable::new(&powers);
        Lights {
            lights,
            environment: environment.map(Arc::new),
            selection,
            offset: OffsetMode::Robust,
        }
    }

    /// True for the lights at infinity: the environment and directional
    /// lights, whose particles start on a disc facing the scene.
    #[inline]
    pub fn is_infinite(&self, light: u32) -> bool {
        match self.lights.get(light as usize) {
            None => true,
            Some(l) => matches!(l, Light::Directional { .. }),
        }
    }

    /// True for a directional light (a delta in direction).
    #[inline]
    pub fn is_directional(&self, light: u32) -> bool {
        matches!(
            self.lights.get(light as usize),
            Some(Light::Directional { .. })
        )
    }

    /// Per area, the density of a particle's start on the disc facing the
    /// scene from light `light` at infinity (without the light's choice).
    #[inline]
    pub fn disc_density(&self, light: u32) -> f32 {
        let radius = match self.lights.get(light as usize) {
            Some(Light::Directional { radius, .. }) => *radius,
            _ => self.environment.as_ref().map_or(1.0, |e| e.radius),
        };
        1.0 / (PI * radius * radius)
    }

    /// The environment, if the scene has one.
    #[inline]
    pub fn environment(&self) -> Option<&Environment> {
        self.environment.as_deref()
    }

    /// The light id of the environment.
    #[inline]
    pub fn environment_id(&self) -> u32 {
        self.lights.len() as u32
    }

    /// Density (solid angle, including selection) with which
    /// [`Lights::sample`] picks direction `d` on the environment.
    #[inline]
    pub fn environment_pdf(&self, d: Vec3A) -> f32 {
        match (&self.environment, &self.selection) {
            (Some(env), Some(table)) => table.pmf(self.lights.len()) * env.pdf(d),
            _ => 0.0,
        }
    }

    /// The same lights with every area light sampled by `mode`.
    pub fn with_sampling(&self, mode: LightSampling) -> Lights {
        let mut lights = self.lights.clone();
        for light in &mut lights {
            match light {
                Light::Triangle(p) | Light::Parallelogram(p) => p.sampling = mode,
                Light::Sphere { sampling, .. } => *sampling = mode,
                Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => {}
            }
        }
        Lights {
            lights,
            environment: self.environment.clone(),
            selection: self.selection.clone(),
            offset: self.offset,
        }
    }

    /// Sets how shadow rays stop short of sampled light points.
    pub fn set_offset(&mut self, offset: OffsetMode) {
        self.offset = offset;
    }

    /// The lights, indexed by the light ids stored on emissive primitives.
    pub fn as_slice(&self) -> &[Light] {
        &self.lights
    }

    /// True when nothing can be sampled.
    pub fn is_empty(&self) -> bool {
        self.selection.is_none()
    }

    /// True when sampling chooses between lights: with one light the
    /// choice's random number is not read, so callers may skip drawing it.
    pub fn has_choice(&self) -> bool {
        self.lights.len() + usize::from(self.environment.is_some()) > 1
    }

    /// Chooses a light with `u_select` and a point on it with `u`, for next-event
    /// estimation from `reference`. The pdf includes the selection probability.
    #[inline(always)]
    pub fn sample(&self, reference: Vec3A, u_select: f32, u: Vec2) -> Option<LightSample> {
        let table = self.selection.as_ref()?;
        // One light needs no choice (the Cornell box); its pmf is 1.
        let (index, pmf) = if self.has_choice() {
            table.sample(u_select)
        } else {
            (0, table.pmf(0))
        };
        let mut s = match self.lights.get(index) {
            Some(light) => light.sample(reference, u)?,
            None => self.environment.as_ref()?.sample_from(reference, u)?,
        };
        s.pdf *= pmf;
        s.light = index as u32;
        s.error = self.offset.spawn_error(s.error, s.normal);
        (s.pdf > 0.0 && s.pdf.is_finite() && s.distance > 0.0).then_some(s)
    }

    /// A hint before [`Lights::sample`] with the same numbers: where that
    /// sample would be the environment's, its first table entry is fetched
    /// into the cache while the caller traces (living-room: the entry was
    /// a cache miss that held 14% of path tracing's time).
    #[inline(always)]
    pub fn prefetch_sample(&self, u_select: f32, u: Vec2) {
        let (Some(environment), Some(table)) = (&self.environment, &self.selection) else {
            return;
        };
        let index = if self.has_choice() {
            table.sample(u_select).0
        } else {
            0
        };
        if index >= self.lights.len() {
            environment.prefetch_sample(u);
        }
    }

    /// Chooses a light by power and samples a particle leaving it (light tracing).
    #[inline]
    pub fn sample_emission(
        &self,
        u_select: f32,
        u_position: Vec2,
        u_direction: Vec2,
    ) -> Option<EmissionSample> {
        let table = self.selection.as_ref()?;
        let (index, pmf) = table.sample(u_select);
        let mut s = match self.lights.get(index) {
            Some(light) => light.sample_emission(u_position, u_direction)?,
            None => self
                .environment
                .as_ref()?
                .emission(u_position, u_direction)?,
        };
        s.throughput /= pmf;
        s.error = self.offset.spawn_error(s.error, s.normal);
        s.pdf_position *= pmf;
        s.light = index as u32;
        (s.throughput.is_finite() && s.pdf_position > 0.0).then_some(s)
    }

    /// Density (solid angle, including selection) that [`Lights::sample`] gives
    /// to the point `point` with normal `normal` on light `light`, as seen from
    /// `reference`. Used for the MIS weight of BSDF-sampled hits on lights.
    #[inline]
    pub fn pdf(&self, light: u32, reference: Vec3A, point: Vec3A, normal: Vec3A) -> f32 {
        if light as usize >= self.lights.len() {
            return self.environment_pdf((point - reference).normalize());
        }
        match &self.selection {
            Some(table) => {
                table.pmf(light as usize)
                    * self.lights[light as usize].pdf(reference, point, normal)
            }
            None => 0.0,
        }
    }

    /// Densities with which [`Lights::sample_emission`] makes a particle
    /// leave light `light` at a point of normal `normal` in direction `w`:
    /// by area (including the light's selection; for point lights the
    /// selection alone, a discrete probability) and by solid angle.
    #[inline]
    pub fn emission_pdf(&self, light: u32, normal: Vec3A, w: Vec3A) -> (f32, f32) {
        let Some(table) = &self.selection else {
            return (0.0, 0.0);
        };
        let pmf = table.pmf(light as usize);
        let Some(&emitter) = self.lights.get(light as usize) else {
            // The environment: a point on its disc, a direction by its map.
            return match &self.environment {
                Some(env) => (
                    pmf / (std::f32::consts::PI * env.radius * env.radius),
                    env.pdf(-w),
                ),
                None => (0.0, 0.0),
            };
        };
        let (area, two_sided) = match emitter {
            Light::Triangle(p) | Light::Parallelogram(p) => (p.area, p.two_sided),
            Light::Sphere {
                radius, two_sided, ..
            } => (4.0 * PI * radius * radius, two_sided),
            Light::Point { .. } => return (pmf, 1.0 / (4.0 * PI)),
            Light::Spot { cone, .. } => {
                let inside = cone.axis.dot(w) > cone.cutoff.cos();
                return (pmf, if inside { cone.pdf() } else { 0.0 });
            }
            Light::Directional { radius, .. } => return (pmf / (PI * radius * radius), 1.0),
        };
        // Cosine-weighted about the normal, on one side or on each side
        // with probability 1/2 (see `emission_direction`).
        let cos = normal.dot(w);
        let pdf_direction = if two_sided {
            0.5 * cos.abs() * std::f32::consts::FRAC_1_PI
        } else {
            cos.max(0.0) * std::f32::consts::FRAC_1_PI
        };
        (pmf / area, pdf_direction)
    }
}

impl Environment {
    /// A light sample towards the environment from `reference`: a point
    /// beyond the scene's bounding sphere in the sampled direction.
    #[inline]
    fn sample_from(&self, reference: Vec3A, u: Vec2) -> Option<LightSample> {
        let (wi, radiance, pdf) = self.sample(u)?;
        let distance = super::light::beyond_bounds(reference, self.center, self.radius);
        Some(LightSample {
            point: reference + wi * distance,
            error: Vec3A::ZERO,
            normal: Vec3A::ZERO,
            wi,
            distance,
            radiance,
            pdf,
            delta: false,
            light: 0,
        })
    }

    /// A particle from the environment (see [`Environment::sample_particle`]).
    #[inline]
    fn emission(&self, u_position: Vec2, u_direction: Vec2) -> Option<EmissionSample> {
        let (point, direction, le, pdf_position, pdf_direction) =
            self.sample_particle(u_position, u_direction)?;
        Some(EmissionSample {
            point,
            error: Vec3A::ZERO,
            normal: direction,
            direction,
            throughput: le / (pdf_position * pdf_direction),
            // The disc is not a surface the camera could see.
            emitted: Rgb::ZERO,
            two_sided: false,
            pdf_position,
            pdf_direction,
            light: 0,
            cone: None,
        })
    }
}
