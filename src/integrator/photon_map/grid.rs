//! The photon map: a hash grid of cells of side 2R built once per map (a
//! counting sort of the photons by cell), R the largest radius a lookup
//! may use: a query sphere then touches at most 2 x 2 x 2 cells.
//! Every lookup of an iteration has the same largest radius and the map is
//! rebuilt every iteration, so a k-d tree's balancing and general
//! nearest-neighbour machinery buy nothing here; SmallVCM's hash grid works
//! the same way. Against kiddo's k-d tree (`benches/photon_lookup.rs`) the
//! grid builds 7x faster and answers lookups 1.3-2x faster.

use super::Photon;
use crate::math::prefetch;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// What a map can hold: a point on a surface and the side of the surface
/// it lies on (a photon, or a light subpath's vertex for vertex merging).
pub trait Stored {
    fn position(&self) -> Vec3A;
    /// The surface's normal on the side the point was reached from.
    fn facing(&self) -> Vec3A;
}

/// The side of a surface from which a lookup gathers.
#[derive(Clone, Copy, Debug)]
pub enum Side {
    /// Only points reached from the side that the normal faces: light on
    /// the far side of a wall does not reach its near side.
    Facing(Vec3A),
    /// Both sides, where light passes through the surface (glass): what
    /// arrives from behind is its transmission.
    Both,
}

impl Side {
    /// The side `normal` faces, or both where the surface `transmits`.
    #[inline]
    pub fn of(normal: Vec3A, transmits: bool) -> Side {
        if transmits {
            Side::Both
        } else {
            Side::Facing(normal)
        }
    }
}

/// Photons found within a lookup's radius before they are visited.
const NEAR_BATCH: usize = 32;

/// The largest k of a k-nearest lookup.
pub const MAX_K: usize = 256;

/// Photons (or other [`Stored`] points) in a hash grid.
pub struct PhotonMap<P = Photon> {
    /// The photons sorted by cell hash: `starts[h]..starts[h + 1]` are those
    /// of hash h, so that a lookup reads the photons it finds in a few runs
    /// of memory, not one cache miss each (dense maps find tens per lookup).
    photons: Vec<P>,
    /// Their positions, in the same order: a lookup tests distances on these
    /// 12 bytes in a row and reads a photon only where it is near (most
    /// candidates of the 2 x 2 x 2 cells are not).
    positions: Vec<Vec3>,
    starts: Vec<u32>,
    cell: f32,
    /// The largest lookup radius.
    radius: f32,
}

impl<P: Stored + Copy + Send + Sync> PhotonMap<P> {
    /// A map of `photons` for lookups of radius at most `radius`: they are
    /// gathered into cell order in parallel (moving them in place, cycle by
    /// cycle, was one thread's random walk over the pass's photons).
    pub fn build(photons: Vec<P>, radius: f32) -> PhotonMap<P> {
        Self::converted(&photons, radius, |p| *p)
    }

    /// A map of what `convert` makes of each of `points`, which stay as
    /// they are (VCM's connections read its light vertices in path order).
    pub fn converted<T: Stored + Sync>(
        points: &[T],
        radius: f32,
        convert: impl Fn(&T) -> P + Sync,
    ) -> PhotonMap<P> {
        let (map, source) = Self::sorted_places(points, radius);
        let photons = source
            .par_iter()
            .map(|&i| convert(&points[i as usize]))
            .collect();
        map.holding(photons)
    }

    /// The map with its photons, already in place order, and their positions.
    fn holding(mut self, photons: Vec<P>) -> PhotonMap<P> {
        self.positions = photons.par_iter().map(|p| p.position().into()).collect();
        self.photons = photons;
        self
    }

    /// An empty map with its buckets' bounds, and the index in `points` of
    /// the point that goes to each place: a counting sort by cell hash.
    fn sorted_places<T: Stored + Sync>(points: &[T], radius: f32) -> (PhotonMap<P>, Vec<u32>) {
        let count = points.len();
        let buckets = count.next_power_of_two().max(1);
        let mut map = PhotonMap {
            photons: Vec::new(),
            positions: Vec::new(),
            starts: vec![0; buckets + 1],
            cell: 2.0 * radius,
            radius,
        };
        let hashes: Vec<u32> = points
            .par_iter()
            .map(|p| map.hash(map.cell_of(p.position())) as u32)
            .collect();
        let source = super::sort::by_bucket(&hashes, &mut map.starts);
        (map, source)
    }

