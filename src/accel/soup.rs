//! Small meshes without a BVH: every triangle is tested, eight at a time.
//!
//! For a few dozen triangles (the Cornell box has 32) a hierarchy costs more
//! than it saves: a ray visits several nodes to reach 3 triangles. Here the
//! watertight test of `triangle.rs` (Woop, Benthin & Wald) runs on eight
//! triangles per instruction (`block.rs`). Measured on the Cornell box:
//! bounding boxes per block tested first (grouped by a surface-area split)
//! cost more than they saved, 2.99 -> 2.70 M paths/s, with only 4 blocks.
//!
//! Shadow rays skip the triangles that lie in a face of the soup's bounding
//! box (a room's floor, ceiling and walls): a segment between two points of
//! a box meets a face's plane only where an endpoint lies on it, and there
//! the watertight test's conservative t rejects the hit. Those triangles are
//! stored last, so the skip is a shorter loop over whole blocks.

use super::block::{Axes, Block, LANES, TriangleHit};
use crate::math::Ray;
use glam::Vec3A;

/// All triangles of a small scene in blocks of eight.
#[derive(Clone, Debug, Default)]
pub struct TriangleSoup {
    blocks: Vec<Block>,
    /// Blocks from the first that hold a triangle off the bounding box's
    /// faces; the rest hold only face triangles.
    inner_blocks: usize,
    /// Triangles from the first off the bounding box's faces (the rest lie
    /// in a face).
    inner_triangles: usize,
    /// The triangles' bounding box.
    lo: Vec3A,
    hi: Vec3A,
    /// How far inside the box a shadow ray's end must be: covers the
    /// rounding of the end point and of the triangle test's t comparison.
    margin: Vec3A,
}

/// True when the triangle lies in a face plane of the box (lo, hi).
fn on_box_face(triangle: &[Vec3A; 3], lo: Vec3A, hi: Vec3A) -> bool {
    (0..3).any(|axis| {
        triangle.iter().all(|v| v[axis] == lo[axis]) || triangle.iter().all(|v| v[axis] == hi[axis])
    })
}

/// Bounding box of the triangles.
fn bounds(triangles: &[[Vec3A; 3]]) -> (Vec3A, Vec3A) {
    let (mut lo, mut hi) = (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY));
    for v in triangles.iter().flatten() {
        (lo, hi) = (lo.min(*v), hi.max(*v));
    }
    (lo, hi)
}

impl TriangleSoup {
    /// The order to store `triangles` in for [`TriangleSoup::new`]: those in
    /// a face of the bounding box last, the others in input order.
    pub fn order(triangles: &[[Vec3A; 3]]) -> Vec<usize> {
        let (lo, hi) = bounds(triangles);
        let (mut inner, mut face): (Vec<usize>, Vec<usize>) =
            (0..triangles.len()).partition(|&i| !on_box_face(&triangles[i], lo, hi));
        inner.append(&mut face);
        inner
    }

    /// Packs triangles (in the given order) into blocks.
    pub fn new(triangles: &[[Vec3A; 3]]) -> Self {
        let blocks: Vec<Block> = triangles
            .chunks(LANES)
            .enumerate()
            .map(|(b, chunk)| Block::new(chunk, b * LANES))
            .collect();
        let (lo, hi) = bounds(triangles);
        // Face triangles stored last (see `order`); in another order none
        // are skipped.
        let last_inner = triangles
            .iter()
            .rposition(|t| !on_box_face(t, lo, hi))
            .map_or(0, |i| i + 1);
        let extent = lo.abs().max(hi.abs());
        TriangleSoup {
            inner_blocks: last_inner.div_ceil(LANES),
            inner_triangles: last_inner,
            blocks,
            lo,
            hi,
            margin: extent * (64.0 * f32::EPSILON),
        }
    }

