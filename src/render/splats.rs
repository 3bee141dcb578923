//! The splat buffer of splatting estimators: per-pixel sums whose value does
//! not depend on the order in which threads add to them.

use crate::math::Rgb;
use glam::Vec2;
use std::sync::atomic::{AtomicU64, Ordering};

/// Per-pixel sums of light-tracing splats in 32.32 fixed point: integer
/// additions commute, so the sums are the same in any thread order.
pub(crate) struct SplatBuffer {
    width: u32,
    height: u32,
    sums: Vec<[AtomicU64; 3]>,
}

/// 2^32: resolution 2.3e-10 per splat, overflow past 4e9 per pixel and pass.
const SPLAT_SCALE: f64 = 4294967296.0;

impl SplatBuffer {
    pub(crate) fn new(width: u32, height: u32) -> Self {
        let sums = (0..width as usize * height as usize)
            .map(|_| [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)])
            .collect();
        SplatBuffer {
            width,
            height,
            sums,
        }
    }

    /// Adds `value` to the pixel containing `film`; false (and nothing added)
    /// when the value is not finite, negative or too large to represent.
    pub(crate) fn add(&self, film: Vec2, value: Rgb) -> bool {
        let (x, y) = (film.x as u32, film.y as u32);
        if x >= self.width || y >= self.height {
            return true;
        }
        let mut fixed = [0u64; 3];
        for c in 0..3 {
            let v = f64::from(value[c]) * SPLAT_SCALE;
            if !(v >= 0.0 && v < 9.0e18) {
                return false;
            }
            fixed[c] = v.round() as u64;
        }
        if fixed == [0; 3] {
            return true;
        }
        let sums = &self.sums[(y * self.width + x) as usize];
        for c in 0..3 {
            sums[c].fetch_add(fixed[c], Ordering::Relaxed);
        }
        true
    }

    pub(crate) fn get(&self, index: u32) -> [f64; 3] {
        let sums = &self.sums[index as usize];
        [0, 1, 2].map(|c| sums[c].load(Ordering::Relaxed) as f64 / SPLAT_SCALE)
    }
}
