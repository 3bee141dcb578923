//! Error-driven sample allocation: where the next pass's samples go.
//!
//! The figure of merit is the image's RMSE, the mean over pixels of each
//! pixel's MSE. A Monte Carlo pixel with per-sample variance v_p and n_p
//! samples has MSE v_p / n_p; minimising the sum for a fixed total of
//! samples gives n_p proportional to sqrt(v_p) (Neyman allocation). Pixel
//! noise is far from even: on the Cornell box the pixels on the light's
//! edges (half light at radiance 17, half ceiling) have per-sample variances
//! ten thousand times the median, and 1% of the pixels carry half of the
//! squared error of a uniform 64-spp render. So after a uniform warm-up,
//! each pass spreads its budget to move every pixel's total toward its
//! share of sqrt(variance).
//!
//! A pixel's share comes from the variance of its eight neighbours, not its
//! own. Noise is spatially coherent, so the neighbours tell nearly as much
//! (a light's edge is a line of noisy pixels), and a pixel's count then does
//! not depend on its own samples, which are independent of its neighbours'
//! (every pixel has its own scrambles and hashes). Using its own variance
//! biases the mean: a pixel whose first samples happen to agree gets fewer
//! samples, so its low-variance (and often low) estimate weighs more. On the
//! Cornell box at 64 spp, own-variance allocation put the image mean 0.2%
//! low; the neighbours' variance keeps it within 0.03% at 3% more RMSE.
//! Dependence remains only at second order (the neighbours' counts depended
//! on this pixel's samples). Every pixel also keeps a floor of
//! [`UNIFORM_SHARE`] of a uniform allocation, so all keep converging.
//!
//! Neyman's rule assumes the Monte Carlo rate, MSE v_p / n_p. Stratified
//! samplers do better where the variance is: a pixel split by an edge (the
//! light's rim) converges as n^-3/4 with jittered or scrambled-net samples.
//! For an error c_p n_p^-a, minimising the summed squared error for a fixed
//! total gives n_p proportional to c_p^(2 / (2a + 1)), that is to the
//! variance to the power 1 / (2a + 1): 1/2 for a = 1/2 (Neyman), 2/5 for a
//! = 3/4. See [`variance_exponent`] for what it measured.

use crate::sampling::hash::{hash_combine, to_unit_float};
use crate::sampling::sampler::SamplerKind;

/// Share of each pass spread uniformly over all pixels.
pub const UNIFORM_SHARE: f64 = 0.2;

/// What the allocator needs to know of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelNoise {
    /// Samples taken so far (finite or not).
    pub taken: u32,
    /// Unbiased per-sample variance, mean over the colour channels (0 with
    /// fewer than two samples).
    pub variance: f64,
}

/// The power of the per-sample variance that a pixel's share follows, from
/// the rate at which `sampler`'s error falls where the variance is (module
/// comment). Measured on the Cornell box (path tracing, 2 threads, seeds 1-3,
/// RMSE at 16 / 64 spp against the Mitsuba reference): with Sobol 2/5 instead
/// of 1/2 lowers it by 4-5% (0.01145 -> 0.01093, 0.00515 -> 0.00493), with
/// multi-jittered by 4%; stratified is unchanged either way; independent
/// numbers are best at 1/2 (2/5 raised it by 6-11%).
pub fn variance_exponent(sampler: SamplerKind) -> f64 {
    let rate = match sampler {
        SamplerKind::Independent => 0.5,
        SamplerKind::Stratified | SamplerKind::MultiJittered | SamplerKind::Sobol => 0.75,
    };
    1.0 / (2.0 * rate + 1.0)
}

/// Samples per pixel for a pass of `budget` samples in all over a
/// `width` x `height` film whose pixels (row-major) are `noise`, each pixel's
/// share following its neighbours' variance to the power `exponent` (see
/// [`variance_exponent`]). The counts sum to `budget` up to rounding, which
/// is randomised by `key` so it is unbiased yet a function of the film only
/// (the same on any thread count).
pub fn plan(
    noise: &[PixelNoise],
    width: u32,
    height: u32,
    budget: u64,
    exponent: f64,
    key: u64,
) -> Vec<u32> {
    let (w, h) = (width as usize, height as usize);
    assert_eq!(noise.len(), w * h, "one noise entry per pixel");
    let pixels = noise.len();
    if pixels == 0 {
        return Vec::new();
    }
    let deviation = smoothed_deviation(noise, w, h, exponent);
    let mean_deviation = deviation.iter().sum::<f64>() / pixels as f64;
    let weight = |p: usize| {
        if mean_deviation > 0.0 {
            UNIFORM_SHARE + (1.0 - UNIFORM_SHARE) * deviation[p] / mean_deviation
        } else {
            1.0
        }
    };
    // Every pixel's fair total after this pass (weights average to one).
    let taken: f64 = noise.iter().map(|n| f64::from(n.taken)).sum();
    let mean_total = (taken + budget as f64) / pixels as f64;
    let deficit: Vec<f64> = (0..pixels)
        .map(|p| (mean_total * weight(p) - f64::from(noise[p].taken)).max(0.0))
        .collect();
    let total_deficit: f64 = deficit.iter().sum();
    let scale = if total_deficit > 0.0 {
        budget as f64 / total_deficit
    } else {
        0.0
    };
    deficit
        .iter()
        .enumerate()
        .map(|(p, d)| {
            let share = d * scale;
            let dither = f64::from(to_unit_float(hash_combine(key, p as u64)));
            (share + dither).floor().min(f64::from(u32::MAX / 2)) as u32
        })
        .collect()
}

