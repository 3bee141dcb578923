//! Light from infinitely far away: a constant environment or a lat-long
//! environment map (Mitsuba's `constant` and `envmap`), with a to-world
//! rotation and a scale. Maps are importance-sampled by a piecewise-
//! constant density of luminance × sin θ over their texels (each texel's
//! weight the largest of its 3 × 3 neighbourhood, so that no direction the
//! bilinear lookup lights has density zero); the density in solid angle is
//! p(u, v) / (2π² sin θ). Light paths start on a disc of the scene's
//! bounding radius facing the sampled direction.

use crate::math::{Rgb, luminance};
use crate::sampling::piecewise::Piecewise2D;
use crate::sampling::warp::square_to_uniform_sphere;
use crate::texture::Bitmap;
use glam::{Mat3A, Vec2, Vec3A};
use std::f32::consts::PI;
use std::sync::Arc;

/// What the environment shows.
#[derive(Clone, Debug)]
pub enum Radiance {
    Constant(Rgb),
    /// Lat-long: u = φ / 2π with φ measured from −z towards +x, v = θ / π
    /// from +y (Mitsuba's envmap convention), row 0 at the top.
    Map(Arc<Bitmap>),
}

/// A direction towards the environment and, on a map, its coordinates
/// ([`Environment::towards`]).
#[derive(Clone, Copy, Debug)]
pub struct Towards {
    pub d: Vec3A,
    uv: Option<Vec2>,
    sin_theta: f32,
}

/// An environment light.
#[derive(Clone, Debug)]
pub struct Environment {
    pub radiance: Radiance,
    pub scale: f32,
    to_world: Mat3A,
    to_local: Mat3A,
    distribution: Option<Piecewise2D>,
    /// The scene's bounding sphere (set by [`Environment::bound`]).
    pub center: Vec3A,
    pub radius: f32,
}

