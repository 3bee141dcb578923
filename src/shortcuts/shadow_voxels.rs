//! Which triangles can block shadow rays to a flat light from each part of
//! the scene: none where the light is seen whole.
//!
//! A shadow ray from a point p to a point on a flat light lies in the convex
//! hull of p and the light. Split the scene's box into voxels: an occluder
//! that does not meet the hull of a voxel and the light blocks no shadow
//! ray from that voxel, so those rays test only the others, and none at all
//! where no occluder is left. Disjointness is shown by separating axes (the triangle's
//! normal, the coordinate axes, the light's normal, and the triangle's edges
//! crossed with those and with the light's edges and the voxel-to-light
//! direction); an axis that cannot be found leaves the voxel to the ray test,
//! so the shortcut only ever answers what the test would have.

use crate::accel::Geometry;
use crate::math::Ray;
use glam::{DVec3, Vec3A};
use rayon::prelude::*;

/// Voxels along the box's longest side: 16 keeps the build near 10 ms for
/// the Cornell box's 24 occluders (every voxel against every occluder).
const RESOLUTION: f32 = 16.0;

/// A voxel's corners and the light's corners on both sides of its plane
/// (a triangle light repeats a corner).
const HULL_POINTS: usize = 16;

/// Voxels of a box, each with the occluders that may block its shadow rays
/// to one light (none: the light is seen whole from there).
#[derive(Clone, Debug, Default)]
pub struct ShadowVoxels {
    lo: Vec3A,
    /// Voxels per unit length.
    scale: f32,
    dims: [u32; 3],
    /// Per voxel (x fastest), [first, count] of its occluders in
    /// `occluders`; a count of [`TEST_ALL`] leaves it to the whole test.
    ranges: Vec<[u32; 2]>,
    /// Triangle indices, each voxel's in storage order.
    occluders: Vec<u32>,
}

/// A voxel with more possible occluders than this tests everything: one
/// by one, the watertight test costs about as much per triangle as the
/// soup's eight-wide test per block (callgrind, Cornell box, per path: up
/// to 8 listed 5 841 instructions, up to 3: 5 763, up to 2: 5 767, none
/// listed, only clear voxels: 5 810).
const MAX_OCCLUDERS: usize = 3;

/// Marks a voxel whose shadow rays test everything.
const TEST_ALL: u32 = u32::MAX;

impl ShadowVoxels {
    /// The voxels of the flat light `light_id` (its corners, in order; its
    /// own triangles carry its id) in a static soup, or None elsewhere.
    pub fn for_light(
        geometry: &Geometry,
        light_id: u32,
        corners: &[Vec3A],
    ) -> Option<ShadowVoxels> {
        let (lo, hi, inner) = geometry.static_soup_box()?;
        // Shadow rays end just before the light's surface, off its own
        // triangles by the light sample's error bound; the soup's face
        // triangles cannot block a segment inside its box.
        let triangles = geometry.triangles();
        let occluders: Vec<(u32, [Vec3A; 3])> = (0..inner)
            .filter(|&i| geometry.triangle_light(i) != light_id)
            .map(|i| (i as u32, triangles[i]))
            .collect();
        let margin = (hi - lo).max_element() * 1e-4;
        Some(ShadowVoxels::build(lo, hi, corners, &occluders, margin))
    }

    /// [`Geometry::occluded`] for a shadow ray that ends on this light:
    /// with both ends inside the soup's box (so that its faces cannot block
    /// it), only the origin voxel's occluders are tested, by the same
    /// watertight test, so the answer is the whole test's. Rays that leave
    /// the box, or whose voxel lists too many, take the whole test.
    /// `PLAIN` as for [`Geometry::occluded_as`].
    #[inline(always)]
    pub fn occluded<const PLAIN: bool>(&self, geometry: &Geometry, ray: &Ray) -> bool {
        if let Some(occluders) = self.occluders_from(ray.origin)
            && geometry.segment_inside_soup(ray)
        {
            return geometry.occluded_among(ray, occluders);
        }
        geometry.occluded_as::<PLAIN>(ray)
    }