/// The mean variance of each pixel's 8 neighbours (fewer at the borders),
/// the pixel itself left out, to the power `exponent`.
fn smoothed_deviation(noise: &[PixelNoise], w: usize, h: usize, exponent: f64) -> Vec<f64> {
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut count) = (0.0, 0.0);
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    sum += noise[ny * w + nx].variance;
                    count += 1.0;
                }
            }
            // Leave the pixel itself out (see the module comment).
            let own = noise[y * w + x].variance;
            out[y * w + x] = ((sum - own) / (count - 1.0)).powf(exponent);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(
        width: u32,
        height: u32,
        taken: u32,
        variance: impl Fn(u32, u32) -> f64,
    ) -> Vec<PixelNoise> {
        (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| PixelNoise {
                taken,
                variance: variance(x, y),
            })
            .collect()
    }

    #[test]
    fn even_noise_gets_an_even_split() {
        let noise = film(8, 8, 4, |_, _| 0.5);
        let counts = plan(&noise, 8, 8, 64 * 4, 0.5, 1);
        assert!(counts.iter().all(|&c| c == 4), "{counts:?}");
    }

    #[test]
    fn noisy_pixels_get_more_and_the_budget_is_kept() {
        // One very noisy pixel in a quiet 16x16 film: its neighbours' shares
        // grow, its own does not.
        let noise = film(
            16,
            16,
            8,
            |x, y| if (x, y) == (5, 9) { 100.0 } else { 0.01 },
        );
        let budget = 256 * 8;
        let counts = plan(&noise, 16, 16, budget, 0.5, 7);
        let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        // Dithered rounding: within one sample per pixel of the budget.
        assert!(total.abs_diff(budget) <= 256, "{total} vs {budget}");
        // The pixel's own share comes from its quiet neighbours.
        let (own, quiet) = (counts[9 * 16 + 5], counts[0]);
        assert!(own <= 2 * quiet.max(1), "own {own}, quiet {quiet}");
        // Its neighbours' shares come from it.
        assert!(counts[9 * 16 + 6] > 20 * quiet.max(1));
    }

    #[test]
    fn quiet_pixels_keep_their_floor_over_passes() {
        // Half the film noisy; over many passes the quiet half still gets at
        // least UNIFORM_SHARE of the uniform rate.
        let (w, h) = (16u32, 8u32);
        let mut noise = film(w, h, 4, |x, _| if x < 8 { 1.0 } else { 0.0 });
        let per_pass = u64::from(w * h) * 4;
        for pass in 0..10 {
            let counts = plan(&noise, w, h, per_pass, 0.5, pass);
            for (n, c) in noise.iter_mut().zip(counts) {
                n.taken += c;
            }
        }
        let mean_taken = noise.iter().map(|n| f64::from(n.taken)).sum::<f64>() / f64::from(w * h);
        let quiet = noise[15].taken as f64;
        assert!(
            quiet >= 0.9 * UNIFORM_SHARE * mean_taken,
            "quiet {quiet} mean {mean_taken}"
        );
        assert!(noise[0].taken as f64 > 1.5 * mean_taken);
    }

    #[test]
    fn shares_follow_the_variance_to_the_sampler_exponent() {
        // Left half variance 1, right half 100; far from the seam every
        // pixel's share is the floor plus the rest in proportion to
        // variance^exponent, so the two halves' counts differ by
        // (U + (1 - U) 100^e / m) / (U + (1 - U) / m), m the mean of the two.
        // Applying the power to the standard deviation instead, or not at
        // all, gives ratios far outside the 2% allowed for rounding.
        let (w, h) = (64u32, 8u32);
        let noise = film(w, h, 0, |x, _| if x < w / 2 { 1.0 } else { 100.0 });
        for (sampler, exponent) in [(SamplerKind::Independent, 0.5), (SamplerKind::Sobol, 0.4)] {
            let e = variance_exponent(sampler);
            assert!((e - exponent).abs() < 1e-12, "{sampler:?}: {e}");
            let counts = plan(&noise, w, h, u64::from(w * h) * 1000, e, 5);
            let row = |x: u32| {
                (0..h)
                    .map(|y| f64::from(counts[(y * w + x) as usize]))
                    .sum::<f64>()
            };
            let m = (1.0 + 100f64.powf(e)) / 2.0;
            let share = |d: f64| UNIFORM_SHARE + (1.0 - UNIFORM_SHARE) * d / m;
            let expected = share(100f64.powf(e)) / share(1.0);
            let ratio = row(w - 5) / row(4);
            assert!(
                (ratio / expected - 1.0).abs() < 0.02,
                "{sampler:?}: ratio {ratio}, expected {expected}"
            );
        }
    }

    #[test]
    fn a_black_film_is_split_evenly() {
        let noise = film(4, 4, 2, |_, _| 0.0);
        assert_eq!(plan(&noise, 4, 4, 32, 0.5, 3), vec![2; 16]);
    }
}
