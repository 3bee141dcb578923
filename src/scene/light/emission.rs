//! Particles leaving lights (light tracing, BDPT's and VCM's light
//! subpaths, photon tracing): a point with its density by area and a
//! direction with its density by solid angle.

use super::*;

/// A particle leaving a light, for light tracing: a point with its density
/// by area and a direction with its density by solid angle.
#[derive(Clone, Copy, Debug)]
pub struct EmissionSample {
    pub point: Vec3A,
    /// Rounding error bound of `point`.
    pub error: Vec3A,
    /// Geometric normal at `point` (zero for point lights).
    pub normal: Vec3A,
    /// Unit direction the particle leaves in.
    pub direction: Vec3A,
    /// Le |cos| / (p_select p_area p_direction): the particle's starting weight.
    pub throughput: Rgb,
    /// Radiance (area lights) or intensity (point lights) and whether it is
    /// emitted on both sides, to connect the light point itself to the camera.
    pub emitted: Rgb,
    pub two_sided: bool,
    /// p_select p_area for area lights, p_select for point lights.
    pub pdf_position: f32,
    /// Density of `direction` wrt. solid angle.
    pub pdf_direction: f32,
    /// Which light ([`Lights::sample_emission`] sets it).
    pub light: u32,
    /// A spot light's cone, whose falloff scales what it emits.
    pub cone: Option<SpotCone>,
}

impl EmissionSample {
    /// Emitted radiance (or intensity) from the light point towards `w`.
    #[inline]
    pub fn emitted_towards(&self, w: Vec3A) -> Rgb {
        if let Some(cone) = self.cone {
            return self.emitted * cone.falloff(w);
        }
        if self.normal == Vec3A::ZERO || self.two_sided || self.normal.dot(w) > 0.0 {
            self.emitted
        } else {
            Rgb::ZERO
        }
    }

    /// The particle's first ray, leaving the light point off its surface.
    #[inline]
    pub fn ray(&self) -> crate::math::Ray {
        crate::math::Ray::new(
            crate::math::offset_ray_origin(self.point, self.error, self.normal, self.direction),
            self.direction,
        )
    }

    /// |cos| between the light's normal and `w` (1 for point lights).
    #[inline]
    pub fn cos_at_light(&self, w: Vec3A) -> f32 {
        if self.normal == Vec3A::ZERO {
            1.0
        } else {
            self.normal.dot(w).abs()
        }
    }
}

/// Cosine-weighted direction about `normal`, on a side chosen with `u.x` for
/// two-sided emitters; returns the direction and its solid-angle density.
#[inline]
fn emission_direction(normal: Vec3A, two_sided: bool, mut u: Vec2) -> (Vec3A, f32) {
    let mut side = 1.0;
    let mut side_pdf = 1.0;
    if two_sided {
        side_pdf = 0.5;
        if u.x < 0.5 {
            u.x *= 2.0;
        } else {
            u.x = (u.x - 0.5) * 2.0;
            side = -1.0;
        }
        u.x = u.x.min(ONE_MINUS_EPSILON);
    }
    let local = square_to_cosine_hemisphere(u);
    let direction = Frame::from_normal(normal * side).to_world(local);
    (direction, side_pdf * cosine_hemisphere_pdf(local))
}

impl Light {
    /// Samples a particle: a point uniformly by area (uniform directions for
    /// point lights) and a cosine-weighted direction. Density excludes selection.
    #[inline]
    pub(in crate::scene) fn sample_emission(
        &self,
        u_position: Vec2,
        u_direction: Vec2,
    ) -> Option<EmissionSample> {
        let (point, error, normal, area, radiance, two_sided) = match *self {
            Light::Triangle(p) | Light::Parallelogram(p) => {
                let b = if matches!(self, Light::Triangle(_)) {
                    square_to_uniform_triangle(u_position)
                } else {
                    u_position
                };
                let (point, error) = p.point(b);
                (point, error, p.normal, p.area, p.radiance, p.two_sided)
            }
            Light::Sphere {
                center,
                radius,
                radiance,
                two_sided,
                ..
            } => {
                let normal = square_to_uniform_sphere(u_position);
                let point = center + radius * normal;
                let error = sphere_point_error(radius * normal, point);
                (
                    point,
                    error,
                    normal,
                    4.0 * PI * radius * radius,
                    radiance,
                    two_sided,
                )
            }
            Light::Point {
                position,
                intensity,
            } => {
                let direction = square_to_uniform_sphere(u_direction);
                return Some(EmissionSample {
                    point: position,
                    error: Vec3A::ZERO,
                    normal: Vec3A::ZERO,
                    direction,
                    // I / (1 / 4 pi).
                    throughput: intensity * (4.0 * PI),
                    emitted: intensity,
                    two_sided: true,
                    pdf_position: 1.0,
                    pdf_direction: 1.0 / (4.0 * PI),
                    light: 0,
                    cone: None,
                });
            }
            Light::Spot {
                position,
                intensity,
                cone,
            } => {
                // Uniform within the cutoff cone.
                let local = square_to_uniform_cap(u_direction, cone.cap_height());
                let direction = Frame::from_normal(cone.axis).to_world(local).normalize();
                return Some(EmissionSample {
                    point: position,
                    error: Vec3A::ZERO,
                    normal: Vec3A::ZERO,
                    direction,
                    throughput: intensity * (cone.falloff(direction) / cone.pdf()),
                    emitted: intensity,
                    two_sided: true,
                    pdf_position: 1.0,
                    pdf_direction: cone.pdf(),
                    light: 0,
                    cone: Some(cone),
                });
            }
            Light::Directional {
                direction,
                irradiance,
                center,
                radius,
            } => {
                let point = disc_point(center, radius, -direction, u_position);
                let pdf_position = 1.0 / (PI * radius * radius);
                return Some(EmissionSample {
                    point,
                    error: Vec3A::ZERO,
                    normal: direction,
                    direction,
                    throughput: irradiance / pdf_position,
                    // The disc is not a surface the camera could see.
                    emitted: Rgb::ZERO,
                    two_sided: false,
                    pdf_position,
                    pdf_direction: 1.0,
                    light: 0,
                    cone: None,
                });
            }
        };
        let (direction, pdf_direction) = emission_direction(normal, two_sided, u_direction);
        let cos = normal.dot(direction).abs();
        if pdf_direction <= 0.0 || cos <= 0.0 {
            return None;
        }
        Some(EmissionSample {
            point,
            error,
            normal,
            direction,
            throughput: radiance * (cos * area / pdf_direction),
            emitted: radiance,
            two_sided,
            pdf_position: 1.0 / area,
            pdf_direction,
            light: 0,
            cone: None,
        })
    }
}