    /// Voxels of the box [lo, hi] and, for each, which of `occluders`
    /// (triangle index, vertices) may block a segment from it to the light
    /// polygon `light` (its corners, in order). `margin` enlarges each voxel
    /// and the light, covering the rounding of shadow rays' ends.
    pub fn build(
        lo: Vec3A,
        hi: Vec3A,
        light: &[Vec3A],
        occluders: &[(u32, [Vec3A; 3])],
        margin: f32,
    ) -> ShadowVoxels {
        let extent = (hi - lo).max(Vec3A::splat(f32::MIN_POSITIVE));
        let scale = RESOLUTION / extent.max_element();
        let dims = (extent * scale)
            .ceil()
            .max(Vec3A::ONE)
            .to_array()
            .map(|d| d as u32);
        let count = (dims[0] * dims[1] * dims[2]) as usize;
        let margin = f64::from(margin);
        let light_points = light_hull_points(light, margin);
        let triangles: Vec<[DVec3; 3]> = occluders
            .iter()
            .map(|(_, t)| t.map(|v| v.as_dvec3()))
            .collect();
        // Each voxel against every occluder: about 10^5 separating-axis
        // tests for the Cornell box, spread over the threads.
        let blockers = |index: usize| -> Vec<u32> {
            let (x, y, z) = (
                index as u32 % dims[0],
                index as u32 / dims[0] % dims[1],
                index as u32 / (dims[0] * dims[1]),
            );
            let corner = |c: u32| {
                let v = Vec3A::new(
                    (x + (c & 1)) as f32,
                    (y + (c >> 1 & 1)) as f32,
                    (z + (c >> 2)) as f32,
                );
                let p = (lo + v / scale).as_dvec3();
                let outward = DVec3::new(
                    if c & 1 == 0 { -1.0 } else { 1.0 },
                    if c >> 1 & 1 == 0 { -1.0 } else { 1.0 },
                    if c >> 2 == 0 { -1.0 } else { 1.0 },
                );
                p + outward * margin
            };
            let mut hull = [DVec3::ZERO; HULL_POINTS];
            for (c, point) in hull[..8].iter_mut().enumerate() {
                *point = corner(c as u32);
            }
            hull[8..].copy_from_slice(&light_points[..HULL_POINTS - 8]);
            triangles
                .iter()
                .zip(occluders)
                .filter(|(t, _)| !separated(t, &hull, light))
                .map(|(_, (index, _))| *index)
                .collect()
        };
        let lists: Vec<Vec<u32>> = (0..count).into_par_iter().map(blockers).collect();
        let mut ranges = Vec::with_capacity(count);
        let mut flat = Vec::new();
        for list in &lists {
            if list.len() > MAX_OCCLUDERS {
                ranges.push([0, TEST_ALL]);
            } else {
                ranges.push([flat.len() as u32, list.len() as u32]);
                flat.extend_from_slice(list);
            }
        }
        ShadowVoxels {
            lo,
            scale,
            dims,
            ranges,
            occluders: flat,
        }
    }

    /// The triangles that may block a shadow ray from `p` to the light (in
    /// storage order; empty where the light is seen whole), or None when
    /// `p` lies outside the box or its voxel has too many.
    #[inline(always)]
    pub fn occluders_from(&self, p: Vec3A) -> Option<&[u32]> {
        let v = (p - self.lo) * self.scale;
        // Negative or NaN coordinates fail the >= test.
        if !v.cmpge(Vec3A::ZERO).all() {
            return None;
        }
        let [x, y, z] = v.to_array().map(|c| c as u32);
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return None;
        }
        let [first, count] = self.ranges[((z * self.dims[1] + y) * self.dims[0] + x) as usize];
        (count != TEST_ALL).then(|| &self.occluders[first as usize..(first + count) as usize])
    }

    /// The fractions of voxels from which the light is seen whole, and of
    /// those that test a short list of occluders instead of everything.
    pub fn summary(&self) -> (f64, f64) {
        let count = self.ranges.len().max(1) as f64;
        let clear = self.ranges.iter().filter(|r| r[1] == 0).count() as f64;
        let listed = self
            .ranges
            .iter()
            .filter(|r| r[1] != 0 && r[1] != TEST_ALL)
            .count() as f64;
        (clear / count, listed / count)
    }
}

/// The light's corners moved off its plane by `margin` to both sides and
/// outward from its centre by `margin`.
fn light_hull_points(light: &[Vec3A], margin: f64) -> Vec<DVec3> {
    // A triangle's first corner twice, so that every light gives eight.
    let light: Vec<Vec3A> = light.iter().copied().cycle().take(4).collect();
    let points: Vec<DVec3> = light.iter().map(|v| v.as_dvec3()).collect();
    let centre = points.iter().sum::<DVec3>() / points.len() as f64;
    let normal = (points[1] - points[0])
        .cross(points[2] - points[0])
        .normalize_or_zero();
    points
        .iter()
        .flat_map(|&p| {
            let out = (p - centre).normalize_or_zero() * margin;
            [p + out + normal * margin, p + out - normal * margin]
        })
        .collect()
}

