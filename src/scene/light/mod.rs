//! Light sources and their sampling for next-event estimation.
//!
//! Every emissive triangle and sphere is an area light; point lights are
//! deltas. A light is chosen in proportion to its emitted power (alias table),
//! then a point on it: triangles uniformly by area, spheres by area or by the
//! solid angle they subtend. All densities are returned wrt. solid angle at
//! the shading point, so the integrators can combine them with BSDF densities.

pub use super::lights::Lights;
use crate::math::{Frame, Rgb, gamma, luminance};
use crate::sampling::spherical_triangle;
use crate::sampling::warp::square_to_concentric_disk;
use crate::sampling::warp::{
    cosine_hemisphere_pdf, sphere_cap_height, square_to_cosine_hemisphere, square_to_uniform_cap,
    square_to_uniform_sphere, square_to_uniform_triangle, uniform_cap_pdf,
};
use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

mod emission;
mod textured;
pub use emission::EmissionSample;
pub use textured::EmissionTexture;

/// How points on area lights are chosen for next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightSampling {
    /// Uniform over the light's area (for spheres, half the samples face
    /// away and are wasted), density d^2 / (cos A) in solid angle.
    Area,
    /// Uniform over the solid angle the light subtends: the cone of a sphere,
    /// the spherical triangle of a triangle (Arvo), density 1 / solid angle.
    #[default]
    SolidAngle,
}

/// One light source.
#[derive(Clone, Copy, Debug)]
pub enum Light {
    /// An emissive triangle: `p0 + b1 e1 + b2 e2` with b1 + b2 <= 1.
    Triangle(PlanarEmitter),
    /// An emissive parallelogram: `p0 + s e1 + t e2` with s, t in [0, 1]; two
    /// triangles of a mesh that share a diagonal, such as the Cornell box's
    /// light, sampled as one. One 2D sample then covers the whole quad (a
    /// stratified 2D point stays stratified over it), with no light choice
    /// between its halves and no square root for a triangle.
    Parallelogram(PlanarEmitter),
    /// An emissive sphere, emitting outwards (and inwards when two-sided).
    Sphere {
        center: Vec3A,
        radius: f32,
        radiance: Rgb,
        two_sided: bool,
        sampling: LightSampling,
    },
    /// An isotropic point light of `intensity` (W/sr per channel).
    Point { position: Vec3A, intensity: Rgb },
    /// A point light emitting into a cone (Mitsuba's `spot`).
    Spot {
        position: Vec3A,
        intensity: Rgb,
        cone: SpotCone,
    },
    /// Parallel light of `irradiance` travelling along `direction` (unit;
    /// Mitsuba's `directional`). Light paths start on a disc of the
    /// scene's bounding radius (`center`, `radius`, set when the scene is
    /// built).
    Directional {
        direction: Vec3A,
        irradiance: Rgb,
        center: Vec3A,
        radius: f32,
    },
}

/// A spot light's cone and falloff: full intensity within `beam_width` of
/// the axis, falling linearly in angle to zero at `cutoff` (Mitsuba's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotCone {
    /// Unit axis the spot points along.
    pub axis: Vec3A,
    /// Angles from the axis, radians.
    pub cutoff: f32,
    pub beam_width: f32,
}

impl SpotCone {
    /// The falloff towards unit direction `w`.
    #[inline]
    pub fn falloff(&self, w: Vec3A) -> f32 {
        let angle = self.angle_to(w);
        if angle >= self.cutoff {
            0.0
        } else if angle <= self.beam_width {
            1.0
        } else {
            ((self.cutoff - angle) / (self.cutoff - self.beam_width).max(1e-6)).clamp(0.0, 1.0)
        }
    }

    /// True when unit direction `w` is inside the cutoff cone.
    #[inline]
    pub fn contains(&self, w: Vec3A) -> bool {
        self.angle_to(w) < self.cutoff
    }

