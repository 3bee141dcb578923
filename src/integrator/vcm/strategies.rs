//! VCM's strategies at a vertex: the light subpaths' splats through the
//! lens (t = 1, the light point itself included), and at a camera vertex
//! light sampling (s = 1), connections to the pixel's light subpath and
//! merges with the light vertices within the radius, each weighed by the
//! recursive quantities of `mod.rs`.

use super::super::light::{photon_shading_factor, sees_lens, shading_correction};
use super::{Iteration, LightVertex, Vcm, Walk};
use crate::camera::CameraConnection;
use crate::film::splats::PendingSplats;
use crate::integrator::RayCounts;
use crate::integrator::photon_map::Side;
use crate::math::{Frame, Rgb, ray_between};
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::light::EmissionSample;
use crate::scene::material::Bsdf;
use glam::Vec3A;

/// A camera subpath's vertex where it connects and merges.
pub(super) struct CameraVertex {
    pub(super) point: Vec3A,
    pub(super) error: Vec3A,
    /// The geometric normal; `frame` is the shading normal's, and `ng` the
    /// geometric normal in it.
    pub(super) normal: Vec3A,
    pub(super) ng: Vec3A,
    pub(super) frame: Frame,
    pub(super) wo: Vec3A,
    pub(super) bsdf: Bsdf,
    pub(super) segments: u32,
}

impl Vcm {
    /// s = 1, t = 1: the light point itself seen through the lens, weighed
    /// against camera rays that hit it (the splats spread an emitter's
    /// edge over the pixels it covers, where camera rays alone are noisy).
    pub(super) fn light_point_to_camera(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        emission: &EmissionSample,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        splats: &mut PendingSplats,
    ) {
        let at = (emission.point, emission.error, emission.normal);
        self.splat_through_lens(scene, iteration, at, sampler, counts, splats, |c| {
            let cos = emission.normal.dot(c.wi).abs();
            let value = emission.emitted_towards(c.wi) * (cos * c.weight / emission.pdf_position);
            let camera = self.camera_density(scene, iteration, c, emission.point, cos);
            value / (1.0 + self.mis(camera / emission.pdf_position))
        });
    }

    /// t = 1: the light vertex seen through the lens, splatted where it
    /// lands.
    pub(super) fn connect_to_camera(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        v: &LightVertex,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        splats: &mut PendingSplats,
    ) {
        let at = (v.point, v.error, v.normal);
        self.splat_through_lens(scene, iteration, at, sampler, counts, splats, |c| {
            let bsdf = scene.materials[v.material as usize].bsdf_at(&scene.textures, v.uv);
            let frame = v.frame();
            let shading = frame.n;
            let (wo, wi) = (frame.to_local(v.wo), frame.to_local(c.wi));
            let (f, _, pdf_reverse) = bsdf.eval_adjoint_with_pdfs(wo, wi);
            let f = f * shading_correction(wo, wi, super::normal_in(&frame, v.normal, shading));
            // The scattering's cosine is the shading normal's, the
            // density's conversion to area the geometric one's.
            let cos = v.normal.dot(c.wi).abs();
            let value = v.beta * f * (wi.z.abs() * c.weight);
            let camera = self.camera_density(scene, iteration, c, v.point, cos);
            let w_light =
                self.mis(camera) * (iteration.vm_factor + v.d_vcm + v.d_vc * self.mis(pdf_reverse));
            value / (1.0 + w_light)
        });
    }

    /// Joins the point `(point, error, normal)` to a lens point and, where
    /// `weighted` (its MIS-weighted value) is positive and the lens is in
    /// sight, splats it where it lands on the film (through `splats`, which
    /// the light path flushes to the iteration's image when it ends). A
    /// non-finite value is dropped by the buffer: the film stays clean.
    #[allow(clippy::too_many_arguments)]
    fn splat_through_lens(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        (point, error, normal): (Vec3A, Vec3A, Vec3A),
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        splats: &mut PendingSplats,
        weighted: impl FnOnce(&CameraConnection) -> Rgb,
    ) {
        let u_lens = sampler.next_2d_for(Domain::Lens);
        let Some(c) = scene.camera.connect(point, u_lens) else {
            return;
        };
        let value = weighted(&c);
        if !(value.max_element() > 0.0)
            || !sees_lens::<false>(scene, point, error, normal, &c, iteration.time, counts)
        {
            return;
        }
        splats.push(&iteration.light_image, c.film, value, true);
    }

    /// The density (area, at `point`) of the camera's rays reaching it, per
    /// light subpath: the film-wide density times pixels / N (pbrt's and
    /// SmallVCM's t = 1 weight).
    fn camera_density(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        c: &CameraConnection,
        point: Vec3A,
        cos: f32,
    ) -> f32 {
        let dist2 = (c.lens_point - point).length_squared();
        let pixels = (scene.camera.width * scene.camera.height) as f32;
        scene.camera.pdf_direction(-c.wi) * cos / dist2 * pixels / iteration.paths as f32
    }