    /// True when the shadow ray's origin lies in the bounding box and its end
    /// lies inside it by more than the margin on every axis: the segment
    /// then meets no face plane except at the origin.
    #[inline(always)]
    pub fn segment_inside(&self, ray: &Ray, t_max: f32) -> bool {
        let end = ray.origin + ray.direction * t_max;
        let slack = self.margin + (ray.direction * t_max).abs() * (4.0 * f32::EPSILON);
        ray.origin.cmpge(self.lo).all()
            && ray.origin.cmple(self.hi).all()
            && end.cmpgt(self.lo + slack).all()
            && end.cmplt(self.hi - slack).all()
    }

    /// Triangles (the first ones stored) that can block a shadow ray for
    /// which [`TriangleSoup::segment_inside`] holds: those off the faces.
    pub fn inner_triangles(&self) -> usize {
        self.inner_triangles
    }

    /// The triangles' bounding box.
    pub fn bounds(&self) -> (Vec3A, Vec3A) {
        (self.lo, self.hi)
    }

    /// Bytes of the blocks.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.blocks[..])
    }

    /// Closest hit in (0, t_max).
    #[inline(always)]
    pub fn closest(&self, ray: &Ray, t_max: f32, triangles: &[[Vec3A; 3]]) -> Option<TriangleHit> {
        let axes = Axes::new(ray);
        let mut best = None;
        let mut best_t = t_max;
        let (inner, faces) = self.blocks.split_at(self.inner_blocks);
        for block in inner {
            block.closest(&axes, ray, triangles, &mut best_t, &mut best);
        }
        // The face triangles lie on the box's boundary: a ray from inside
        // meets them no nearer than where it leaves the box, so a hit
        // already nearer than that settles it.
        if best.is_some() && best_t < self.exit_distance(ray) {
            return best;
        }
        for block in faces {
            block.closest(&axes, ray, triangles, &mut best_t, &mut best);
        }
        best
    }

    /// A lower bound on where `ray` leaves the box (0 when its origin is
    /// not inside): the nearest face plane ahead, shortened by far more than
    /// the rounding of this division and of the triangle test's t.
    #[inline(always)]
    fn exit_distance(&self, ray: &Ray) -> f32 {
        let o = ray.origin;
        if !(o.cmpge(self.lo).all() && o.cmple(self.hi).all()) {
            return 0.0;
        }
        let d = ray.direction;
        let ahead = Vec3A::select(d.cmpgt(Vec3A::ZERO), self.hi, self.lo);
        // A zero component gives an infinity, or a NaN that min ignores.
        let t = (ahead - o) / d;
        t.min_element() * (1.0 - 64.0 * f32::EPSILON)
    }

    /// True when a triangle that `accept` accepts is hit in (0, t_max).
    #[inline(always)]
    pub fn any_where(
        &self,
        ray: &Ray,
        t_max: f32,
        triangles: &[[Vec3A; 3]],
        accept: &mut impl FnMut(usize) -> bool,
    ) -> bool {
        let axes = Axes::new(ray);
        let blocks = if self.inner_blocks < self.blocks.len() && self.segment_inside(ray, t_max) {
            &self.blocks[..self.inner_blocks]
        } else {
            &self.blocks[..]
        };
        for block in blocks {
            if block.any_where(&axes, ray, triangles, t_max, accept) {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::triangle::{ShearedRay, closest_by_scalar_test};
    use crate::sampling::hash::{hash_combine, to_unit_float};

    #[test]
    fn agrees_with_the_scalar_test_on_random_rays() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let triangles: Vec<[Vec3A; 3]> = (0..37u64)
            .map(|i| {
                let p = |k| Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) * 2.0 - Vec3A::ONE;
                [p(10), p(20), p(30)]
            })
            .collect();
        let soup = TriangleSoup::new(&triangles);
        for i in 0..20_000u64 {
            let origin = Vec3A::new(u(1, i), u(2, i), u(3, i)) * 4.0 - Vec3A::splat(2.0);
            let direction = (Vec3A::new(u(4, i), u(5, i), u(6, i)) * 2.0 - Vec3A::ONE).normalize();
            let ray = Ray::new(origin, direction);
            let expected = closest_by_scalar_test(&ray, &triangles);
            assert_eq!(
                soup.closest(&ray, f32::INFINITY, &triangles),
                expected,
                "ray {i}"
            );
            assert_eq!(
                soup.any_where(&ray, 1.0, &triangles, &mut |_| true),
                expected.is_some_and(|h| h.1 < 1.0),
                "ray {i}"
            );
        }
    }

    /// A room: the six faces of the box [0, 2]^3 (two triangles each, in
    /// their planes exactly) and random triangles inside. Shadow rays between
    /// points inside and on the faces skip the face triangles, and closest
    /// hits nearer than the box's exit skip them too; both must agree with
    /// testing everything; rays from outside test everything.
    #[test]
    fn rays_that_skip_the_box_faces_agree_with_the_scalar_test() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let corner =
            |c: usize| Vec3A::new((c & 1) as f32, ((c >> 1) & 1) as f32, (c >> 2) as f32) * 2.0;
        let mut triangles: Vec<[Vec3A; 3]> = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                let on_face: Vec<usize> = (0..8).filter(|c| (c >> axis) & 1 == side).collect();
                let [a, b, c, d] = [0, 1, 2, 3].map(|k| corner(on_face[k]));
                triangles.push([a, b, d]);
                triangles.push([a, d, c]);
            }
        }
        for i in 0..13u64 {
            let p = |k| Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) * 1.6 + Vec3A::splat(0.2);
            triangles.push([p(10), p(20), p(30)]);
        }
        let stored: Vec<[Vec3A; 3]> = TriangleSoup::order(&triangles)
            .into_iter()
            .map(|i| triangles[i])
            .collect();
        let soup = TriangleSoup::new(&stored);
        // 13 inner triangles fill two blocks; the 12 face triangles the rest.
        assert_eq!((soup.inner_blocks, soup.blocks.len()), (2, 4));
        let (mut skipped, mut face_skips) = (0, 0);
        for i in 0..20_000u64 {
            let point = |k| Vec3A::new(u(k, i), u(k + 1, i), u(k + 2, i)) * 2.0;
            let mut origin = point(1);
            // Every fourth origin on a face, as a shadow ray from a wall.
            if i % 4 == 0 {
                origin[(i / 4 % 3) as usize] = if i % 8 == 0 { 0.0 } else { 2.0 };
            }
            // Every tenth ray from outside the box.
            if i % 10 == 1 {
                origin = origin * 3.0 - Vec3A::splat(2.0);
            }
            let to = point(4) * 0.98 + Vec3A::splat(0.02);
            let ray = Ray::new(origin, (to - origin).normalize());
            let t_max = (to - origin).length();
            skipped += usize::from(soup.segment_inside(&ray, t_max));
            let sheared = ShearedRay::new(&ray);
            let expected = stored.iter().any(|t| sheared.intersect(t, t_max).is_some());
            assert_eq!(
                soup.any_where(&ray, t_max, &stored, &mut |_| true),
                expected,
                "ray {i}"
            );
            // Closest hits, which skip the faces once an inner hit is nearer
            // than the box's exit, agree too.
            let closest = closest_by_scalar_test(&ray, &stored);
            assert_eq!(
                soup.closest(&ray, f32::INFINITY, &stored),
                closest,
                "ray {i}"
            );
            // The 13 inner triangles are stored first.
            face_skips += usize::from(
                closest.is_some_and(|h| h.0 < 13) && soup.exit_distance(&ray) > closest.unwrap().1,
            );
        }
        // Most rays take the shortcut (the inside ones), not all (outside).
        assert!((14_000..19_000).contains(&skipped), "{skipped}");
        // Many closest hits are settled before the face blocks.
        assert!(face_skips > 2_000, "{face_skips}");
    }
}