    /// Angle from the axis to unit `w`, from the chord between them: the
    /// acos of a cosine near 1 moves in steps of 3.5e-4 rad in f32, which
    /// made a spot of 0.02° 22% too bright.
    #[inline]
    fn angle_to(&self, w: Vec3A) -> f32 {
        2.0 * (0.5 * (w - self.axis).length()).min(1.0).asin()
    }

    /// Height 1 − cos(cutoff) of the cone's cap, as 2 sin²(cutoff / 2):
    /// exact for narrow spots, where 1 − cos loses its digits.
    #[inline]
    pub fn cap_height(&self) -> f32 {
        2.0 * (0.5 * self.cutoff).sin().powi(2)
    }

    /// Density of a uniform direction within the cutoff cone.
    #[inline]
    pub fn pdf(&self) -> f32 {
        uniform_cap_pdf(self.cap_height().max(f32::MIN_POSITIVE))
    }
}

/// A flat emitter spanned by `e1` and `e2` from `p0`: a triangle or a
/// parallelogram, as its [`Light`] variant says.
#[derive(Clone, Copy, Debug)]
pub struct PlanarEmitter {
    pub p0: Vec3A,
    pub e1: Vec3A,
    pub e2: Vec3A,
    /// Unit normal of the emitting side (one-sided emitters).
    pub normal: Vec3A,
    pub area: f32,
    pub radiance: Rgb,
    pub two_sided: bool,
    pub sampling: LightSampling,
}

impl PlanarEmitter {
    /// The point `p0 + b.x e1 + b.y e2` and its rounding error bound.
    #[inline]
    fn point(&self, b: Vec2) -> (Vec3A, Vec3A) {
        let (p0, e1, e2) = (self.p0, self.e1, self.e2);
        let point = p0 + b.x * e1 + b.y * e2;
        let error = gamma(6) * (p0.abs() + (b.x * e1).abs() + (b.y * e2).abs());
        (point, error)
    }

    /// The point at `b` sampled uniformly by area, seen from `reference`.
    #[inline]
    fn area_sample(&self, reference: Vec3A, b: Vec2) -> Option<LightSample> {
        let (point, error) = self.point(b);
        area_sample(
            reference,
            point,
            error,
            self.normal,
            self.area,
            self.radiance,
            self.two_sided,
        )
    }

    /// A direction uniform in the solid angle of the triangle `o + b1 a +
    /// b2 b` (this emitter or a half of it), with the point where it meets
    /// the triangle (found as barycentrics, so that the point lies on the
    /// triangle with the usual error bound).
    #[inline]
    fn solid_angle_sample(
        &self,
        reference: Vec3A,
        (o, a, b): (Vec3A, Vec3A, Vec3A),
        u: Vec2,
    ) -> Option<LightSample> {
        let (wi, pdf) = spherical_triangle::sample(reference, [o, o + a, o + b], u)?;
        let cos_light = -self.normal.dot(wi);
        if !(cos_light > 0.0 || (self.two_sided && cos_light < 0.0)) {
            return None;
        }
        // Möller-Trumbore for the barycentrics of the hit of reference + t wi.
        let pvec = wi.cross(b);
        let det = a.dot(pvec);
        if det == 0.0 {
            return None;
        }
        let tvec = reference - o;
        let b1 = (tvec.dot(pvec) / det).clamp(0.0, 1.0);
        let qvec = tvec.cross(a);
        let b2 = (wi.dot(qvec) / det).clamp(0.0, 1.0 - b1);
        let point = o + b1 * a + b2 * b;
        let error = gamma(6) * (o.abs() + (b1 * a).abs() + (b2 * b).abs());
        let distance = (point - reference).length();
        if !(distance > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(LightSample {
            point,
            error,
            normal: self.normal,
            wi,
            distance,
            radiance: self.radiance,
            pdf,
            delta: false,
            light: 0,
        })
    }
}

/// A point sampled on a light, seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Point on the light (for shadow rays).
    pub point: Vec3A,
    /// Rounding error bound of `point` (zero for point lights).
    pub error: Vec3A,
    /// Geometric normal at `point` (zero for point lights).
    pub normal: Vec3A,
    /// Unit direction from the shading point to `point`.
    pub wi: Vec3A,
    /// Distance from the shading point to `point`.
    pub distance: f32,
    /// Incident radiance along `wi`; for point lights the irradiance-like
    /// `I / d^2`, which with `pdf` = selection probability gives the right estimator.
    pub radiance: Rgb,
    /// Density wrt. solid angle including the light selection probability;
    /// for point lights the selection probability alone.
    pub pdf: f32,
    /// True for point lights (no MIS: BSDF sampling cannot hit them).
    pub delta: bool,
    /// Which light ([`Lights::sample`] sets it).
    pub light: u32,
}

