//! Counter-based randomness: every random number is a hash of its coordinates
//! (seed, pixel, sample index, dimension), so any sample can be replayed and an
//! image never depends on thread count or tile order.

/// 64-bit finaliser of MurmurHash3 (`fmix64`): a bijective mixer whose every
/// output bit depends on every input bit.
#[inline]
pub fn mix64(mut k: u64) -> u64 {
    k ^= k >> 33;
    k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
    k ^= k >> 33;
    k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    k ^= k >> 33;
    k
}

/// Combines a running key with one more coordinate.
#[inline]
pub fn hash_combine(key: u64, value: u64) -> u64 {
    mix64(
        key ^ value
            .wrapping_add(0x9e37_79b9_7f4a_7c15)
            .wrapping_add(key << 6)
            .wrapping_add(key >> 2),
    )
}

/// Maps the high 24 bits of a hash to a float in [0, 1).
#[inline]
pub fn to_unit_float(h: u64) -> f32 {
    ((h >> 40) as u32) as f32 * (1.0 / 16_777_216.0)
}

/// Up to this size, permutations are drawn uniformly from all n! by their
/// Lehmer code: Kensler's hash reaches only a few of them for tiny n (its
/// mixing steps shift the few index bits away), which correlates the strata
/// of different pixels and dimensions.
const SMALL_PERMUTATION: u32 = 8;

/// Element `i` of a uniformly random permutation of `[0, n)` chosen by
/// `seed`: its Lehmer code's digits (the rank of each element among those
/// still available) are drawn by multiplying a 64-bit hash by each radix
/// n, n - 1, ... and taking the high word, which is uniform up to n! / 2^64.
/// Only the digits up to position `i` are drawn, without a division
/// (decoding a code modulo n! by factorials made multi-jittered sampling
/// 4x slower than Sobol).
#[inline]
fn small_permute(i: u32, n: u32, seed: u32) -> u32 {
    let mut h = mix64(u64::from(seed) ^ 0x2545_f491_4f6c_dd1d);
    let mut available = (1u32 << n) - 1;
    for position in 0..=i {
        let product = u128::from(h) * u128::from(n - position);
        let k = (product >> 64) as u32;
        h = product as u64;
        // The k-th element still available: clear the k lowest set bits.
        let mut rest = available;
        for _ in 0..k {
            rest &= rest - 1;
        }
        let element = rest.trailing_zeros();
        if position == i {
            return element;
        }
        available &= !(1 << element);
    }
    unreachable!("i < n")
}

/// A pseudo-random permutation of `[0, n)` evaluated one element at a time, with
/// no table: `permute(i, n, seed)` is the image of `i`. Cycle-walking over the
/// next power of two with an invertible hash, after Kensler, "Correlated
/// Multi-Jittered Sampling" (Pixar TM 13-01, 2013).
#[inline]
pub fn permute(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(n > 0 && i < n);
    if n == 1 {
        return 0;
    }
    if n <= SMALL_PERMUTATION {
        return small_permute(i, n, seed);
    }
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        // Each step is a bijection on [0, w] (w = 2^k - 1), so the walk stays
        // inside one cycle and terminates once it lands below n.
        i ^= seed;
        i = i.wrapping_mul(0xe170_893d);
        i ^= seed >> 16;
        i ^= (i & w) >> 4;
        i ^= seed >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= seed >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | seed >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    (i.wrapping_add(seed)) % n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_bijection() {
        for n in [1u32, 2, 3, 7, 16, 100, 1000] {
            for seed in [0u32, 1, 0xdead_beef] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, seed) as usize;
                    assert!(!seen[j], "n={n} seed={seed}: {j} twice");
                    seen[j] = true;
                }
            }
        }
    }

    #[test]
    fn unit_floats_stay_below_one_and_look_uniform() {
        let n = 100_000;
        let mut bins = [0u32; 10];
        for i in 0..n {
            let u = to_unit_float(hash_combine(42, i));
            assert!((0.0..1.0).contains(&u));
            bins[(u * 10.0) as usize] += 1;
        }
        // Each bin is Binomial(n, 0.1): sd = sqrt(n * 0.09) ~ 95; allow 5 sd.
        for b in bins {
            assert!((b as f64 - 10_000.0).abs() < 5.0 * 95.0, "{bins:?}");
        }
    }
}