    /// s = 1: a point sampled on a light, weighed against hitting it (s = 0)
    /// and against every strategy with more light vertices.
    pub(super) fn light_sample(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        at: &CameraVertex,
        walk: &Walk,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let u_select = sampler.next_1d_for(Domain::Light);
        let u_light = sampler.next_2d_for(Domain::Light);
        // The environment's radiance is looked up behind a clear shadow ray.
        let Some((ls, deferred)) = scene
            .lights
            .sample_as_emitted_deferred(at.point, u_select, u_light)
        else {
            return Rgb::ZERO;
        };
        let wi = at.frame.to_local(ls.wi);
        let (f, pdf, pdf_reverse) = at.bsdf.eval_with_pdfs(at.wo, wi);
        let cos = at.normal.dot(ls.wi).abs();
        let scale = wi.z.abs() / ls.pdf;
        if !((f * ls.radiance * scale).max_element() > 0.0) {
            return Rgb::ZERO;
        }
        let dist2 = ls.distance * ls.distance;
        let (pdf_position, pdf_emission) = scene.lights.emission_pdf(ls.light, ls.normal, -ls.wi);
        // A light at infinity is sampled by direction; its light subpaths
        // start on a disc, by area there.
        let infinite = scene.lights.is_infinite(ls.light);
        let w_light = if ls.delta {
            0.0
        } else if infinite {
            self.mis(pdf / ls.pdf)
        } else {
            let cos_light = ls.normal.dot(ls.wi).abs();
            self.mis(pdf * cos_light / (dist2 * pdf_position))
        };
        let emitted_here = if infinite {
            pdf_position * pdf_emission * cos / ls.pdf
        } else {
            pdf_emission * cos / dist2
        };
        let w_camera = self.mis(emitted_here)
            * (iteration.vm_factor + walk.d_vcm + walk.d_vc * self.mis(pdf_reverse));
        counts.shadow += 1;
        let shadow = ray_between(at.point, at.error, at.normal, ls.point, ls.error, ls.normal)
            .at_time(iteration.time);
        if scene.geometry.occluded(&shadow) {
            return Rgb::ZERO;
        }
        let radiance = scene.lights.deferred_radiance(deferred, ls.radiance);
        f * radiance * scale / (1.0 + w_light + w_camera)
    }

    /// s >= 2, t >= 2: a shadow ray from the camera vertex to a vertex of
    /// its pixel's light subpath.
    pub(super) fn connect(
        &self,
        scene: &Scene,
        iteration: &Iteration,
        at: &CameraVertex,
        walk: &Walk,
        light: &LightVertex,
        counts: &mut RayCounts,
    ) -> Rgb {
        let d = light.point - at.point;
        let dist2 = d.length_squared();
        if !(dist2 > 0.0) {
            return Rgb::ZERO;
        }
        let w = d / dist2.sqrt();
        let w_camera_local = at.frame.to_local(w);
        let (f_camera, pdf_camera, pdf_camera_reverse) =
            at.bsdf.eval_with_pdfs(at.wo, w_camera_local);
        let light_bsdf =
            scene.materials[light.material as usize].bsdf_at(&scene.textures, light.uv);
        let light_frame = light.frame();
        let light_shading = light_frame.n;
        let (light_wo, light_wi) = (light_frame.to_local(light.wo), light_frame.to_local(-w));
        let (f_light, pdf_light, pdf_light_reverse) =
            light_bsdf.eval_adjoint_with_pdfs(light_wo, light_wi);
        let f_light = f_light
            * shading_correction(
                light_wo,
                light_wi,
                super::normal_in(&light_frame, light.normal, light_shading),
            );
        // Shading cosines in the value (pbrt's G), geometric ones in the
        // densities' conversions to area.
        let (cos_camera, cos_light) = (at.normal.dot(w).abs(), light.normal.dot(w).abs());
        let value =
            f_camera * f_light * light.beta * (w_camera_local.z.abs() * light_wi.z.abs() / dist2);
        if !(value.max_element() > 0.0) {
            return Rgb::ZERO;
        }
        // Densities (area) of each end sampled from the other.
        let camera_to_light = pdf_camera * cos_light / dist2;
        let light_to_camera = pdf_light * cos_camera / dist2;
        let w_light = self.mis(camera_to_light)
            * (iteration.vm_factor + light.d_vcm + light.d_vc * self.mis(pdf_light_reverse));
        let w_camera = self.mis(light_to_camera)
            * (iteration.vm_factor + walk.d_vcm + walk.d_vc * self.mis(pdf_camera_reverse));
        counts.shadow += 1;
        let shadow = ray_between(
            at.point,
            at.error,
            at.normal,
            light.point,
            light.error,
            light.normal,
        )
        .at_time(iteration.time);
        if scene.geometry.occluded(&shadow) {
            return Rgb::ZERO;
        }
        value / (1.0 + w_light + w_camera)
    }

    /// Merges: every light vertex within the radius on the same side (on
    /// both where the surface transmits), its flux reflected by the camera
    /// vertex's BSDF, each weighed against the connections that could have
    /// made its path (not yet divided by pi r^2 N).
    pub(super) fn merge(&self, iteration: &Iteration, at: &CameraVertex, walk: &Walk) -> Rgb {
        let facing = if at.normal.dot(at.frame.to_world(at.wo)) >= 0.0 {
            at.normal
        } else {
            -at.normal
        };
        let side = Side::of(facing, at.bsdf.is_transmissive());
        let mut sum = Rgb::ZERO;
        iteration.map.for_each_near(at.point, side, |light| {
            if light.segments + at.segments > self.max_depth + 1 {
                return;
            }
            let wi = at.frame.to_local(light.wo.into());
            let (f, pdf, pdf_reverse) = at.bsdf.eval_with_pdfs(at.wo, wi);
            // Flux per geometric area turned into the shading integral.
            let f = f * photon_shading_factor(wi, at.ng);
            if !(f.max_element() > 0.0) {
                return;
            }
            let w_light = light.d_vcm * iteration.vc_factor + light.d_vm * self.mis(pdf);
            let w_camera = walk.d_vcm * iteration.vc_factor + walk.d_vm * self.mis(pdf_reverse);
            sum += f * Rgb::from(light.beta) / (1.0 + w_light + w_camera);
        });
        sum
    }
}