impl LightSample {
    /// The shadow ray from surface hit `hit` to the sampled point, both ends
    /// moved off their surfaces by their error bounds.
    #[inline]
    pub fn shadow_ray_from(&self, hit: &crate::accel::SurfaceHit) -> crate::math::Ray {
        crate::math::ray_between(
            hit.point,
            hit.error,
            hit.normal,
            self.point,
            self.error,
            self.normal,
        )
        .at_time(hit.time)
    }
}

impl Light {
    /// Emitted power in luminance units, used to choose lights.
    pub fn power(&self) -> f32 {
        match *self {
            Light::Triangle(p) | Light::Parallelogram(p) => {
                luminance(p.radiance) * p.area * PI * if p.two_sided { 2.0 } else { 1.0 }
            }
            Light::Sphere {
                radius,
                radiance,
                two_sided,
                ..
            } => {
                luminance(radiance)
                    * 4.0
                    * PI
                    * radius
                    * radius
                    * PI
                    * if two_sided { 2.0 } else { 1.0 }
            }
            Light::Point { intensity, .. } => luminance(intensity) * 4.0 * PI,
            Light::Spot {
                intensity, cone, ..
            } => luminance(intensity) / cone.pdf(),
            Light::Directional {
                irradiance, radius, ..
            } => luminance(irradiance) * PI * radius * radius,
        }
    }