    /// The bucket of cell `c`: rows of cells along x fill consecutive
    /// buckets, so that a lookup's two cells of a row are read as one run
    /// of memory (its 2 x 2 x 2 cells are four runs, not eight places).
    fn hash(&self, c: [i32; 3]) -> usize {
        let row = (c[1] as u32).wrapping_mul(19349663) ^ (c[2] as u32).wrapping_mul(83492791);
        (c[0] as u32).wrapping_add(row) as usize & self.mask()
    }

    /// Buckets − 1 (their number is a power of two).
    fn mask(&self) -> usize {
        self.starts.len() - 2
    }

    fn cell_of(&self, p: Vec3A) -> [i32; 3] {
        let c = (p / self.cell).floor();
        [c.x as i32, c.y as i32, c.z as i32]
    }

    /// Photons stored.
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    /// True when no photon was stored.
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// What the map holds, sorted by cell.
    pub fn items(&self) -> &[P] {
        &self.photons
    }

    /// The largest lookup radius.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Calls `visit` with every photon within the map's radius of `point`
    /// on `side` of the surface.
    #[inline]
    pub fn for_each_near(&self, point: Vec3A, side: Side, mut visit: impl FnMut(&P)) {
        self.visit_near(point, side, |_, p| visit(p));
    }

    /// [`PhotonMap::for_each_near`] with each photon's index.
    #[inline]
    fn visit_near(&self, point: Vec3A, side: Side, mut visit: impl FnMut(u32, &P)) {
        if self.photons.is_empty() {
            return;
        }
        // The 2 x 2 x 2 cells nearest the point cover its sphere; a row's
        // second cell is the bucket after its first.
        let r2 = self.radius * self.radius;
        // The photons within the radius are found first and asked of the
        // cache, then visited: their misses overlap instead of each waiting
        // behind the previous one's visit (a dense map finds tens).
        let mut near = [0u32; NEAR_BATCH];
        let mut found = 0;
        let mut seen = [usize::MAX; 8];
        for (row, first) in self.rows(point).into_iter().enumerate() {
            for (k, h) in [(2 * row, first), (2 * row + 1, (first + 1) & self.mask())] {
                // Two cells may share a bucket; visit each bucket once.
                if seen[..k].contains(&h) {
                    continue;
                }
                seen[k] = h;
                for i in self.starts[h] as usize..self.starts[h + 1] as usize {
                    if (Vec3A::from(self.positions[i]) - point).length_squared() <= r2 {
                        prefetch(&self.photons[i]);
                        near[found] = i as u32;
                        found += 1;
                        if found == NEAR_BATCH {
                            self.visit_on(&near, side, &mut visit);
                            found = 0;
                        }
                    }
                }
            }
        }
        self.visit_on(&near[..found], side, &mut visit);
    }

    /// Calls `visit` with each of the photons `near` on `side`.
    #[inline(always)]
    fn visit_on(&self, near: &[u32], side: Side, visit: &mut impl FnMut(u32, &P)) {
        for &i in near {
            let p = &self.photons[i as usize];
            match side {
                Side::Facing(normal) if p.facing().dot(normal) <= 0.0 => {}
                _ => visit(i, p),
            }
        }
    }

