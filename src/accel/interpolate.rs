//! What a hit interpolates when asked: the shading normal, texture
//! coordinates and their derivatives, on the geometry's own triangles and
//! spheres, or read from an instance's prototype and moved back.

use super::*;

impl Geometry {
    /// Asks the cache for triangle `i`'s record, texture coordinates and
    /// vertex normals, which the hit and its shading read (living-room,
    /// staircase: a miss each, after the traversal).
    #[inline(always)]
    pub(super) fn prefetch_shading(&self, i: usize) {
        if let Some(record) = self.tri_shading.get(i) {
            crate::math::prefetch(record);
        }
        if let Some(uvs) = self.tri_uvs.get(i) {
            crate::math::prefetch(uvs);
        }
        if let Some(normals) = self.tri_normals.get(i) {
            crate::math::prefetch(&normals[0]);
            crate::math::prefetch(&normals[2]);
        }
    }

    /// The unit shading normal at `hit`: its triangle's vertex normals
    /// interpolated, else the geometric normal. BSDFs act in its frame;
    /// offsets, emission and area densities keep the geometric one.
    /// Moving objects shade with their geometric normals.
    #[inline(always)]
    pub fn shading_normal(&self, hit: &SurfaceHit) -> Vec3A {
        if hit.instance != NO_INSTANCE {
            return self.instances.shading_normal(hit);
        }
        self.local_shading_normal(hit).unwrap_or(hit.normal)
    }

    /// The interpolated vertex normal at a hit on this geometry's own
    /// triangles, in its space; None where they have none.
    #[inline(always)]
    pub(super) fn local_shading_normal(&self, hit: &SurfaceHit) -> Option<Vec3A> {
        let [n0, n1, n2] = self.tri_normals.get(hit.primitive as usize)?;
        let (b1, b2) = (hit.barycentric.x, hit.barycentric.y);
        let n = ((1.0 - b1 - b2) * *n0 + b1 * *n1 + b2 * *n2).normalize_or_zero();
        (n != Vec3A::ZERO).then_some(n)
    }

    /// Texture coordinates at `hit`: interpolated from its triangle's (the
    /// barycentrics where none were kept), or (φ / 2π, θ / π) on a sphere as
    /// Mitsuba's.
    #[inline]
    pub fn uv(&self, hit: &SurfaceHit) -> Vec2 {
        if hit.instance != NO_INSTANCE {
            return self.instances.uv(hit);
        }
        self.local_uv(hit)
    }

    #[inline]
    pub(super) fn local_uv(&self, hit: &SurfaceHit) -> Vec2 {
        let i = hit.primitive as usize;
        if let Some([t0, t1, t2]) = self.tri_uvs.get(i) {
            let (b1, b2) = (hit.barycentric.x, hit.barycentric.y);
            return (1.0 - b1 - b2) * *t0 + b1 * *t1 + b2 * *t2;
        }
        if hit.primitive & MOVING_PRIMITIVE == 0 && i >= self.tri_vertices.len() {
            return sphere_uv(hit.normal);
        }
        hit.barycentric
    }

    /// Triangle `i`'s texture coordinates at its corners (storage order):
    /// its own, or the barycentric corners that [`Geometry::uv`] falls back on.
    pub fn triangle_uvs(&self, i: usize) -> [Vec2; 3] {
        match self.tri_uvs.get(i) {
            Some(&uvs) => uvs,
            None => [Vec2::ZERO, Vec2::X, Vec2::Y],
        }
    }

    /// dp/du and dp/dv at `hit`, where the surface has texture coordinates
    /// that vary over it: a triangle's kept uvs, or a sphere's (φ / 2π,
    /// θ / π). `None` where uv is degenerate.
    #[inline]
    pub fn uv_derivatives(&self, hit: &SurfaceHit) -> Option<(Vec3A, Vec3A)> {
        if hit.instance != NO_INSTANCE {
            return self.instances.uv_derivatives(hit);
        }
        self.local_uv_derivatives(hit)
    }

    #[inline]
    pub(super) fn local_uv_derivatives(&self, hit: &SurfaceHit) -> Option<(Vec3A, Vec3A)> {
        let i = hit.primitive as usize;
        if let Some([t0, t1, t2]) = self.tri_uvs.get(i) {
            let [p0, p1, p2] = self.tri_vertices[i];
            let (d1, d2) = (*t1 - *t0, *t2 - *t0);
            let det = d1.x * d2.y - d1.y * d2.x;
            let (e1, e2) = (p1 - p0, p2 - p0);
            let dpdu = (d2.y * e1 - d1.y * e2) / det;
            let dpdv = (d1.x * e2 - d2.x * e1) / det;
            return (det.abs() > 1e-20
                && dpdu.is_finite()
                && dpdv.is_finite()
                && dpdu != Vec3A::ZERO)
                .then_some((dpdu, dpdv));
        }
        if hit.primitive & MOVING_PRIMITIVE == 0 && i >= self.tri_vertices.len() {
            let r = self.spheres[i - self.tri_vertices.len()].radius;
            let n = hit.normal;
            let sin_theta = (n.x * n.x + n.y * n.y).sqrt();
            if sin_theta < 1e-6 {
                return None;
            }
            // p = r (sin θ cos φ, sin θ sin φ, cos θ), u = φ / 2π, v = θ / π.
            let dpdu = std::f32::consts::TAU * r * Vec3A::new(-n.y, n.x, 0.0);
            let dpdv = std::f32::consts::PI
                * r
                * Vec3A::new(n.z * n.x / sin_theta, n.z * n.y / sin_theta, -sin_theta);
            return Some((dpdu, dpdv));
        }
        None
    }
}

/// A sphere's texture coordinates at outward unit normal `n`: longitude
/// about z over 2π, colatitude over π.
#[inline]
pub fn sphere_uv(n: Vec3A) -> Vec2 {
    let phi = n.y.atan2(n.x);
    let phi = if phi < 0.0 {
        phi + std::f32::consts::TAU
    } else {
        phi
    };
    Vec2::new(
        phi * (0.5 * std::f32::consts::FRAC_1_PI),
        n.z.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI,
    )
}
