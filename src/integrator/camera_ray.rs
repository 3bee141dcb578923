//! The camera ray of a sample, and its time, as every technique draws them.

use crate::filter::PixelFilter;
use crate::math::Ray;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use glam::Vec2;

/// The time of a path: uniform over the shutter interval when something
/// moves while the shutter is open, else the shutter's opening without
/// consuming a dimension (a static scene has no time dimension). `always`
/// draws the time anyway, as a renderer without feature detection would.
#[inline]
pub fn sample_time(scene: &Scene, sampler: &mut Sampler, always: bool) -> f32 {
    if scene.features.motion || always {
        scene.camera.time(sampler.next_1d_for(Domain::Time))
    } else {
        scene.camera.shutter_open
    }
}

/// The camera ray of the sample the sampler was started at, for pixel
/// (`x`, `y`): film position, lens point and time in this order, so that a
/// replay draws the same numbers. `deterministic` estimators shoot through
/// the pixel and lens centres at mid-exposure.
#[inline(always)]
pub fn camera_ray(
    scene: &Scene,
    sampler: &mut Sampler,
    x: u32,
    y: u32,
    deterministic: bool,
    general: bool,
) -> Ray {
    camera_ray_through(
        scene,
        sampler,
        x,
        y,
        deterministic,
        general,
        scene.camera.filter,
    )
    .0
}

/// [`camera_ray`] with the film position drawn from `filter` (the box: uniform
/// in the pixel, for samples splatted through the camera's filter), and
/// that position.
#[inline(always)]
pub fn camera_ray_through(
    scene: &Scene,
    sampler: &mut Sampler,
    x: u32,
    y: u32,
    deterministic: bool,
    general: bool,
    filter: PixelFilter,
) -> (Ray, Vec2) {
    let u_pixel = sampler.next_2d_for(Domain::Pixel);
    // Filter importance sampling; the box keeps its exact arithmetic.
    let mut film_point = match filter {
        PixelFilter::Box => Vec2::new(x as f32, y as f32) + u_pixel,
        filter => Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + filter.sample(u_pixel),
    };
    let lens_dim = sampler.skip();
    let mut lens = if scene.camera.aperture_radius > 0.0 {
        sampler.get_2d_for(lens_dim, Domain::Lens)
    } else {
        Vec2::splat(0.5)
    };
    let mut time = sample_time(scene, sampler, general);
    if deterministic {
        film_point = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        lens = Vec2::splat(0.5);
        time = scene.camera.time(0.5);
    }
    (
        scene.camera.generate_ray(film_point, lens).at_time(time),
        film_point,
    )
}