impl Environment {
    /// An environment of `radiance` × `scale`, rotated by `to_world`.
    pub fn new(radiance: Radiance, scale: f32, to_world: Mat3A) -> Environment {
        let distribution = match &radiance {
            Radiance::Constant(_) => None,
            Radiance::Map(map) => {
                let (w, h) = (map.width, map.height);
                // Each texel's weight is the largest luminance of its 3 × 3
                // neighbourhood (wrapping in φ, clamped in θ) times sin θ:
                // luminance once per texel, then the max in x, then in y,
                // rows in parallel (the same values as the 9-texel loop).
                use rayon::prelude::*;
                let mut lum = vec![0.0f32; w * h];
                lum.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                    for (x, l) in row.iter_mut().enumerate() {
                        *l = luminance(map.at(x, y));
                    }
                });
                let mut across = vec![0.0f32; w * h];
                across.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                    let l = &lum[y * w..(y + 1) * w];
                    for (x, m) in row.iter_mut().enumerate() {
                        *m = l[(x + w - 1) % w].max(l[x]).max(l[(x + 1) % w]);
                    }
                });
                // The luminances are spent: their buffer takes the weights.
                let mut weights = lum;
                weights.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                    let sin_theta = ((y as f32 + 0.5) / h as f32 * PI).sin();
                    let (up, down) = (y.saturating_sub(1), (y + 1).min(h - 1));
                    for (x, m) in row.iter_mut().enumerate() {
                        let a = across[up * w + x]
                            .max(across[y * w + x])
                            .max(across[down * w + x]);
                        *m = a * sin_theta;
                    }
                });
                Some(Piecewise2D::new(&weights, w, h))
            }
        };
        Environment {
            radiance,
            scale,
            to_world,
            to_local: to_world.transpose(),
            distribution,
            center: Vec3A::ZERO,
            radius: 1.0,
        }
    }

    /// The same environment sampled uniformly over the sphere: the
    /// baseline that importance sampling is measured against.
    pub fn with_uniform_sampling(mut self) -> Environment {
        self.distribution = None;
        self
    }

    /// Places the environment around a scene bounded by the given sphere.
    pub fn bound(&mut self, center: Vec3A, radius: f32) {
        self.center = center;
        self.radius = radius.max(1e-3);
    }

    /// Radiance arriving from direction `d` (unit, pointing away from the scene).
    #[inline]
    pub fn le(&self, d: Vec3A) -> Rgb {
        self.le_towards(self.towards(d))
    }

    /// Direction `d` with its map coordinates, for a caller that reads both
    /// the radiance and a density there (a ray that left the scene): the
    /// arc tangent and cosine of the conversion once, not twice.
    #[inline]
    pub fn towards(&self, d: Vec3A) -> Towards {
        match &self.radiance {
            Radiance::Constant(_) => Towards {
                d,
                uv: None,
                sin_theta: 0.0,
            },
            Radiance::Map(_) => {
                let local = self.to_local * d;
                Towards {
                    d,
                    uv: Some(direction_to_uv(local)),
                    sin_theta: sin_theta_of(local),
                }
            }
        }
    }

    /// [`Environment::le`] of a [`Environment::towards`].
    #[inline]
    pub fn le_towards(&self, towards: Towards) -> Rgb {
        // A constant environment reads no coordinates.
        self.le_at(towards.uv.unwrap_or(Vec2::ZERO))
    }

    /// Radiance at map coordinates `uv` (as [`Environment::sample_direction`]
    /// gives them).
    #[inline]
    pub fn le_at(&self, uv: Vec2) -> Rgb {
        match &self.radiance {
            Radiance::Constant(c) => *c * self.scale,
            Radiance::Map(map) => lookup(map, uv) * self.scale,
        }
    }

    /// A direction with its radiance and density in solid angle.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3A, Rgb, f32)> {
        let (d, uv, pdf) = self.sample_direction(u)?;
        Some((d, self.le_at(uv), pdf))
    }

    /// A direction, its map coordinates (for [`Environment::le_at`]) and
    /// its density in solid angle.
    #[inline]
    pub fn sample_direction(&self, u: Vec2) -> Option<(Vec3A, Vec2, f32)> {
        let Some(distribution) = &self.distribution else {
            let d = square_to_uniform_sphere(u);
            return Some((d, direction_to_uv(self.to_local * d), 1.0 / (4.0 * PI)));
        };
        let (uv, pdf_uv) = distribution.sample(u);
        let (local, sin_theta) = uv_to_direction_and_sin_theta(uv);
        if pdf_uv <= 0.0 || sin_theta <= 0.0 {
            return None;
        }
        let d = (self.to_world * local).normalize();
        // The sample's own density and coordinates, as pbrt and Mitsuba
        // give them: reading them back from the direction (an arc tangent,
        // an arc cosine, a sine and a second table read) differs only where
        // rounding moves a direction across a cell's edge.
        Some((d, uv, per_solid_angle(pdf_uv, sin_theta)))
    }

    /// Asks the cache for the texels that [`Environment::le_at`] reads at
    /// `uv`: a caller that looks the radiance up only once its shadow ray
    /// is found clear fetches them meanwhile.
    #[inline(always)]
    pub fn prefetch_le(&self, uv: Vec2) {
        if let Radiance::Map(map) = &self.radiance {
            let (x, y, _, _) = bilinear_corner(map, uv);
            map.prefetch(x, y);
            map.prefetch(x, (y + 1).min(map.height - 1));
        }
    }

    /// Asks the cache for the table line that [`Environment::sample`]
    /// reads for `u`: the caller knows u before it traces the ray whose
    /// hit the sample lights, and the line arrives meanwhile.
    #[inline(always)]
    pub fn prefetch_sample(&self, u: Vec2) {
        if let Some(distribution) = &self.distribution {
            distribution.prefetch(u);
        }
    }

    /// Density of [`Environment::sample`] at direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3A) -> f32 {
        let Some(distribution) = &self.distribution else {
            return 1.0 / (4.0 * PI);
        };
        let local = self.to_local * d;
        pdf_at(distribution, direction_to_uv(local), sin_theta_of(local))
    }

    /// [`Environment::pdf`] of a [`Environment::towards`].
    #[inline]
    pub fn pdf_towards(&self, towards: Towards) -> f32 {
        match (&self.distribution, towards.uv) {
            (Some(distribution), Some(uv)) => pdf_at(distribution, uv, towards.sin_theta),
            (Some(_), None) => self.pdf(towards.d),
            (None, _) => 1.0 / (4.0 * PI),
        }
    }

    /// Power, for choosing between lights: π R² ∫ luminance(L) dω.
    /// Bytes of the map's texels and its sampling table.
    pub fn memory_bytes(&self) -> usize {
        let texels = match &self.radiance {
            Radiance::Constant(_) => 0,
            Radiance::Map(map) => map.memory_bytes(),
        };
        texels
            + self
                .distribution
                .as_ref()
                .map_or(0, Piecewise2D::memory_bytes)
    }

    pub fn power(&self) -> f32 {
        let mean = match &self.radiance {
            Radiance::Constant(c) => luminance(*c) * 4.0 * PI,
            Radiance::Map(map) => {
                // ∫ L dω over the texels' solid angles.
                let (w, h) = (map.width, map.height);
                let mut sum = 0.0f64;
                for y in 0..h {
                    let sin_theta = ((y as f32 + 0.5) / h as f32 * PI).sin() as f64;
                    for x in 0..w {
                        sum += luminance(map.at(x, y)) as f64 * sin_theta;
                    }
                }
                (sum * 2.0 * PI as f64 * PI as f64 / (w * h) as f64) as f32
            }
        };
        mean * self.scale * PI * self.radius * self.radius
    }

    /// A particle entering the scene: a direction `d` towards the
    /// environment and a point on the disc of the bounding radius facing
    /// it, outside the bounding sphere. Returns (point, travel direction,
    /// radiance, density of the point on the disc, density of d).
    #[inline]
    pub fn sample_particle(
        &self,
        u_position: Vec2,
        u_direction: Vec2,
    ) -> Option<(Vec3A, Vec3A, Rgb, f32, f32)> {
        let (d, le, pdf_direction) = self.sample(u_direction)?;
        let point = super::light::disc_point(self.center, self.radius, d, u_position);
        let pdf_position = 1.0 / (PI * self.radius * self.radius);
        Some((point, -d, le, pdf_position, pdf_direction))
    }
}