    /// Samples a point on the light as seen from `reference`; `pdf` excludes selection.
    #[inline(always)]
    pub(super) fn sample(&self, reference: Vec3A, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Triangle(p) => {
                if p.sampling == LightSampling::SolidAngle {
                    let vertices = [p.p0, p.p0 + p.e1, p.p0 + p.e2];
                    if spherical_triangle::usable(spherical_triangle::solid_angle(
                        reference, vertices,
                    )) {
                        return p.solid_angle_sample(reference, (p.p0, p.e1, p.e2), u);
                    }
                }
                p.area_sample(reference, square_to_uniform_triangle(u))
            }
            Light::Parallelogram(p) => {
                if p.sampling == LightSampling::SolidAngle
                    && let Some(omegas) = parallelogram_solid_angles(reference, &p)
                {
                    // Uniform over the union of the halves' spherical
                    // triangles: a half in proportion to its solid angle.
                    let total = omegas[0] + omegas[1];
                    let split = omegas[0] / total;
                    let (half, ux) = if u.x < split {
                        (0, u.x / split)
                    } else {
                        (1, (u.x - split) / (1.0 - split))
                    };
                    let u = Vec2::new(ux.min(ONE_MINUS_EPSILON), u.y);
                    let mut s =
                        p.solid_angle_sample(reference, parallelogram_halves(&p)[half], u)?;
                    s.pdf = 1.0 / total;
                    return Some(s);
                }
                p.area_sample(reference, u)
            }
            Light::Sphere {
                center,
                radius,
                radiance,
                two_sided,
                sampling,
            } => {
                let to_center = center - reference;
                let dc2 = to_center.length_squared();
                let inside = dc2 <= radius * radius * (1.0 + 1e-4);
                if sampling == LightSampling::SolidAngle && !inside {
                    let dc = dc2.sqrt();
                    let cap = sphere_cap_height(radius * radius / dc2);
                    let frame = Frame::from_normal(to_center / dc);
                    let wi = frame.to_world(square_to_uniform_cap(u, cap)).normalize();
                    // Nearest intersection of the sampled direction with the sphere;
                    // clamping the discriminant handles directions at the silhouette.
                    let b = wi.dot(to_center);
                    let perp2 = (to_center - b * wi).length_squared();
                    let half_chord = (radius * radius - perp2).max(0.0).sqrt();
                    let distance = (b - half_chord).max(0.0);
                    let normal = (reference + distance * wi - center).normalize();
                    // Re-projected onto the sphere, as intersections are.
                    let point = center + radius * normal;
                    let error = sphere_point_error(radius * normal, point);
                    let pdf = uniform_cap_pdf(cap);
                    if !pdf.is_finite() {
                        return None;
                    }
                    Some(LightSample {
                        point,
                        error,
                        normal,
                        wi,
                        distance,
                        radiance,
                        pdf,
                        delta: false,
                        light: 0,
                    })
                } else {
                    let normal = square_to_uniform_sphere(u);
                    let point = center + radius * normal;
                    let error = sphere_point_error(radius * normal, point);
                    let area = 4.0 * PI * radius * radius;
                    area_sample(reference, point, error, normal, area, radiance, two_sided)
                }
            }
            Light::Point {
                position,
                intensity,
            } => Some(point_sample(reference, position, |_| intensity)),
            Light::Spot {
                position,
                intensity,
                cone,
            } => {
                let s = point_sample(reference, position, |w| intensity * cone.falloff(w));
                (s.radiance.max_element() > 0.0).then_some(s)
            }
            Light::Directional {
                direction,
                irradiance,
                center,
                radius,
            } => {
                // A point beyond the bounding sphere, against the light.
                let distance = beyond_bounds(reference, center, radius);
                Some(LightSample {
                    point: reference - direction * distance,
                    error: Vec3A::ZERO,
                    normal: Vec3A::ZERO,
                    wi: -direction,
                    distance,
                    radiance: irradiance,
                    pdf: 1.0,
                    delta: true,
                    light: 0,
                })
            }
        }
    }

    /// Solid-angle density (excluding selection) with which `sample` would
    /// produce `point` (normal `normal`) seen from `reference`.
    #[inline]
    pub(super) fn pdf(&self, reference: Vec3A, point: Vec3A, normal: Vec3A) -> f32 {
        let to_light = point - reference;
        let dist2 = to_light.length_squared();
        let cos_light = normal.dot(to_light).abs() / dist2.sqrt();
        match *self {
            Light::Triangle(p) => {
                if p.sampling == LightSampling::SolidAngle {
                    let omega = spherical_triangle::solid_angle(
                        reference,
                        [p.p0, p.p0 + p.e1, p.p0 + p.e2],
                    );
                    if spherical_triangle::usable(omega) {
                        return 1.0 / omega;
                    }
                }
                dist2 / (cos_light * p.area)
            }
            Light::Parallelogram(p) => {
                if p.sampling == LightSampling::SolidAngle
                    && let Some(omegas) = parallelogram_solid_angles(reference, &p)
                {
                    return 1.0 / (omegas[0] + omegas[1]);
                }
                dist2 / (cos_light * p.area)
            }
            Light::Sphere {
                center,
                radius,
                sampling,
                ..
            } => {
                let dc2 = (center - reference).length_squared();
                let inside = dc2 <= radius * radius * (1.0 + 1e-4);
                if sampling == LightSampling::SolidAngle && !inside {
                    uniform_cap_pdf(sphere_cap_height(radius * radius / dc2))
                } else {
                    dist2 / (cos_light * 4.0 * PI * radius * radius)
                }
            }
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => 0.0,
        }
    }
}

