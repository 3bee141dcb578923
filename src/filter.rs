//! Pixel reconstruction filters (Mitsuba's `rfilter`): box, tent and
//! Gaussian, applied by filter importance sampling (Ernst et al. 2006;
//! pbrt-v4): a camera sample's film position is drawn from the filter
//! around the pixel's centre, so every sample keeps weight 1 and the film
//! stays a plain mean. Splatting techniques spread each splat over the
//! pixels whose filter covers it, weighted by the same normalised filter,
//! so that both estimate ∫ f(p − c) L(p) dp for a pixel centred at c.
//! Camera samples can be splatted the same way ([`FilterSampling::Splat`],
//! Mitsuba's film): see `crate::film::filtered`.

use crate::math::{erf, erfinv};
use glam::Vec2;

/// A separable pixel filter, normalised to integrate to 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFilter {
    /// The pixel's square (radius 0.5): each sample counts for its pixel.
    Box,
    /// A tent (triangle) of the given radius in pixels (Mitsuba: 1).
    Tent { radius: f32 },
    /// A Gaussian of standard deviation `stddev` pixels, cut at `radius`
    /// (Mitsuba: 0.5 and 4 stddev). Mitsuba also subtracts the value at the
    /// radius, e^-8 of the peak at its defaults; this filter does not (a
    /// difference of 3e-4 of the peak, below any test's resolution).
    Gaussian { stddev: f32, radius: f32 },
}

impl Default for PixelFilter {
    fn default() -> Self {
        PixelFilter::Box
    }
}

/// How camera samples meet a filter wider than the box.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FilterSampling {
    /// Each sample is taken uniformly in its pixel and added to every pixel
    /// the filter covers, with the filter's weight; a pixel is the weighted
    /// mean of what it received (Mitsuba's film). A pixel then averages
    /// the samples of (∫f)² / ∫f² pixels' area (2.25 for the tent, π for
    /// Mitsuba's Gaussian), at the price of correlated neighbours.
    #[default]
    Splat,
    /// Each sample's position is drawn from the filter and counts for its
    /// own pixel alone, with weight 1 (pbrt-v4): pixels stay independent.
    Importance,
}

impl FilterSampling {
    /// The name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            FilterSampling::Splat => "splat",
            FilterSampling::Importance => "importance",
        }
    }
}

impl PixelFilter {
    /// Mitsuba's tent.
    pub fn tent() -> PixelFilter {
        PixelFilter::Tent { radius: 1.0 }
    }

    /// Mitsuba's Gaussian.
    pub fn gaussian() -> PixelFilter {
        PixelFilter::Gaussian {
            stddev: 0.5,
            radius: 2.0,
        }
    }

    /// How far from a pixel's centre its filter reaches, in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            PixelFilter::Box => 0.5,
            PixelFilter::Tent { radius } | PixelFilter::Gaussian { radius, .. } => radius,
        }
    }

    /// An offset from the pixel's centre drawn from the filter.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec2 {
        match *self {
            PixelFilter::Box => u - Vec2::splat(0.5),
            PixelFilter::Tent { radius } => {
                Vec2::new(sample_tent(u.x, radius), sample_tent(u.y, radius))
            }
            PixelFilter::Gaussian { stddev, radius } => Vec2::new(
                sample_gaussian(u.x, stddev, radius),
                sample_gaussian(u.y, stddev, radius),
            ),
        }
    }

    /// The normalised filter at offset `d` from a pixel's centre.
    #[inline]
    pub fn eval(&self, d: Vec2) -> f32 {
        let f = self.one_dimensional();
        f.eval(d.x) * f.eval(d.y)
    }

    /// The normalised 1D filter at `x`: the 2D filter is the product in x
    /// and y, so a splat's footprint needs one per row and column.
    #[inline]
    pub fn eval_1d(&self, x: f32) -> f32 {
        self.one_dimensional().eval(x)
    }

    /// The normalised 1D filter with its constants computed once (a
    /// Gaussian's mass is an erf), for many evaluations.
    #[inline]
    pub fn one_dimensional(&self) -> Filter1d {
        let scale = match *self {
            PixelFilter::Gaussian { stddev, radius } => {
                let mass = erf(radius / (stddev * std::f32::consts::SQRT_2));
                stddev * (2.0 * std::f32::consts::PI).sqrt() * mass
            }
            PixelFilter::Tent { radius } => radius * radius,
            PixelFilter::Box => 1.0,
        };
        Filter1d {
            filter: *self,
            scale,
        }
    }

    /// The 1D filter at `x` up to a constant factor (the 2D filter is the
    /// product in x and y): what a weighted mean needs, without the
    /// Gaussian's erf.
    #[inline]
    pub fn shape_1d(&self, x: f32) -> f32 {
        match *self {
            PixelFilter::Box => f32::from(u8::from(x.abs() <= 0.5)),
            PixelFilter::Tent { radius } => (radius - x.abs()).max(0.0),
            PixelFilter::Gaussian { stddev, radius } => {
                if x.abs() > radius {
                    0.0
                } else {
                    (-(x * x) / (2.0 * stddev * stddev)).exp()
                }
            }
        }
    }

    /// The filter's name as a scene file writes it.
    pub fn name(&self) -> &'static str {
        match self {
            PixelFilter::Box => "box",
            PixelFilter::Tent { .. } => "tent",
            PixelFilter::Gaussian { .. } => "gaussian",
        }
    }
}

