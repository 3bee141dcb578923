//! Next-event estimation's choice between lights at infinity and bounded
//! lights, aimed by a pilot. Power compares an environment's flux through
//! a disc around the whole scene with a lamp's, a comparison whose outcome
//! depends on how far the scene's floor reaches: beside Mitsuba's dim
//! constant environment it gave two spot lights an eighth of the shadow
//! rays each, while under a sky with a sun it was right to give the sky
//! nearly all. The pilot measures instead what each group delivers where
//! the camera looks: a grid of camera rays, at each first hit a few light
//! samples chosen by power, their unoccluded cosine-weighted luminance
//! summed per group. Deterministic (fixed points, no random numbers), and
//! a few thousand rays.

use super::Scene;
use crate::math::luminance;
use glam::Vec2;

/// Camera rays per side of the pilot's grid.
const GRID: u32 = 32;
/// Light samples at each first hit.
const SAMPLES: u32 = 8;
/// Every group keeps at least this fraction of an even split, so that a
/// group the camera's points happen not to see is still sampled.
const FLOOR: f64 = 0.1;

/// Shares of next-event estimation's choice per group of
/// [`super::lights::Lights::direct_groups`]; None where there are no
/// groups to weigh or the camera sees no light arrive.
pub(super) fn direct_shares(scene: &Scene) -> Option<Vec<f64>> {
    let groups = scene.lights.direct_groups();
    if groups < 2 {
        return None;
    }
    let group_of = scene.lights.direct_group_of_each();
    let mut sums = vec![0.0f64; groups];
    let camera = &scene.camera;
    let cell = Vec2::new(camera.width as f32, camera.height as f32) / GRID as f32;
    for n in 0..GRID * GRID {
        let film = (Vec2::new((n % GRID) as f32, (n / GRID) as f32) + 0.5) * cell;
        let ray = camera.generate_ray(film, Vec2::splat(0.5));
        let Some(hit) = scene.geometry.intersect(&ray) else {
            continue;
        };
        let facing = -ray.direction.dot(hit.normal).signum();
        for k in 0..SAMPLES {
            // Strata of the choice rotated per point (the golden ratio), and
            // an R2 sequence on the light.
            let i = (n * SAMPLES + k) as f32;
            let u_select = ((k as f32 + 0.5) / SAMPLES as f32 + 0.618_034 * n as f32).fract();
            let u = Vec2::new((0.754_878 * i).fract(), (0.569_840 * i).fract());
            let Some(ls) = scene.lights.sample_as_emitted(hit.point, u_select, u) else {
                continue;
            };
            let cos = ls.wi.dot(hit.normal) * facing;
            if cos <= 0.0 || scene.geometry.occluded(&ls.shadow_ray_from(&hit)) {
                continue;
            }
            let arriving = f64::from(luminance(ls.radiance) * cos / ls.pdf);
            if arriving.is_finite() {
                sums[group_of[ls.light as usize]] += arriving;
            }
        }
    }
    let total: f64 = sums.iter().sum();
    if !(total > 0.0) {
        return None;
    }
    let floor = FLOOR / groups as f64;
    let floored: Vec<f64> = sums.iter().map(|s| (s / total).max(floor)).collect();
    let sum: f64 = floored.iter().sum();
    Some(floored.iter().map(|s| s / sum).collect())
}
