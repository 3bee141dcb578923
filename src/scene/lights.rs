//! All lights of a scene and how one is chosen: the emitters of `light.rs`
//! and the environment, for next-event estimation and for light paths.

use super::environment::{Environment, Towards};
use super::light::{EmissionSample, EmissionTexture, Light, LightSample, LightSampling};
use crate::math::{OffsetMode, Rgb};
use crate::sampling::AliasTable;
use crate::texture::Texture;
use glam::{Vec2, Vec3A};
use std::f32::consts::PI;
use std::sync::Arc;

/// All lights of a scene with their two selection tables.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    lights: Vec<Light>,
    /// Light from infinitely far away; its light id is `lights.len()`.
    environment: Option<Arc<Environment>>,
    /// In proportion to power: particles, and the bidirectional techniques'
    /// light ends, whose MIS weights need one density for both.
    selection: Option<AliasTable>,
    /// Next-event estimation's choice: by power, or by the shares that the
    /// scene's pilot measured for its groups ([`Lights::set_direct_shares`]).
    direct: Option<AliasTable>,
    /// Whether a pilot set `direct`.
    aimed: bool,
    /// How shadow rays stop short of sampled light points.
    offset: OffsetMode,
    /// Per light id, the texture that multiplies its radiance; empty
    /// where no light is textured, so that other scenes pay one length
    /// test per sample.
    textured: Vec<Option<EmissionTexture>>,
    /// The scene's textures, which `textured` indexes (their images are
    /// shared, not copied).
    textures: Vec<Texture>,
    /// Per light id (where any is textured), its texture averaged over
    /// it, 1 for an untextured light: for what treats a light as one
    /// value (Whitted's point lights).
    texture_means: Vec<Rgb>,
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
        // Power until the scene is built and its pilot aims the choice
        // ([`Lights::set_direct_shares`]).
        let direct = selection.clone();
        Lights {
            lights,
            environment: environment.map(Arc::new),
            selection,
            direct,
            aimed: false,
            offset: OffsetMode::Robust,
            textured: Vec::new(),
            textures: Vec::new(),
            texture_means: Vec::new(),
        }
    }

    /// The same lights, those named in `textured` (by light id) with their
    /// radiance multiplied by a texture of `textures`, and chosen by their
    /// radiance averaged over the texture.
    pub fn with_textured_emission(
        self,
        textured: Vec<Option<EmissionTexture>>,
        textures: Vec<Texture>,
    ) -> Lights {
        if textured.iter().all(Option::is_none) {
            return self;
        }
        let texture_means: Vec<Rgb> = textured
            .iter()
            .map(|t| t.map_or(Rgb::ONE, |t| t.mean(&textures)))
            .collect();
        let mut averaged = self.lights.clone();
        for (light, t) in averaged.iter_mut().zip(&textured) {
            let Some(t) = t else { continue };
            let weight = t.choice_weight(&textures);
            match light {
                Light::Triangle(p) | Light::Parallelogram(p) => p.radiance *= weight,
                Light::Sphere { radiance, .. } => *radiance *= weight,
                Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => {}
            }
        }
        let mut powers: Vec<f32> = averaged.iter().map(Light::power).collect();
        if let Some(env) = &self.environment {
            powers.push(env.power());
        }
        let selection = AliasTable::new(&powers);
        Lights {
            direct: selection.clone(),
            selection,
            aimed: false,
            textured,
            textures,
            texture_means,
            ..self
        }
    }

    /// Light `light`'s texture averaged over it; 1 where it has none.
    pub fn texture_mean(&self, light: usize) -> Rgb {
        self.texture_means.get(light).copied().unwrap_or(Rgb::ONE)
    }

    /// The factor by which light `index`'s texture multiplies its
    /// radiance at `point` (normal `normal`) on it, if it is textured.
    #[inline(always)]
    pub fn texture_at(&self, index: usize, point: Vec3A, normal: Vec3A) -> Option<Rgb> {
        let t = self.textured.get(index)?.as_ref()?;
        Some(t.at(&self.lights[index], point, normal, &self.textures))
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

    /// The groups whose shares of next-event estimation's choice a pilot
    /// may set: all bounded lights together (group 0), then each light at
    /// infinity; 0 where there is nothing to weigh (no light of one kind,
    /// or one kind emits nothing), and power alone decides.
    pub fn direct_groups(&self) -> usize {
        let Some(table) = &self.selection else {
            return 0;
        };
        let ids = 0..self.count();
        let (mut near, mut far, mut far_power) = (0.0, 0, 0.0);
        for i in ids {
            if self.is_infinite(i as u32) {
                (far, far_power) = (far + 1, far_power + table.pmf(i));
            } else {
                near += table.pmf(i);
            }
        }
        if near > 0.0 && far_power > 0.0 {
            1 + far
        } else {
            0
        }
    }

    /// Each light's group in [`Lights::direct_groups`]'s numbering, by
    /// light id.
    pub fn direct_group_of_each(&self) -> Vec<usize> {
        let mut far = 0;
        (0..self.count() as u32)
            .map(|i| match self.is_infinite(i) {
                true => {
                    far += 1;
                    far
                }
                false => 0,
            })
            .collect()
    }

    /// Next-event estimation chooses group g with probability `shares[g]`
    /// and, within it, by power.
    pub fn set_direct_shares(&mut self, shares: &[f64]) {
        let Some(table) = &self.selection else {
            return;
        };
        let powers: Vec<f32> = (0..self.count()).map(|i| table.pmf(i)).collect();
        let groups = self.direct_group_of_each();
        if let Some(weights) = direct_weights(&powers, &groups, shares) {
            self.direct = AliasTable::new(&weights);
            self.aimed = self.direct.is_some();
        }
    }

    /// Each group's share of next-event estimation's choice beside its
    /// share by power, for the render summary; None where no pilot set them.
    pub fn direct_summary(&self) -> Option<String> {
        let (Some(direct), Some(power), true) = (&self.direct, &self.selection, self.aimed) else {
            return None;
        };
        let groups = self.direct_groups();
        if groups < 2 {
            return None;
        }
        let mut shares = vec![(0.0f32, 0.0f32); groups];
        for (id, g) in self.direct_group_of_each().into_iter().enumerate() {
            shares[g].0 += direct.pmf(id);
            shares[g].1 += power.pmf(id);
        }
        let parts: Vec<String> = shares
            .iter()
            .enumerate()
            .map(|(g, (d, p))| {
                let name = match g {
                    0 => "bounded lights".to_string(),
                    _ if g == groups - 1 && self.environment.is_some() => "the environment".into(),
                    _ => format!("directional light {g}"),
                };
                format!("{name} {:.0}% (by power {:.0}%)", 100.0 * d, 100.0 * p)
            })
            .collect();
        Some(format!(
            "shadow rays' light choice, measured by a pilot: {}",
            parts.join(", ")
        ))
    }

    /// The share of next-event estimation's choices that goes to light
    /// `light`: for tests and summaries.
    pub fn direct_pmf(&self, light: u32) -> f32 {
        self.direct.as_ref().map_or(0.0, |t| t.pmf(light as usize))
    }

    /// Lights and the environment: the light ids.
    #[inline]
    fn count(&self) -> usize {
        self.lights.len() + usize::from(self.environment.is_some())
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
        match (&self.environment, &self.direct) {
            (Some(env), Some(table)) => table.pmf(self.lights.len()) * env.pdf(d),
            _ => 0.0,
        }
    }

    /// [`Lights::environment_pdf`] of an [`Environment::towards`].
    #[inline]
    pub fn environment_pdf_towards(&self, towards: Towards) -> f32 {
        match (&self.environment, &self.direct) {
            (Some(env), Some(table)) => table.pmf(self.lights.len()) * env.pdf_towards(towards),
            _ => 0.0,
        }
    }

    /// [`Lights::environment_pdf`] for [`Lights::sample_as_emitted`].
    #[inline]
    pub fn environment_pdf_as_emitted(&self, d: Vec3A) -> f32 {
        match (&self.environment, &self.selection) {
            (Some(env), Some(table)) => table.pmf(self.lights.len()) * env.pdf(d),
            _ => 0.0,
        }
    }

    /// [`Lights::environment_pdf_as_emitted`] of an [`Environment::towards`].
    #[inline]
    pub fn environment_pdf_as_emitted_towards(&self, towards: Towards) -> f32 {
        match (&self.environment, &self.selection) {
            (Some(env), Some(table)) => table.pmf(self.lights.len()) * env.pdf_towards(towards),
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
            direct: self.direct.clone(),
            aimed: self.aimed,
            offset: self.offset,
            textured: self.textured.clone(),
            textures: self.textures.clone(),
            texture_means: self.texture_means.clone(),
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
        self.count() > 1
    }

    /// Chooses a light with `u_select` and a point on it with `u`, for next-event
    /// estimation from `reference`. The pdf includes the selection probability.
    #[inline(always)]
    pub fn sample(&self, reference: Vec3A, u_select: f32, u: Vec2) -> Option<LightSample> {
        let table = self.direct.as_ref()?;
        Some(
            self.sample_from_table::<false>(table, reference, u_select, u)?
                .0,
        )
    }

    /// [`Lights::sample`], except that where it samples the environment its
    /// `radiance` is left at 1 and the map coordinates to look it up at
    /// ([`Environment::le_at`]) come beside it, with their texels asked for:
    /// a path tracer looks them up only where the shadow ray is clear
    /// (living-room: the lookup's cache misses were 11% of the time, and
    /// most of its shadow rays end on the walls).
    #[inline(always)]
    pub fn sample_deferred(
        &self,
        reference: Vec3A,
        u_select: f32,
        u: Vec2,
    ) -> Option<(LightSample, Option<Vec2>)> {
        self.sample_from_table::<true>(self.direct.as_ref()?, reference, u_select, u)
    }

    /// The radiance of a sample from [`Lights::sample_deferred`] or
    /// [`Lights::sample_as_emitted_deferred`]: the environment's at the map
    /// coordinates `deferred` where it left them, else `radiance` as given.
    #[inline(always)]
    pub fn deferred_radiance(&self, deferred: Option<Vec2>, radiance: Rgb) -> Rgb {
        match (deferred, &self.environment) {
            (Some(uv), Some(environment)) => environment.le_at(uv),
            _ => radiance,
        }
    }

    /// [`Lights::sample`] with the light chosen as [`Lights::sample_emission`]
    /// chooses it: the connection to a light of BDPT and VCM, whose weights
    /// give a path's light end one density whichever strategy made it.
    #[inline(always)]
    pub fn sample_as_emitted(
        &self,
        reference: Vec3A,
        u_select: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let table = self.selection.as_ref()?;
        Some(
            self.sample_from_table::<false>(table, reference, u_select, u)?
                .0,
        )
    }

    /// [`Lights::sample_as_emitted`], leaving the environment's radiance as
    /// [`Lights::sample_deferred`] does (BDPT's and VCM's connections to
    /// a light look it up behind a clear shadow ray).
    #[inline(always)]
    pub fn sample_as_emitted_deferred(
        &self,
        reference: Vec3A,
        u_select: f32,
        u: Vec2,
    ) -> Option<(LightSample, Option<Vec2>)> {
        self.sample_from_table::<true>(self.selection.as_ref()?, reference, u_select, u)
    }

    /// A light sample; with `DEFER`, an environment sample's radiance is
    /// left to look up at the coordinates returned beside it.
    #[inline(always)]
    fn sample_from_table<const DEFER: bool>(
        &self,
        table: &AliasTable,
        reference: Vec3A,
        u_select: f32,
        u: Vec2,
    ) -> Option<(LightSample, Option<Vec2>)> {
        // One light needs no choice (the Cornell box); its pmf is 1.
        let (index, pmf) = if self.has_choice() {
            table.sample(u_select)
        } else {
            (0, table.pmf(0))
        };
        let mut deferred = None;
        let mut s = match self.lights.get(index) {
            Some(light) => light.sample(reference, u)?,
            None => {
                let environment = self.environment.as_ref()?;
                let (s, uv) = environment.sample_from::<DEFER>(reference, u)?;
                deferred = uv;
                s
            }
        };
        if let Some(texture) = self.texture_at(index, s.point, s.normal) {
            s.radiance *= texture;
        }
        s.pdf *= pmf;
        s.light = index as u32;
        s.error = self.offset.spawn_error(s.error, s.normal);
        (s.pdf > 0.0 && s.pdf.is_finite() && s.distance > 0.0).then_some((s, deferred))
    }

    /// A hint before [`Lights::sample`] with the same numbers: where that
    /// sample would be the environment's, the line of its table that it
    /// reads is fetched into the cache while the caller traces
    /// (living-room: that miss held 14% of path tracing's time).
    #[inline(always)]
    pub fn prefetch_sample(&self, u_select: f32, u: Vec2) {
        self.prefetch_environment(self.direct.as_ref(), u_select, u);
    }

    /// [`Lights::prefetch_sample`] for [`Lights::sample_as_emitted`].
    #[inline(always)]
    pub fn prefetch_sample_as_emitted(&self, u_select: f32, u: Vec2) {
        self.prefetch_environment(self.selection.as_ref(), u_select, u);
    }

    #[inline(always)]
    fn prefetch_environment(&self, table: Option<&AliasTable>, u_select: f32, u: Vec2) {
        let (Some(environment), Some(table)) = (&self.environment, table) else {
            return;
        };
        let index = if self.has_choice() {
            table.sample(u_select).0
        } else {
            0
        };
        if index < self.lights.len() {
            return;
        }
        environment.prefetch_sample(u);
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
        if let Some(texture) = self.texture_at(index, s.point, s.normal) {
            s.emitted *= texture;
            s.throughput *= texture;
        }
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
        match &self.direct {
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
                return (pmf, if cone.contains(w) { cone.pdf() } else { 0.0 });
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

/// Weights that give group `groups[i]` the share `shares[group]` of the
/// choice, split by `powers` within it; a group without power passes its
/// share on to the others. None where a light's group has no share.
fn direct_weights(powers: &[f32], groups: &[usize], shares: &[f64]) -> Option<Vec<f32>> {
    let mut totals = vec![0.0f64; shares.len()];
    for (&p, &g) in powers.iter().zip(groups) {
        *totals.get_mut(g)? += f64::from(p);
    }
    let weights = powers
        .iter()
        .zip(groups)
        .map(|(&p, &g)| match totals[g] {
            t if t > 0.0 => (f64::from(p) * shares[g] / t) as f32,
            _ => 0.0,
        })
        .collect();
    Some(weights)
}

impl Environment {
    /// A light sample towards the environment from `reference`: a point
    /// beyond the scene's bounding sphere in the sampled direction.
    /// With `DEFER`, the radiance is 1 and the map coordinates to look it
    /// up at come beside the sample, their texels asked for.
    #[inline]
    fn sample_from<const DEFER: bool>(
        &self,
        reference: Vec3A,
        u: Vec2,
    ) -> Option<(LightSample, Option<Vec2>)> {
        let (wi, uv, pdf) = self.sample_direction(u)?;
        let (radiance, deferred) = if DEFER {
            self.prefetch_le(uv);
            (Rgb::ONE, Some(uv))
        } else {
            (self.le_at(uv), None)
        };
        let distance = super::light::beyond_bounds(reference, self.center, self.radius);
        let sample = LightSample {
            point: reference + wi * distance,
            error: Vec3A::ZERO,
            normal: Vec3A::ZERO,
            wi,
            distance,
            radiance,
            pdf,
            delta: false,
            light: 0,
        };
        Some((sample, deferred))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_group_gets_its_share_split_by_power() {
        // Two spots of 60 and 40, a sun of 100 and a sky of 900, shares
        // 0.5, 0.2, 0.3 for the spots, the sun and the sky.
        let powers = [60.0, 40.0, 100.0, 900.0];
        let w = direct_weights(&powers, &[0, 0, 1, 2], &[0.5, 0.2, 0.3]).unwrap();
        let total: f32 = w.iter().sum();
        let share: Vec<f32> = w.iter().map(|x| x / total).collect();
        for (got, want) in share.iter().zip([0.3, 0.2, 0.2, 0.3]) {
            assert!((got - want).abs() < 1e-6, "{share:?}");
        }
        // A group without power passes its share on.
        let w = direct_weights(&[0.0, 5.0, 5.0], &[0, 1, 2], &[0.5, 0.2, 0.3]).unwrap();
        assert_eq!(w[0], 0.0);
        assert!((w[1] / w[2] - 2.0 / 3.0).abs() < 1e-6);
        assert!(direct_weights(&[1.0, 1.0], &[0, 2], &[0.5, 0.5]).is_none());
    }
}
