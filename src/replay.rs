//! Replaying one sample (`tracelab render --debug-sample X,Y,S`): the
//! sampler is keyed by (seed, pixel, sample index), so the same settings
//! trace exactly the path the render took, here with every vertex, pdf and
//! weight written down.

use crate::accel::SurfaceHit;
use crate::error::{Error, Result};
use crate::filter::PixelFilter;
use crate::integrator::camera_ray_through;
use crate::integrator::path::PathObserver;
use crate::integrator::{CameraIntegrator, Integrator, RayCounts};
use crate::math::Rgb;
use crate::render::RenderSettings;
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::scene::light::LightSample;
use crate::scene::material::BsdfSample;
use crate::shortcuts::CameraSampling;
use std::fmt::Write;

/// Lines describing one path, one event each.
struct PathLog<'a> {
    scene: &'a Scene,
    lines: Vec<String>,
}

fn rgb(c: Rgb) -> String {
    format!("({:.4}, {:.4}, {:.4})", c.x, c.y, c.z)
}

impl PathObserver for PathLog<'_> {
    fn vertex(&mut self, bounce: u32, hit: &SurfaceHit, beta: Rgb) {
        let material = &self.scene.materials[hit.material as usize].name;
        self.lines.push(format!(
            "vertex {bounce}: t {:.6} point ({:.6}, {:.6}, {:.6}) normal ({:.3}, {:.3}, {:.3}) material `{material}` throughput {}",
            hit.t,
            hit.point.x,
            hit.point.y,
            hit.point.z,
            hit.normal.x,
            hit.normal.y,
            hit.normal.z,
            rgb(beta)
        ));
    }

    fn emission(&mut self, emitted: Rgb, weight: f32, added: Rgb) {
        self.lines.push(format!(
            "  emission {} MIS weight {weight:.4} adds {}",
            rgb(emitted),
            rgb(added)
        ));
    }

    fn light_sample(&mut self, ls: &LightSample, f: Rgb, weight: f32, visible: bool, added: Rgb) {
        let mut line = format!(
            "  light sample at ({:.6}, {:.6}, {:.6}) pdf {:.6} (solid angle) f {} MIS weight {weight:.4}",
            ls.point.x,
            ls.point.y,
            ls.point.z,
            ls.pdf,
            rgb(f)
        );
        if visible {
            let _ = write!(line, " visible, adds {}", rgb(added));
        } else {
            line.push_str(" occluded");
        }
        self.lines.push(line);
    }

    fn bsdf_sample(&mut self, sample: &BsdfSample) {
        self.lines.push(format!(
            "  BSDF sample wi ({:.4}, {:.4}, {:.4}) (local) pdf {:.6}{} weight f cos / pdf {}",
            sample.wi.x,
            sample.wi.y,
            sample.wi.z,
            sample.pdf,
            if sample.specular { " (specular)" } else { "" },
            rgb(sample.weight)
        ));
    }

    fn roulette(&mut self, q: f32, survived: bool) {
        self.lines.push(format!(
            "  Russian roulette: survival probability {q:.4}, {}",
            if survived { "survived" } else { "ended" }
        ));
    }

    fn escaped(&mut self) {
        self.lines.push("ray left the scene".into());
    }
}

/// Traces sample `index` of pixel (`x`, `y`) as a render with `settings`
/// would, and returns its value and a description of the path.
pub fn replay_sample(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    index: u32,
) -> Result<(Rgb, Vec<String>)> {
    let Integrator::Camera(CameraIntegrator::Path(tracer)) = settings.integrator else {
        return Err(Error::new(
            "--debug-sample replays path tracing samples (--integrator path)",
        ));
    };
    let (width, height) = (scene.camera.width, scene.camera.height);
    if x >= width || y >= height {
        return Err(Error::new(format!(
            "--debug-sample: pixel ({x}, {y}) is outside the {width}x{height} image"
        )));
    }
    let mut sampler = Sampler::new(settings.sampler, settings.seed, settings.planned_spp)
        .with_domains(settings.domains);
    sampler.start(y * width + x, index);
    // The film position as the render drew it: uniform in the pixel where
    // its samples are splatted through the filter, else from the filter.
    let splatted = crate::render::splats_through_filter(scene, settings, false);
    let position_filter = match splatted {
        true => PixelFilter::Box,
        false => scene.camera.filter,
    };
    let (ray, _) = camera_ray_through(
        scene,
        &mut sampler,
        x,
        y,
        false,
        tracer.general,
        position_filter,
    );
    let mut log = PathLog {
        scene,
        lines: vec![format!(
            "pixel ({x}, {y}) sample {index}, seed {}: camera ray from ({:.6}, {:.6}, {:.6}) direction ({:.4}, {:.4}, {:.4}) time {:.4}",
            settings.seed,
            ray.origin.x,
            ray.origin.y,
            ray.origin.z,
            ray.direction.x,
            ray.direction.y,
            ray.direction.z,
            ray.time
        )],
    };
    // The camera ray tests what the render's does.
    let sampling = CameraSampling::of(scene.camera.filter, splatted, false);
    let mut pixel = scene
        .primary_candidates()
        .filter(|_| sampling.lists_apply())
        .map(|p| p.pixel(y * scene.camera.width + x))
        .unwrap_or_default();
    pixel.seen_emission = pixel
        .seen_emission
        .filter(|_| sampling.seen_emission_applies());
    let value = tracer.radiance_observed(
        scene,
        ray,
        pixel,
        &mut sampler,
        &mut RayCounts::default(),
        &mut log,
    );
    log.lines.push(format!(
        "sample value {}{}",
        rgb(value),
        if value.is_finite() {
            ""
        } else {
            " (non-finite)"
        }
    ));
    Ok((value, log.lines))
}
