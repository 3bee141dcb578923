//! Ray queries whose possible hits are known in advance (by the
//! small-scene shortcuts, `crate::shortcuts`): each tests only the triangles
//! it is given, by the same watertight test, so it returns what the whole
//! query would; and what the shortcuts need to know of the soup.

use super::triangle::ShearedRay;
use super::{Geometry, SurfaceHit, TriangleIndex};
use crate::math::{OffsetMode, Ray};
use glam::Vec3A;

impl Geometry {
    /// True when the geometry is a soup of triangles only, none moving and
    /// none masked:
    /// the soup tests every triangle one by one, so a query among some of
    /// them finds the same hits.
    pub fn is_static_soup(&self) -> bool {
        matches!(self.tri_index, TriangleIndex::Soup(_))
            && self.spheres.is_empty()
            && self.moving.is_empty()
            && self.masks.is_none()
            && self.instances.is_empty()
    }

    /// For a static soup ([`Geometry::is_static_soup`]): its box, and the
    /// number of its inner triangles (the first, in storage order; the
    /// others are faces of the box, which cannot block a segment inside it).
    pub fn static_soup_box(&self) -> Option<(Vec3A, Vec3A, usize)> {
        match &self.tri_index {
            TriangleIndex::Soup(soup) if self.is_static_soup() => {
                let (lo, hi) = soup.bounds();
                Some((lo, hi, soup.inner_triangles()))
            }
            _ => None,
        }
    }

    /// True when the segment of `ray` up to its `t_max` lies inside a
    /// static soup's box, and rays leave surfaces by robust offsets (a fixed
    /// epsilon may end a shadow ray farther off a light than a shortcut's
    /// margin allows for).
    #[inline(always)]
    pub fn segment_inside_soup(&self, ray: &Ray) -> bool {
        matches!(&self.tri_index, TriangleIndex::Soup(soup)
            if self.offset == OffsetMode::Robust && soup.segment_inside(ray, ray.t_max))
    }

    /// [`Geometry::occluded`] for a segment that can only be blocked by the
    /// triangles `occluders`, by the same watertight test.
    #[inline(always)]
    pub fn occluded_among(&self, ray: &Ray, occluders: &[u32]) -> bool {
        if occluders.is_empty() {
            return false;
        }
        let sheared = ShearedRay::new(ray);
        occluders.iter().any(|&i| {
            sheared
                .intersect(&self.tri_vertices[i as usize], ray.t_max)
                .is_some()
        })
    }

    /// [`Geometry::intersect_among`] where the ray's possible hits are known
    /// (a camera ray's candidates), else [`Geometry::intersect_as`].
    #[inline(always)]
    pub fn intersect_maybe_among<const PLAIN: bool>(
        &self,
        ray: &Ray,
        candidates: Option<&[u32]>,
    ) -> Option<SurfaceHit> {
        match candidates {
            Some(among) => self.intersect_among(ray, among),
            None => self.intersect_as::<PLAIN>(ray),
        }
    }

    /// [`Geometry::intersect`] for a ray that can only hit the triangles
    /// `candidates` (in storage order): the same hit, by the same
    /// watertight test, without testing the rest.
    #[inline(always)]
    pub fn intersect_among(&self, ray: &Ray, candidates: &[u32]) -> Option<SurfaceHit> {
        let sheared = ShearedRay::new(ray);
        let mut best: Option<(u32, f32, f32, f32)> = None;
        let mut best_t = ray.t_max;
        for &index in candidates {
            if let Some((t, b1, b2)) = sheared.intersect(&self.tri_vertices[index as usize], best_t)
            {
                best_t = t;
                best = Some((index, t, b1, b2));
            }
        }
        let (index, t, b1, b2) = best?;
        let mut hit = self.triangle_hit(ray, index, self.tri_vertices[index as usize], t, b1, b2);
        if let OffsetMode::Fixed(_) = self.offset {
            hit.error = self.offset.spawn_error(hit.error, hit.normal);
        }
        if let Some(blends) = &self.blends {
            hit.material = blends.material_at(&hit, || self.uv(&hit));
        }
        Some(hit)
    }
}
