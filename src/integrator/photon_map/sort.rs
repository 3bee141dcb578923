//! The photon map's counting sort: the points' indices in order of their
//! bucket (stable: input order within a bucket) and each bucket's start.
//! One thread's pass over every point between the parallel parts of an
//! iteration is what Amdahl's law charges most at 16 threads, so with more
//! than two threads the sort runs in two parallel passes (by the bucket's
//! high bits, then within each of those ranges by the rest); on one or two
//! threads the one serial pass costs less. Both give the same order.

use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// Points below this are sorted serially, whatever the threads: the serial
/// pass takes about a nanosecond a point, and each of the three parallel
/// passes must first wake the pool's threads (tens of microseconds).
const PARALLEL_MIN: usize = 1 << 17;

/// The most ranges of the first parallel pass (by the high bits).
const RANGES: usize = 256;

/// Sorts the indices of `hashes` (each below `starts.len() - 1`, a power of
/// two) by bucket into the returned order, and writes each bucket's first
/// place into `starts` (its last entry: the number of points).
pub(super) fn by_bucket(hashes: &[u32], starts: &mut [u32]) -> Vec<u32> {
    if rayon::current_num_threads() > 2 && hashes.len() >= PARALLEL_MIN {
        in_parallel(hashes, starts)
    } else {
        serially(hashes, starts)
    }
}

fn serially(hashes: &[u32], starts: &mut [u32]) -> Vec<u32> {
    starts.fill(0);
    for &h in hashes {
        starts[h as usize + 1] += 1;
    }
    for i in 1..starts.len() {
        starts[i] += starts[i - 1];
    }
    let mut next = starts.to_vec();
    let mut order = vec![0u32; hashes.len()];
    for (i, &h) in hashes.iter().enumerate() {
        order[next[h as usize] as usize] = i as u32;
        next[h as usize] += 1;
    }
    order
}

fn in_parallel(hashes: &[u32], starts: &mut [u32]) -> Vec<u32> {
    let buckets = starts.len() - 1;
    let ranges = RANGES.min(buckets);
    let per_range = buckets / ranges;
    let shift = per_range.trailing_zeros();
    // Pass 1: per chunk of the input, a count per range; places assigned
    // range by range, chunk by chunk within a range (so stably); each
    // chunk then writes its indices to its own places.
    let chunk = hashes.len().div_ceil(4 * rayon::current_num_threads());
    let counts: Vec<Vec<u32>> = hashes
        .par_chunks(chunk)
        .map(|part| {
            let mut count = vec![0u32; ranges];
            for &h in part {
                count[(h >> shift) as usize] += 1;
            }
            count
        })
        .collect();
    let mut places = vec![vec![0u32; ranges]; counts.len()];
    let mut range_starts = vec![0usize; ranges + 1];
    let mut total = 0u32;
    for r in 0..ranges {
        range_starts[r] = total as usize;
        for (c, count) in counts.iter().enumerate() {
            places[c][r] = total;
            total += count[r];
        }
    }
    range_starts[ranges] = total as usize;
    // Disjoint places by construction; relaxed atomics make that safe to
    // write from every chunk at once (a plain store on x86).
    let staged: Vec<AtomicU32> = (0..hashes.len())
        .into_par_iter()
        .map(|_| AtomicU32::new(0))
        .collect();
    hashes
        .par_chunks(chunk)
        .zip(places)
        .enumerate()
        .for_each(|(c, (part, mut place))| {
            for (k, &h) in part.iter().enumerate() {
                let r = (h >> shift) as usize;
                staged[place[r] as usize].store((c * chunk + k) as u32, Ordering::Relaxed);
                place[r] += 1;
            }
        });
    // Pass 2: each range sorted by the rest of its bucket, serially within
    // it, the ranges in parallel.
    let mut order = vec![0u32; hashes.len()];
    let mut pieces = Vec::with_capacity(ranges);
    let mut rest = order.as_mut_slice();
    for r in 0..ranges {
        let (piece, tail) = rest.split_at_mut(range_starts[r + 1] - range_starts[r]);
        pieces.push(piece);
        rest = tail;
    }
    pieces
        .into_par_iter()
        .zip(starts[..buckets].par_chunks_mut(per_range))
        .enumerate()
        .for_each(|(r, (piece, range_buckets))| {
            let first_bucket = r * per_range;
            let staged = &staged[range_starts[r]..range_starts[r + 1]];
            range_buckets.fill(0);
            for s in staged {
                let b = hashes[s.load(Ordering::Relaxed) as usize] as usize - first_bucket;
                range_buckets[b] += 1;
            }
            // Counts to first places, from the range's own start.
            let mut place = range_starts[r] as u32;
            for start in range_buckets.iter_mut() {
                let n = *start;
                *start = place;
                place += n;
            }
            let mut next: Vec<u32> = range_buckets.to_vec();
            for s in staged {
                let i = s.load(Ordering::Relaxed);
                let b = hashes[i as usize] as usize - first_bucket;
                piece[next[b] as usize - range_starts[r]] = i;
                next[b] += 1;
            }
        });
    starts[buckets] = hashes.len() as u32;
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel passes give the serial pass's order and starts, for
    /// clustered and spread hashes and bucket counts above and below the
    /// number of ranges, in a pool of four threads.
    #[test]
    fn both_sorts_agree() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        for (count, buckets, spread) in [
            (140_000usize, 262_144usize, 262_144u64),
            (140_000, 262_144, 97),
            (135_000, 128, 128),
            (150_000, 1 << 20, 1 << 20),
        ] {
            let hashes: Vec<u32> = (0..count as u64)
                .map(|i| (crate::sampling::hash::hash_combine(7, i) % spread) as u32)
                .collect();
            let mut serial_starts = vec![0u32; buckets + 1];
            let serial = serially(&hashes, &mut serial_starts);
            let mut parallel_starts = vec![7u32; buckets + 1];
            let parallel = pool.install(|| {
                assert!(rayon::current_num_threads() > 2 && count >= PARALLEL_MIN);
                by_bucket(&hashes, &mut parallel_starts)
            });
            assert_eq!(serial, parallel, "{count} points, {buckets} buckets");
            assert_eq!(
                serial_starts, parallel_starts,
                "{count} points, {buckets} buckets"
            );
        }
    }
}
