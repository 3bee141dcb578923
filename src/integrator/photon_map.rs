//! Photons and the map that finds them, shared by the photon mappers
//! (`photon.rs`, Jensen's two-pass method; `sppm.rs`, progressive) and by
//! vertex connection and merging (`vcm/`, for its light vertices).
//!
//! Photons are found through a hash grid of cells of side 2R built once per
//! map (a counting sort of the photons by cell), R the
//! largest radius a lookup may use: a query sphere then touches at most
//! 2 x 2 x 2 cells.
//! Every lookup of an iteration has the same largest radius and the map is
//! rebuilt every iteration, so a k-d tree's balancing and general
//! nearest-neighbour machinery buy nothing here; SmallVCM's hash grid works
//! the same way. Against kiddo's k-d tree (`benches/photon_lookup.rs`) the
//! grid builds 7x faster and answers lookups 1.3-2x faster.

use super::RayCounts;
use super::light::importance_weight;
use crate::accel::{NO_LIGHT, SurfaceHit};
use crate::math::{Frame, Ray, Rgb, prefetch, ray_between};
use crate::sampling::hash::hash_combine;
use crate::sampling::{Domain, Sampler, SamplerKind};
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::{Vec2, Vec3, Vec3A};
use rayon::prelude::*;

/// A photon: where it landed, where it came from, and what it carries.
#[derive(Clone, Copy, Debug)]
pub struct Photon {
    pub point: Vec3A,
    /// Unit direction back towards where the photon came from.
    pub wi: Vec3A,
    /// The surface's normal on the side the photon arrived, so that photons
    /// on the far side of a thin wall do not count.
    pub normal: Vec3A,
    /// Its weight (flux) after N photons were shot: divide by N.
    pub power: Rgb,
}

/// How a photon got where it is: bounces since the light, and whether
/// every one of them was specular (a caustic photon, L S+ D).
#[derive(Clone, Copy, Debug)]
pub struct PhotonPath {
    pub bounces: u32,
    pub specular_only: bool,
}

/// What a map can hold: a point on a surface and the side of the surface
/// it lies on (a photon, or a light subpath's vertex for vertex merging).
pub trait Stored {
    fn position(&self) -> Vec3A;
    /// The surface's normal on the side the point was reached from.
    fn facing(&self) -> Vec3A;
}

impl Stored for Photon {
    #[inline]
    fn position(&self) -> Vec3A {
        self.point
    }
    #[inline]
    fn facing(&self) -> Vec3A {
        self.normal
    }
}

/// Photons found within a lookup's radius before they are visited.
const NEAR_BATCH: usize = 32;

/// The largest k of a k-nearest lookup.
pub const MAX_K: usize = 256;

/// `fraction` of the scene's bounding-box diagonal, in scene units (the
/// fraction itself where the scene has no finite size), so that radii do
/// not depend on the scene's units.
pub fn of_diagonal(scene: &Scene, fraction: f32) -> f32 {
    let bounds = scene.geometry.bounds();
    let diagonal = (bounds.max - bounds.min).length();
    if diagonal.is_finite() && diagonal > 0.0 {
        fraction * diagonal
    } else {
        fraction
    }
}

/// The photons to shoot per iteration: `photons`, or one per pixel for 0.
pub fn photons_per_iteration(scene: &Scene, photons: u32) -> u32 {
    if photons == 0 {
        scene.camera.width * scene.camera.height
    } else {
        photons
    }
}