/// Inverse CDF of the tent: each half is a triangle of mass 1/2, and the
/// half is the sign of 2u − 1 (without a branch, which a random u
/// mispredicts every other sample).
#[inline]
fn sample_tent(u: f32, r: f32) -> f32 {
    let d = 2.0 * u - 1.0;
    (r * (1.0 - (1.0 - d.abs()).max(0.0).sqrt())).copysign(d)
}

/// A pixel filter's normalised 1D profile ([`PixelFilter::one_dimensional`]).
#[derive(Clone, Copy, Debug)]
pub struct Filter1d {
    filter: PixelFilter,
    /// The integral of [`PixelFilter::shape_1d`]: r² for the tent, σ √(2π)
    /// times its mass within ±r for the Gaussian.
    scale: f32,
}

impl Filter1d {
    /// The filter at `x` (the Gaussian cut at ±r).
    #[inline]
    pub fn eval(&self, x: f32) -> f32 {
        self.filter.shape_1d(x) / self.scale
    }
}

/// Inverse CDF of the Gaussian cut at ±r, through erf and its inverse.
#[inline]
fn sample_gaussian(u: f32, s: f32, r: f32) -> f32 {
    let k = s * std::f32::consts::SQRT_2;
    let mass = erf(r / k);
    (k * erfinv((2.0 * u - 1.0) * mass)).clamp(-r, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tent_sampling_inverts_its_cdf() {
        // F(x) = (x + r)² / 2r² left of 0, 1 − (r − x)² / 2r² right of it.
        let r = 1.5f32;
        let cdf = |x: f32| {
            if x < 0.0 {
                (x + r) * (x + r) / (2.0 * r * r)
            } else {
                1.0 - (r - x) * (r - x) / (2.0 * r * r)
            }
        };
        for i in 0..=1000 {
            let u = i as f32 / 1000.0;
            let x = sample_tent(u, r);
            assert!(x.abs() <= r, "u {u}: x {x} outside the tent");
            assert!((cdf(x) - u).abs() < 1e-5, "u {u}: F(x) = {}", cdf(x));
        }
    }

    #[test]
    fn filters_integrate_to_one_and_sample_their_own_shape() {
        for filter in [PixelFilter::tent(), PixelFilter::gaussian()] {
            let r = filter.radius();
            let n = 400;
            let h = 2.0 * r / n as f32;
            let mut integral = 0.0;
            for i in 0..n {
                let x = -r + (i as f32 + 0.5) * h;
                integral += filter.eval(Vec2::new(x, 0.0)) * h;
            }
            // eval at y = 0 is the 1D filter times its peak: normalise by it.
            let peak = filter.eval_1d(0.0);
            assert!(
                (integral / peak - 1.0).abs() < 1e-3,
                "{filter:?}: {}",
                integral / peak
            );
            // The sampled CDF matches the filter's, into the tails.
            for q in [0.001f32, 0.01, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999] {
                let x = filter.sample(Vec2::new(q, 0.5)).x;
                let mut cdf = 0.0;
                for i in 0..n {
                    let t = -r + (i as f32 + 0.5) * h;
                    if t < x {
                        cdf += filter.eval(Vec2::new(t, 0.0)) / peak * h;
                    }
                }
                assert!((cdf - q).abs() < 5e-3, "{filter:?} at {q}: cdf {cdf}");
            }
        }
        assert_eq!(
            PixelFilter::Box.sample(Vec2::new(0.25, 0.75)),
            Vec2::new(-0.25, 0.25)
        );
    }
}
