//! The pass of splatting estimators (light tracing, BDPT): paths from the
//! lights splat anywhere on the film through a fixed-point buffer, and
//! BDPT's estimates of a sample's own pixel go where camera samples go.

use super::Session;
use crate::film::filtered::{self, Apron, PassAprons};
use crate::film::splats::{PendingSplats, SplatBuffer};
use crate::filter::PixelFilter;
use crate::integrator::{RayCounts, SplattingIntegrator};
use crate::math::Rgb;
use crate::sampling::Sampler;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

impl Session {
    /// Splatting estimators (light tracing): `spp` paths per pixel (the
    /// same total as a camera pass), seeded by (pixel, index) so the result
    /// does not depend on the schedule. Splats go to a fixed-point buffer whose integer sums do not
    /// depend on their order either; the pass's estimate then enters the film
    /// as `spp` samples of equal value, so the film's mean is exact and its
    /// standard error is estimated across passes (exact for 1-spp passes).
    pub(super) fn splat_pass(&self, estimator: &SplattingIntegrator, first: u32, spp: u32) {
        // In the pool throughout: the buffer's fill and the film's update
        // are parallel loops over every pixel too.
        self.pool
            .install(|| self.splat_pass_in_pool(estimator, first, spp));
    }

    fn splat_pass_in_pool(&self, estimator: &SplattingIntegrator, first: u32, spp: u32) {
        let scene = &*self.scene;
        let settings = &self.settings;
        let (width, height) = (self.film.width(), self.film.height());
        let splats = SplatBuffer::with_filter(width, height, scene.camera.filter);
        // A pixel's own estimates (BDPT's camera strategies) are splatted
        // through the filter as camera samples are, into aprons; the light
        // splats stay in the buffer.
        let filter = scene.camera.filter;
        let own_splatted = self.splats_camera_samples();
        let camera_filter = if own_splatted {
            PixelFilter::Box
        } else {
            filter
        };
        let aprons = PassAprons::new(self.film.tiles().len(), own_splatted);
        // A camera strategy's value is scaled for the buffer, which divides by W H n.
        let pixel_scale = 1.0 / (width as f32 * height as f32);
        self.film
            .tiles()
            .par_iter()
            .enumerate()
            .with_max_len(1)
            .for_each(|(index, tile)| {
                if self.cancelled.load(Ordering::Relaxed) {
                    return;
                }
                let (x0, y0, tile_width, tile_height, mut apron) = {
                    let t = tile.lock().unwrap_or_else(|e| e.into_inner());
                    let apron = own_splatted.then(|| Apron::new(&t, filter));
                    (t.x0, t.y0, t.width, t.height, apron)
                };
                let mut sampler =
                    Sampler::new(settings.sampler, settings.seed, settings.planned_spp)
                        .with_domains(settings.domains);
                let mut counts = RayCounts::default();
                let mut pending = PendingSplats::new();
                let mut rejected = 0u64;
                for i in 0..tile_width * tile_height {
                    let (x, y) = (x0 + i % tile_width, y0 + i / tile_width);
                    let centre = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    for s in first..first + spp {
                        sampler.start(y * width + x, s);
                        let trace =
                            |splat: crate::integrator::Splat| match (splat.filtered, &mut apron) {
                                (true, _) => pending.push(&splats, splat.film, splat.value, true),
                                (false, Some(apron)) => {
                                    let value = splat.value * pixel_scale;
                                    match value.is_finite() && value.min_element() >= 0.0 {
                                        true => apron.splat(splat.film, value),
                                        false => rejected += 1,
                                    }
                                }
                                // A black estimate adds nothing to the buffer.
                                (false, None) if splat.value == Rgb::ZERO => {}
                                (false, None) => pending.push(&splats, centre, splat.value, false),
                            };
                        estimator.trace(
                            scene,
                            (x, y),
                            camera_filter,
                            &mut sampler,
                            &mut counts,
                            trace,
                        );
                        pending.flush(&splats);
                    }
                }
                if let Some(apron) = apron {
                    aprons.put(index, apron);
                }
                self.add_counts(
                    u64::from(tile_width * tile_height * spp),
                    &counts,
                    pending.rejected + rejected,
                );
            });
        if self.cancelled.load(Ordering::Relaxed) {
            return;
        }
        let particles = f64::from(width) * f64::from(height) * f64::from(spp);
        let aprons = aprons.into_aprons();
        let across = self.film.tiles_across();
        self.film.tiles().par_iter().for_each(|tile| {
            let mut tile = tile.lock().unwrap_or_else(|e| e.into_inner());
            let (x0, y0, tile_width) = (tile.x0, tile.y0, tile.width);
            let light = |i: usize| {
                let (x, y) = (x0 + i as u32 % tile_width, y0 + i as u32 / tile_width);
                splats.get(y * width + x).map(|v| v / particles)
            };
            if own_splatted {
                // The pass's light image joins each of its samples' values.
                filtered::fold_shifted(&mut tile, &aprons, across, light);
                for pixel in &mut tile.pixels {
                    pixel.count += spp;
                }
            } else {
                for (i, pixel) in tile.pixels.iter_mut().enumerate() {
                    pixel.add_repeated(light(i), spp);
                }
            }
        });
    }
}