/// Says how many photons an iteration shoots, for summaries.
pub fn describe_photons(photons: u32) -> String {
    if photons == 0 {
        "one per pixel".to_string()
    } else {
        photons.to_string()
    }
}

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
    /// A map of `photons` for lookups of radius at most `radius`, sorted
    /// in place (a copy would cost each pass new pages).
    pub fn build(mut photons: Vec<P>, radius: f32) -> PhotonMap<P> {
        let (map, mut source) = Self::sorted_places(&[photons.as_slice()], radius);
        // Each cycle of the permutation moved along, one photon in hand.
        for start in 0..source.len() {
            if source[start] as usize == start {
                continue;
            }
            let held = photons[start];
            let mut place = start;
            loop {
                let from = source[place] as usize;
                source[place] = place as u32;
                if from == start {
                    photons[place] = held;
                    break;
                }
                photons[place] = photons[from];
                place = from;
            }
        }
        map.holding(photons)
    }

    /// A map of what `convert` makes of the points of `parts` (one part
    /// after another), without first copying them into one list.
    pub fn from_parts<T: Stored + Sync>(
        parts: &[&[T]],
        radius: f32,
        convert: impl Fn(&T) -> P + Sync,
    ) -> PhotonMap<P> {
        let (map, source) = Self::sorted_places(parts, radius);
        let mut offsets = Vec::with_capacity(parts.len() + 1);
        offsets.push(0);
        for part in parts {
            offsets.push(offsets.last().unwrap() + part.len());
        }
        let photons = source
            .par_iter()
            .map(|&i| {
                let i = i as usize;
                let part = offsets.partition_point(|&o| o <= i) - 1;
                convert(&parts[part][i - offsets[part]])
            })
            .collect();
        map.holding(photons)
    }

    /// The map with its photons, already in place order, and their positions.
    fn holding(mut self, photons: Vec<P>) -> PhotonMap<P> {
        self.positions = photons.par_iter().map(|p| p.position().into()).collect();
        self.photons = photons;
        self
    }

    /// An empty map with its buckets' bounds, and the point (an index into
    /// `parts` one after another) that goes to each place: a counting sort
    /// by cell hash.
    fn sorted_places<T: Stored + Sync>(parts: &[&[T]], radius: f32) -> (PhotonMap<P>, Vec<u32>) {
        let count: usize = parts.iter().map(|p| p.len()).sum();
        let buckets = count.next_power_of_two().max(1);
        let mut map = PhotonMap {
            photons: Vec::new(),
            positions: Vec::new(),
            starts: vec![0; buckets + 1],
            cell: 2.0 * radius,
            radius,
        };
        let mut hashes: Vec<u32> = Vec::with_capacity(count);
        for part in parts {
            hashes.par_extend(
                part.par_iter()
                    .map(|p| map.hash(map.cell_of(p.position())) as u32),
            );
        }
        for &h in &hashes {
            map.starts[h as usize + 1] += 1;
        }
        for i in 1..map.starts.len() {
            map.starts[i] += map.starts[i - 1];
        }
        let mut next = map.starts.clone();
        let mut source = vec![0u32; count];
        for (i, &h) in hashes.iter().enumerate() {
            source[next[h as usize] as usize] = i as u32;
            next[h as usize] += 1;
        }
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
    /// on the side of the surface that `normal` faces.
    #[inline]
    pub fn for_each_near(&self, point: Vec3A, normal: Vec3A, mut visit: impl FnMut(&P)) {
        self.visit_near(point, normal, |_, p| visit(p));
    }

    /// [`PhotonMap::for_each_near`] with each photon's index.
    #[inline]
    fn visit_near(&self, point: Vec3A, normal: Vec3A, mut visit: impl FnMut(u32, &P)) {
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
                            self.visit_facing(&near, normal, &mut visit);
                            found = 0;
                        }
                    }
                }
            }
        }
        self.visit_facing(&near[..found], normal, &mut visit);
    }

    /// Calls `visit` with each of the photons `near` on the side of the
    /// surface that `normal` faces.
    #[inline(always)]
    fn visit_facing(&self, near: &[u32], normal: Vec3A, visit: &mut impl FnMut(u32, &P)) {
        for &i in near {
            let p = &self.photons[i as usize];
            if p.facing().dot(normal) > 0.0 {
                visit(i, p);
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
    /// lookup), in `nearest`, sorted by distance; returns how many were
    /// found and the squared radius of the disc that holds them (the map's
    /// radius when fewer than `k` were found).
    pub fn nearest(
        &self,
        point: Vec3A,
        normal: Vec3A,
        k: usize,
        nearest: &mut [(f32, u32); MAX_K],
    ) -> (usize, f32) {
        let k = k.clamp(1, MAX_K);
        let mut found = 0usize;
        self.visit_near(point, normal, |index, p| {
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

/// Shoots `count` photons (randomness from `key` and each photon's index,
/// so the maps do not depend on the schedule), following each for up to
/// `max_bounces` bounces, and sorts the photons that land on non-specular
/// surfaces into two lists by `keep`: (first list, second list).
pub fn shoot(
    scene: &Scene,
    count: u32,
    key: u64,
    max_bounces: u32,
    keep: impl Fn(PhotonPath) -> (bool, bool) + Sync,
    counts: &mut RayCounts,
) -> (Vec<Photon>, Vec<Photon>) {
    let chunks = count.div_ceil(PARTICLE_CHUNK);
    let key = hash_combine(key, 0x5048_4f54_4f4e);
    let results: Vec<(Vec<Photon>, Vec<Photon>, u64)> = (0..chunks)
        .into_par_iter()
        .map(|chunk| {
            let mut sampler = Sampler::new(SamplerKind::Independent, key, 0);
            let (mut first, mut second) = (Vec::new(), Vec::new());
            let mut rays = RayCounts::default();
            let end = ((chunk + 1) * PARTICLE_CHUNK).min(count);
            for index in chunk * PARTICLE_CHUNK..end {
                sampler.start(index, 0);
                trace_photon(
                    scene,
                    &mut sampler,
                    max_bounces,
                    &mut rays,
                    |photon, path| {
                        let (a, b) = keep(path);
                        if a {
                            first.push(photon);
                        }
                        if b {
                            second.push(photon);
                        }
                    },
                );
            }
            (first, second, rays.bounce)
        })
        .collect();
    counts.bounce += results.iter().map(|r| r.2).sum::<u64>();
    let first = concat(&results.iter().map(|r| r.0.as_slice()).collect::<Vec<_>>());
    let second = concat(&results.iter().map(|r| r.1.as_slice()).collect::<Vec<_>>());
    (first, second)
}

/// Particles (photons, VCM's light paths) traced per parallel task: small
/// enough that the last tasks of a pass leave few of 16 threads idle, large
/// enough that a task's set-up is nothing beside its paths.
pub(crate) const PARTICLE_CHUNK: u32 = 1024;

/// The parts one after another, copied in parallel: at 16 threads a serial
/// copy of a pass's photons or light vertices would be a large share of the
/// pass.
pub(crate) fn concat<T: Copy + Send + Sync>(parts: &[&[T]]) -> Vec<T> {
    let total = parts.iter().map(|p| p.len()).sum();
    let mut out = Vec::with_capacity(total);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let mut places = Vec::with_capacity(parts.len());
    for part in parts {
        let (place, tail) = rest.split_at_mut(part.len());
        places.push(place);
        rest = tail;
    }
    places.into_par_iter().zip(parts).for_each(|(place, part)| {
        for (slot, &item) in place.iter_mut().zip(part.iter()) {
            slot.write(item);
        }
    });
    // SAFETY: the places cover the first `total` slots, each written above.
    unsafe { out.set_len(total) };
    out
}

/// Traces one photon from the lights and hands every landing on a
/// non-specular surface to `store`, with how it got there.
fn trace_photon(
    scene: &Scene,
    sampler: &mut Sampler,
    max_bounces: u32,
    counts: &mut RayCounts,
    mut store: impl FnMut(Photon, PhotonPath),
) {
    let Some(emission) = super::light::sample_particle(scene, sampler) else {
        return;
    };
    let roulette_scale = 1.0 / emission.throughput.max_element();
    let mut beta = emission.throughput;
    let mut ray = emission.ray().at_time(scene.camera.shutter_open);
    counts.bounce += 1;
    let mut specular_only = true;
    for bounces in 0..=max_bounces {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            break;
        };
        let bsdf = scene.bsdf_at(&hit);
        if bsdf.is_black() {
            break;
        }
        let frame = scene.shading_frame(&hit);
        let ng = frame.to_local(hit.normal);
        let wo = frame.to_local(-ray.direction);
        let u_lobe = sampler.next_1d_for(Domain::Bsdf);
        let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
        let u_roulette = sampler.next_1d();
        if !bsdf.is_specular() {
            let facing = if hit.normal.dot(ray.direction) < 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            store(
                Photon {
                    point: hit.point,
                    wi: -ray.direction,
                    normal: facing,
                    power: beta,
                },
                PhotonPath {
                    bounces,
                    specular_only,
                },
            );
            specular_only = false;
        }
        if bounces == max_bounces {
            break;
        }
        let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
            break;
        };
        beta *= importance_weight(bsdf, wo, sample.wi, ng, sample.weight);
        // Roulette from the first bounce: a photon is cheap and the map
        // only needs its density right.
        if !super::survives_roulette(&mut beta, roulette_scale, u_roulette) {
            break;
        }
        ray = hit.spawn_ray(frame.to_world(sample.wi));
        counts.bounce += 1;
    }
}

/// Where a camera ray of a photon mapper is estimated: its first diffuse
/// or glossy hit, reached through mirrors and glass.
pub struct DiffuseHit {
    pub hit: SurfaceHit,
    /// The weight of the chain of mirrors and glass before it.
    pub beta: Rgb,
    pub bsdf: Bsdf,
    pub frame: Frame,
    /// Direction to the camera side, local.
    pub wo: Vec3A,
    /// The normal on the side the ray arrived from.
    pub facing: Vec3A,
    /// Random numbers for a BSDF sample at the hit.
    pub u_lobe: f32,
    pub u_bsdf: Vec2,
}

/// Follows a camera ray through mirrors and glass (a chain of at most
/// `max_depth` bounces) to its first diffuse or glossy hit; returns the
/// emission seen on the way and the hit, if the ray got there.
pub fn camera_to_diffuse(
    scene: &Scene,
    mut ray: Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    counts: &mut RayCounts,
) -> (Rgb, Option<DiffuseHit>) {
    let mut beta = Rgb::ONE;
    let mut emitted = Rgb::ZERO;
    for _ in 0..=max_depth {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            // Seen directly or through Dirac surfaces only: no photon
            // stands for it.
            if let Some(env) = scene.lights.environment() {
                emitted += beta * env.le(ray.direction);
            }
            break;
        };
        let material = &scene.materials[hit.material as usize];
        let wo_world = -ray.direction;
        if hit.light != NO_LIGHT {
            emitted += beta * material.emitted(hit.normal, wo_world);
        }
        let bsdf = scene.bsdf_at(&hit);
        if bsdf.is_black() {
            break;
        }
        let frame = scene.shading_frame(&hit);
        let wo = frame.to_local(wo_world);
        let u_lobe = sampler.next_1d_for(Domain::Bsdf);
        let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
        if !bsdf.is_specular() {
            let facing = if hit.normal.dot(wo_world) > 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            let diffuse = DiffuseHit {
                hit,
                beta,
                bsdf,
                frame,
                wo,
                facing,
                u_lobe,
                u_bsdf,
            };
            return (emitted, Some(diffuse));
        }
        let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
            break;
        };
        beta *= sample.weight;
        ray = hit.spawn_ray(frame.to_world(sample.wi));
        counts.bounce += 1;
    }
    (emitted, None)
}

impl DiffuseHit {
    /// Direct light at the hit by one light sample (next-event
    /// estimation), times the chain's weight.
    pub fn direct_light(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let u_select = sampler.next_1d_for(Domain::Light);
        let u_light = sampler.next_2d_for(Domain::Light);
        let hit = &self.hit;
        let Some(ls) = scene.lights.sample(hit.point, u_select, u_light) else {
            return Rgb::ZERO;
        };
        let wi = self.frame.to_local(ls.wi);
        let f = self.bsdf.eval(self.wo, wi);
        if !(f.max_element() > 0.0) {
            return Rgb::ZERO;
        }
        counts.shadow += 1;
        let shadow = ray_between(
            hit.point, hit.error, hit.normal, ls.point, ls.error, ls.normal,
        )
        .at_time(hit.time);
        if scene.geometry.occluded(&shadow) {
            return Rgb::ZERO;
        }
        self.beta * f * ls.radiance * (wi.z.abs() / ls.pdf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concat_keeps_every_part_in_order() {
        let parts: Vec<Vec<u32>> = vec![vec![], vec![1, 2, 3], vec![], vec![4], vec![5, 6]];
        let slices: Vec<&[u32]> = parts.iter().map(Vec::as_slice).collect();
        assert_eq!(concat(&slices), vec![1, 2, 3, 4, 5, 6]);
        assert!(concat::<u32>(&[]).is_empty());
    }

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
                normal: Vec3A::Z,
                power: Rgb::ONE,
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
            map.for_each_near(q, Vec3A::Z, |_| found += 1);
            let expected = photons
                .iter()
                .filter(|p| (p.point - q).length_squared() <= radius * radius)
                .count();
            assert_eq!(found, expected, "at {q:?}");
        }
    }

    #[test]
    fn both_builds_keep_every_photon_once_in_the_same_order() {
        let photons = cloud();
        let in_place = PhotonMap::build(photons.clone(), 0.13);
        let (a, b) = photons.split_at(photons.len() / 3);
        let gathered = PhotonMap::from_parts(&[a, b], 0.13, |p: &Photon| *p);
        let key = |p: &Photon| p.point.to_array().map(f32::to_bits);
        let order: Vec<_> = in_place.items().iter().map(key).collect();
        assert_eq!(order, gathered.items().iter().map(key).collect::<Vec<_>>());
        let mut given: Vec<_> = photons.iter().map(key).collect();
        let mut kept = order;
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
            let (found, r2) = map.nearest(q, Vec3A::Z, 10, &mut nearest);
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