    /// The first bucket of each row of two cells that a lookup at `point`
    /// reads (the 2 x 2 x 2 cells nearest it are four such rows).
    #[inline(always)]
    fn rows(&self, point: Vec3A) -> [usize; 4] {
        let base = (point / self.cell - Vec3A::splat(0.5)).floor();
        let (x, y, z) = (base.x as i32, base.y as i32, base.z as i32);
        [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dy, dz)| self.hash([x, y + dy, z + dz]))
    }

    /// Asks the cache for the bucket bounds that a lookup at `point` reads
    /// first: a lookup's reads are cache misses (its cells are anywhere in
    /// the map), which the caller's work until the lookup can hide.
    #[inline(always)]
    pub fn prefetch_buckets(&self, point: Vec3A) {
        if !self.photons.is_empty() {
            for h in self.rows(point) {
                prefetch(&self.starts[h]);
            }
        }
    }

    /// Asks the cache for the first entries of those buckets: call it once
    /// [`PhotonMap::prefetch_buckets`] has had time to bring their bounds.
    #[inline(always)]
    pub fn prefetch_entries(&self, point: Vec3A) {
        if !self.photons.is_empty() {
            for h in self.rows(point) {
                if let Some(p) = self.positions.get(self.starts[h] as usize) {
                    prefetch(p);
                }
            }
        }
    }

    /// The `k` photons nearest `point` within the map's radius (Jensen's
    /// lookup) among those it may `keep`, in `nearest`, sorted by distance; returns how many were
    /// found and the squared radius of the disc that holds them (the map's
    /// radius when fewer than `k` were found).
    pub fn nearest(
        &self,
        point: Vec3A,
        side: Side,
        k: usize,
        keep: impl Fn(&P) -> bool,
        nearest: &mut [(f32, u32); MAX_K],
    ) -> (usize, f32) {
        let k = k.clamp(1, MAX_K);
        let mut found = 0usize;
        self.visit_near(point, side, |index, p| {
            if !keep(p) {
                return;
            }
            let d2 = (p.position() - point).length_squared();
            if found == k && d2 >= nearest[k - 1].0 {
                return;
            }
            // Insertion into the sorted prefix.
            let mut i = found.min(k - 1);
            while i > 0 && nearest[i - 1].0 > d2 {
                nearest[i] = nearest[i - 1];
                i -= 1;
            }
            nearest[i] = (d2, index);
            found = (found + 1).min(k);
        });
        let r2 = if found == k {
            nearest[k - 1].0
        } else {
            self.radius * self.radius
        };
        (found, r2)
    }

    /// The photon at `index` (from [`PhotonMap::nearest`]).
    pub fn photon(&self, index: u32) -> &P {
        &self.photons[index as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;

    fn cloud() -> Vec<Photon> {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..5000)
            .map(|_| Photon {
                point: Vec3A::new(next(), next(), next()) * 3.0 - Vec3A::ONE,
                wi: Vec3A::Z,
                power: Rgb::ONE,
                normal: Vec3A::Z,
                bounces: 1,
            })
            .collect()
    }

    #[test]
    fn the_grid_finds_exactly_the_photons_within_the_radius() {
        let photons = cloud();
        let radius = 0.13;
        let map = PhotonMap::build(photons.clone(), radius);
        for q in photons
            .iter()
            .step_by(25)
            .map(|p| p.point + Vec3A::splat(0.01))
        {
            let mut found = 0;
            map.for_each_near(q, Side::Facing(Vec3A::Z), |_| found += 1);
            let expected = photons
                .iter()
                .filter(|p| (p.point - q).length_squared() <= radius * radius)
                .count();
            assert_eq!(found, expected, "at {q:?}");
        }
    }

    #[test]
    fn the_build_keeps_every_photon_once_in_bucket_order() {
        let photons = cloud();
        let map = PhotonMap::build(photons.clone(), 0.13);
        let buckets: Vec<usize> = map
            .items()
            .iter()
            .map(|p| map.hash(map.cell_of(p.position())))
            .collect();
        assert!(buckets.windows(2).all(|w| w[0] <= w[1]));
        let key = |p: &Photon| p.point.to_array().map(f32::to_bits);
        let mut given: Vec<_> = photons.iter().map(key).collect();
        let mut kept: Vec<_> = map.items().iter().map(key).collect();
        given.sort();
        kept.sort();
        assert_eq!(given, kept);
    }

    #[test]
    fn nearest_finds_the_k_closest() {
        let photons = cloud();
        let map = PhotonMap::build(photons.clone(), 0.3);
        let mut nearest = [(0.0f32, 0u32); MAX_K];
        for q in photons.iter().step_by(97).map(|p| p.point) {
            let (found, r2) = map.nearest(q, Side::Facing(Vec3A::Z), 10, |_| true, &mut nearest);
            let mut d: Vec<f32> = photons
                .iter()
                .map(|p| (p.point - q).length_squared())
                .filter(|&d| d <= 0.09)
                .collect();
            d.sort_by(f32::total_cmp);
            assert_eq!(found, d.len().min(10));
            if found == 10 {
                assert_eq!(r2, d[9]);
            }
            for (i, n) in nearest[..found].iter().enumerate() {
                assert_eq!(n.0, d[i]);
            }
        }
    }
}