/// True when some axis separates the triangle from the convex hull of
/// `hull` (so they do not meet); false when none of the axes tried does.
/// The cheap axes come first: the box axes, then the triangle's normal.
fn separated(triangle: &[DVec3; 3], hull: &[DVec3; HULL_POINTS], light: &[Vec3A]) -> bool {
    let separates = |axis: DVec3| {
        if axis.length_squared() < 1e-24 {
            return false;
        }
        let (t_lo, t_hi) = interval(triangle, axis);
        let (h_lo, h_hi) = interval(hull, axis);
        t_hi < h_lo || h_hi < t_lo
    };
    if [DVec3::X, DVec3::Y, DVec3::Z].into_iter().any(separates) {
        return true;
    }
    let edges = [
        triangle[1] - triangle[0],
        triangle[2] - triangle[1],
        triangle[0] - triangle[2],
    ];
    let light_edges = [
        (light[1] - light[0]).as_dvec3(),
        (light[2] - light[1]).as_dvec3(),
    ];
    let light_normal = light_edges[0].cross(light_edges[1]);
    // Voxel centre to light centre (the hull's first eight points are the
    // voxel's corners).
    let centre = |points: &[DVec3]| points.iter().sum::<DVec3>() / points.len() as f64;
    let direction = centre(&hull[8..]) - centre(&hull[..8]);
    let crossed = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        light_normal,
        light_edges[0],
        light_edges[1],
        direction,
    ];
    separates(edges[0].cross(edges[1]))
        || separates(light_normal)
        || edges
            .iter()
            .any(|e| crossed.iter().any(|&a| separates(e.cross(a))))
}

/// The projections of `points` onto `axis`: (min, max).
fn interval(points: &[DVec3], axis: DVec3) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = p.dot(axis);
            (lo.min(d), hi.max(d))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::triangle::ShearedRay;
    use crate::math::Ray;
    use crate::sampling::hash::{hash_combine, to_unit_float};

    /// A room under a square light with a box standing in it: a random ray
    /// from any voxel to a random light point is blocked only by occluders
    /// in that voxel's list (the scalar test says so), there are clear
    /// voxels (the test is not vacuous) and voxels with short lists (near
    /// the box).
    #[test]
    fn shadow_rays_are_blocked_only_by_their_voxels_occluders() {
        let u = |k: u64, i: u64| to_unit_float(hash_combine(k, i));
        let (lo, hi) = (Vec3A::ZERO, Vec3A::splat(4.0));
        let light = [
            Vec3A::new(1.5, 3.9, 1.5),
            Vec3A::new(2.5, 3.9, 1.5),
            Vec3A::new(2.5, 3.9, 2.5),
            Vec3A::new(1.5, 3.9, 2.5),
        ];
        // A box [1, 2] x [0, 1.5] x [1, 2] as twelve triangles, and a slanted
        // panel.
        let corner = |c: u32| {
            Vec3A::new(
                1.0 + (c & 1) as f32,
                1.5 * (c >> 1 & 1) as f32,
                1.0 + (c >> 2) as f32,
            )
        };
        let mut occluders = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                let face: Vec<Vec3A> = (0..8)
                    .filter(|c| (c >> axis) & 1 == side)
                    .map(corner)
                    .collect();
                occluders.push([face[0], face[1], face[3]]);
                occluders.push([face[0], face[3], face[2]]);
            }
        }
        occluders.push([
            Vec3A::new(3.0, 2.0, 0.5),
            Vec3A::new(3.5, 3.0, 0.5),
            Vec3A::new(3.2, 2.5, 1.5),
        ]);
        let indexed: Vec<(u32, [Vec3A; 3])> = (0..).zip(occluders.iter().copied()).collect();
        let voxels = ShadowVoxels::build(lo, hi, &light, &indexed, 1e-4);
        let (fraction, listed) = voxels.summary();
        assert!(fraction > 0.2 && fraction < 0.95, "{fraction}");
        assert!(listed > 0.02, "{listed}");
        let mut clear = 0;
        for i in 0..200_000u64 {
            let p = Vec3A::new(u(1, i), u(2, i), u(3, i)) * 4.0;
            let Some(listed) = voxels.occluders_from(p) else {
                continue;
            };
            let (s, t) = (u(4, i), u(5, i));
            let q = light[0] + s * (light[1] - light[0]) + t * (light[3] - light[0]);
            let ray = Ray::new(p, (q - p).normalize());
            let sheared = ShearedRay::new(&ray);
            let t_max = (q - p).length();
            for (k, tri) in occluders.iter().enumerate() {
                let blocks = sheared.intersect(tri, t_max).is_some();
                assert!(
                    !blocks || listed.contains(&(k as u32)),
                    "ray {i} from {p} is blocked by {k}, which its voxel does not list"
                );
            }
            clear += usize::from(listed.is_empty());
        }
        assert!(clear > 20_000, "{clear}");
        // Right above the box, looking up at the light: clear; beside the
        // box on the floor, where its shadow falls partly: not clear;
        // outside the box: no answer.
        assert_eq!(
            voxels.occluders_from(Vec3A::new(1.5, 1.9, 1.5)),
            Some(&[][..])
        );
        assert_ne!(
            voxels.occluders_from(Vec3A::new(2.1, 0.05, 1.5)),
            Some(&[][..])
        );
        assert_eq!(voxels.occluders_from(Vec3A::new(-0.1, 1.0, 1.0)), None);
    }
}