/// Density per solid angle of `distribution` at map coordinates `uv`, of
/// polar angle θ.
#[inline]
fn pdf_at(distribution: &Piecewise2D, uv: Vec2, sin_theta: f32) -> f32 {
    per_solid_angle(distribution.pdf(uv), sin_theta)
}

/// A density over map coordinates as one over solid angle, at polar angle
/// θ: the lat-long map's Jacobian, 2π² sin θ (none at the poles).
#[inline]
fn per_solid_angle(pdf_uv: f32, sin_theta: f32) -> f32 {
    if sin_theta <= 0.0 {
        return 0.0;
    }
    pdf_uv / (2.0 * PI * PI * sin_theta)
}

/// The map at `uv`, bilinear between texels placed as Mitsuba's envmap
/// places them (checked against its `eval` to 1e-5 of the peak): texel
/// (i, j) at u = (i + 1/2) / width (wrapping), v = j / (height − 1), so the
/// first and last rows are the poles.
#[inline]
fn lookup(map: &Bitmap, uv: Vec2) -> Rgb {
    if !uv.is_finite() {
        return Rgb::ZERO;
    }
    let (x0, y0, fx, fy) = bilinear_corner(map, uv);
    let x1 = (x0 + 1) % map.width;
    let y1 = (y0 + 1).min(map.height - 1);
    let t = |x: usize, y: usize| map.at(x, y);
    (t(x0, y0) * (1.0 - fx) + t(x1, y0) * fx) * (1.0 - fy)
        + (t(x0, y1) * (1.0 - fx) + t(x1, y1) * fx) * fy
}

/// The texel at the top left of the 2 × 2 that [`lookup`] blends at `uv`
/// (in range: a non-finite uv lands on a corner, the casts saturating),
/// and the blend's fractions along x and y.
#[inline(always)]
fn bilinear_corner(map: &Bitmap, uv: Vec2) -> (usize, usize, f32, f32) {
    let (w, h) = (map.width, map.height);
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * (h.max(2) - 1) as f32;
    let (x0, y0) = (x.floor(), y.floor().clamp(0.0, (h.max(2) - 2) as f32));
    let (fx, fy) = (x - x0, (y - y0).clamp(0.0, 1.0));
    (
        (x0 as i64).rem_euclid(w as i64) as usize,
        (y0 as usize).min(h - 1),
        fx,
        fy,
    )
}

/// Mitsuba's lat-long coordinates of a local direction.
#[inline]
pub fn direction_to_uv(v: Vec3A) -> Vec2 {
    let u = v.x.atan2(-v.z) * (0.5 / PI);
    let u = u - u.floor();
    let theta = v.y.clamp(-1.0, 1.0).acos();
    Vec2::new(u, theta / PI)
}

/// sin θ of a local unit direction (θ from +y, as [`direction_to_uv`]
/// reads it): from the other two coordinates, no sine, and precise near
/// the poles where 1 − y² would cancel.
#[inline]
fn sin_theta_of(v: Vec3A) -> f32 {
    (v.x * v.x + v.z * v.z).sqrt()
}

/// The local direction of lat-long coordinates.
#[inline]
pub fn uv_to_direction(uv: Vec2) -> Vec3A {
    uv_to_direction_and_sin_theta(uv).0
}

/// [`uv_to_direction`] and the sine of its polar angle, zero at the poles
/// where a sample's density is infinite (computed once: a second sine
/// was 1% of path tracing's time on Bitterli's living room).
#[inline]
fn uv_to_direction_and_sin_theta(uv: Vec2) -> (Vec3A, f32) {
    let (sin_theta, cos_theta) = (uv.y * PI).sin_cos();
    let (sin_phi, cos_phi) = (uv.x * 2.0 * PI).sin_cos();
    (
        Vec3A::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi),
        sin_theta,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lat_long_coordinates_round_trip() {
        for uv in [
            Vec2::new(0.1, 0.3),
            Vec2::new(0.7, 0.9),
            Vec2::new(0.5, 0.5),
        ] {
            let back = direction_to_uv(uv_to_direction(uv));
            assert!((back - uv).abs().max_element() < 1e-5, "{uv} -> {back}");
        }
        // Mitsuba: up is +y, u = 0 looks along -z.
        assert!((uv_to_direction(Vec2::new(0.0, 0.5)) - Vec3A::NEG_Z).length() < 1e-6);
        assert!((uv_to_direction(Vec2::new(0.25, 0.5)) - Vec3A::X).length() < 1e-6);
    }
}
