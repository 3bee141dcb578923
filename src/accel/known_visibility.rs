//! Ray queries whose possible hits are known in advance: camera rays
//! through a pixel ([`PrimaryCandidates`]) and shadow rays to a flat light
//! from a voxel ([`ShadowVoxels`]). Each tests only those triangles, by the
//! same watertight test, so it returns what the whole query would.

use super::triangle::ShearedRay;
use super::{Geometry, PrimaryCandidates, ShadowVoxels, SurfaceHit, TriangleIndex};
use crate::math::{OffsetMode, Ray};
use crate::scene::camera::Camera;
use glam::Vec3A;

impl Geometry {
    /// True when camera rays may be tested against per-pixel candidates
    /// ([`PrimaryCandidates`]): triangles only, in a soup (whose hits the
    /// candidates' one-by-one test reproduces exactly), none moving.
    pub fn allows_primary_candidates(&self) -> bool {
        matches!(self.tri_index, TriangleIndex::Soup(_))
            && self.spheres.is_empty()
            && self.moving.is_empty()
    }

    /// Candidate lists of `camera`'s pixels for these triangles (see
    /// [`PrimaryCandidates`]), where they apply.
    pub fn primary_candidates(&self, camera: &Camera) -> Option<PrimaryCandidates> {
        if !self.allows_primary_candidates() {
            return None;
        }
        PrimaryCandidates::build(camera, &self.tri_vertices)
    }

    /// Per voxel, the triangles that may block shadow rays to the flat light
    /// `light` (its corners, in order; its own triangles carry the light id
    /// `light_id`), for soups without spheres or motion (see [`ShadowVoxels`]).
    pub fn shadow_voxels(&self, light_id: u32, light: &[Vec3A]) -> Option<ShadowVoxels> {
        let TriangleIndex::Soup(soup) = &self.tri_index else {
            return None;
        };
        if !self.spheres.is_empty() || !self.moving.is_empty() {
            return None;
        }
        // Shadow rays end just before the light's surface, off its own
        // triangles by the light sample's error bound; the soup's face
        // triangles cannot block a segment inside its box.
        let occluders: Vec<(u32, [Vec3A; 3])> = (0..soup.inner_triangles())
            .filter(|&i| self.tri_shading[i].light != light_id)
            .map(|i| (i as u32, self.tri_vertices[i]))
            .collect();
        let (lo, hi) = soup.bounds();
        let margin = (hi - lo).max_element() * 1e-4;
        Some(ShadowVoxels::build(lo, hi, light, &occluders, margin))
    }

    /// [`Geometry::occluded`] for a shadow ray that ends on the light of
    /// `voxels` (built by [`Geometry::shadow_voxels`]): with both ends inside
    /// the box (so that its faces cannot block it, as the soup reasons),
    /// only the origin voxel's occluders are tested, by the same watertight
    /// test, so the answer is the whole test's. A fixed-epsilon offset
    /// (`--offset fixed:E`) may end the ray farther off the light than the
    /// voxels' margin allows for: those rays take the whole test.
    #[inline(always)]
    pub fn occluded_towards(&self, ray: &Ray, voxels: &ShadowVoxels) -> bool {
        if let TriangleIndex::Soup(soup) = &self.tri_index
            && self.offset == OffsetMode::Robust
            && let Some(occluders) = voxels.occluders_from(ray.origin)
            && soup.segment_inside(ray, ray.t_max)
        {
            if occluders.is_empty() {
                return false;
            }
            let sheared = ShearedRay::new(ray);
            return occluders.iter().any(|&i| {
                sheared
                    .intersect(&self.tri_vertices[i as usize], ray.t_max)
                    .is_some()
            });
        }
        self.occluded(ray)
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
        Some(hit)
    }
}