/// A distance from `reference` that ends beyond the bounding sphere
/// (`center`, `radius`): where shadow rays towards light at infinity stop.
#[inline]
pub fn beyond_bounds(reference: Vec3A, center: Vec3A, radius: f32) -> f32 {
    2.0 * radius + (reference - center).length()
}

/// A point, uniform by area for `u`, on the disc of the bounding sphere's
/// radius that faces unit direction `toward` from outside the sphere:
/// where light paths from infinity start.
#[inline]
pub fn disc_point(center: Vec3A, radius: f32, toward: Vec3A, u: Vec2) -> Vec3A {
    let disk = square_to_concentric_disk(u) * radius;
    let frame = Frame::from_normal(toward);
    center + radius * toward + frame.s * disk.x + frame.t * disk.y
}

/// The sample of a light at a point: radiance I(w) / d², `w` the unit
/// direction from the light to `reference`.
#[inline(always)]
fn point_sample(
    reference: Vec3A,
    position: Vec3A,
    intensity: impl Fn(Vec3A) -> Rgb,
) -> LightSample {
    let to_light = position - reference;
    let dist2 = to_light.length_squared();
    let distance = dist2.sqrt();
    let wi = to_light / distance;
    LightSample {
        point: position,
        error: Vec3A::ZERO,
        normal: Vec3A::ZERO,
        wi,
        distance,
        radiance: intensity(-wi) / dist2,
        pdf: 1.0,
        delta: true,
        light: 0,
    }
}

/// The two triangles of a parallelogram, split along the diagonal e1 - e2,
/// each as (corner, edge, edge).
#[inline]
fn parallelogram_halves(p: &PlanarEmitter) -> [(Vec3A, Vec3A, Vec3A); 2] {
    [(p.p0, p.e1, p.e2), (p.p0 + p.e1 + p.e2, -p.e1, -p.e2)]
}

/// The solid angles of a parallelogram's halves seen from `reference`, when
/// spherical-triangle sampling is accurate for both; else `None` (area
/// sampling), the same decision in `sample` and `pdf`.
#[inline]
fn parallelogram_solid_angles(reference: Vec3A, p: &PlanarEmitter) -> Option<[f32; 2]> {
    let omegas = parallelogram_halves(p)
        .map(|(o, a, b)| spherical_triangle::solid_angle(reference, [o, o + a, o + b]));
    omegas
        .iter()
        .all(|&omega| spherical_triangle::usable(omega))
        .then_some(omegas)
}

/// Rounding error bound of a point re-projected onto a sphere (pbrt-v4
/// 6.8.5, gamma(5) of the offset from the centre) plus the translation by
/// the centre.
#[inline]
fn sphere_point_error(offset_from_center: Vec3A, point: Vec3A) -> Vec3A {
    gamma(5) * offset_from_center.abs() + gamma(1) * point.abs()
}

/// A point sampled uniformly by area (density 1 / `area`) seen from
/// `reference`, its density converted to solid angle: d^2 / (|cos| A).
/// `None` when the point shows the reference its non-emitting side.
#[inline]
fn area_sample(
    reference: Vec3A,
    point: Vec3A,
    error: Vec3A,
    normal: Vec3A,
    area: f32,
    radiance: Rgb,
    two_sided: bool,
) -> Option<LightSample> {
    let to_light = point - reference;
    let dist2 = to_light.length_squared();
    let distance = dist2.sqrt();
    let wi = to_light / distance;
    let cos_light = -normal.dot(wi);
    if !(cos_light > 0.0 || (two_sided && cos_light < 0.0)) {
        return None;
    }
    let pdf = dist2 / (cos_light.abs() * area);
    Some(LightSample {
        point,
        error,
        normal,
        wi,
        distance,
        radiance,
        pdf,
        delta: false,
        light: 0,
    })
}

/// The largest float below 1, where remapped numbers must stay.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;
