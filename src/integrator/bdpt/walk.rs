//! Bidirectional path tracing's subpaths: a light subpath from a particle,
//! and the random walk that extends either subpath vertex by vertex,
//! storing the densities its MIS weights need.

use super::vertex::{Kind, Local, Subpath, Vertex, origin_density, surface_vertex};
use super::{Bdpt, RayCounts, Transport};
use crate::accel::NO_LIGHT;
use crate::integrator::light::{importance_weight, sample_particle};
use crate::math::{Ray, Rgb};
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::material::Bsdf;
use glam::Vec3A;

impl Bdpt {
    /// Traces a light subpath of at most `max_vertices` vertices into
    /// `path` (empty), from a particle the sampler's current numbers choose.
    pub(super) fn light_subpath(
        &self,
        scene: &Scene,
        time: f32,
        max_vertices: usize,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        path: &mut Subpath,
    ) {
        let emission = sample_particle(scene, sampler);
        let u_lens = sampler.next_2d_for(Domain::Lens);
        let Some(emission) = emission else {
            return;
        };
        let infinite = scene.lights.is_infinite(emission.light);
        path.push(Vertex {
            kind: Kind::Light,
            point: emission.point,
            error: emission.error,
            normal: emission.normal,
            beta: Rgb::splat(1.0 / emission.pdf_position),
            // From infinity the particle's origin is its direction
            // (per solid angle; 0 for a directional light's delta).
            pdf_fwd: if infinite {
                origin_density(scene, emission.light, -emission.direction)
            } else {
                emission.pdf_position
            },
            delta_light: emission.normal == Vec3A::ZERO
                || scene.lights.is_directional(emission.light),
            infinite,
            light: emission.light,
            emitted: emission.emitted,
            two_sided: emission.two_sided,
            u_connect: u_lens,
            ..Vertex::EMPTY
        });
        let ray = emission.ray().at_time(time);
        counts.bounce += 1;
        self.random_walk(
            scene,
            ray,
            emission.throughput,
            emission.pdf_direction,
            Transport::Importance,
            max_vertices,
            sampler,
            counts,
            path,
        );
    }

    /// Extends `path` (which holds its first vertex) by tracing `ray` and
    /// sampling BSDFs, up to `max_vertices` vertices. `beta`: the weight the
    /// first ray carries; `pdf_direction`: the density of its direction.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn random_walk(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut beta: Rgb,
        mut pdf_direction: f32,
        transport: Transport,
        max_vertices: usize,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
        path: &mut Subpath,
    ) {
        // What the subpath carries relative to where it started, with the
        // radiance scaling of refraction divided out: roulette reads it, so
        // that neither a light's units nor a stay inside glass decide how
        // long a path lives.
        let mut relative = Rgb::ONE;
        let mut bounces = 0;
        while path.len() < max_vertices {
            // The lobe and roulette numbers are computed only where used
            // (their dimensions are kept either way).
            let lobe_dim = sampler.skip();
            let u_bsdf = sampler.next_2d_for(Domain::Bsdf);
            let roulette_dim = sampler.skip();
            let (u_select, u_connect) = match transport {
                Transport::Radiance => (
                    sampler.next_1d_for(Domain::Light),
                    sampler.next_2d_for(Domain::Light),
                ),
                Transport::Importance => (0.0, sampler.next_2d_for(Domain::Lens)),
            };
            // The environment's table line for this vertex's light sample
            // (made later, by the connections), fetched as the path tracer
            // fetches it.
            let camera_side = transport == Transport::Radiance;
            if camera_side {
                scene.lights.prefetch_sample_as_emitted(u_select, u_connect);
            }
            let Some(hit) = scene.geometry.intersect(&ray) else {
                // A camera subpath that leaves the scene ends on the environment.
                if camera_side && let Some(env) = scene.lights.environment() {
                    let previous = path.vertices[path.len() - 1];
                    let distance =
                        crate::scene::light::beyond_bounds(ray.origin, env.center, env.radius);
                    path.push(Vertex {
                        kind: Kind::Light,
                        point: ray.origin + ray.direction * distance,
                        normal: -ray.direction,
                        wo: -ray.direction,
                        beta,
                        pdf_fwd: previous.area_density_at(
                            pdf_direction,
                            &Vertex {
                                infinite: true,
                                ..Vertex::EMPTY
                            },
                        ),
                        infinite: true,
                        light: scene.lights.as_slice().len() as u32,
                        emitted: env.le(ray.direction),
                        ..Vertex::EMPTY
                    });
                }
                break;
            };
            let wo_world = -ray.direction;
            let index = path.len();
            let previous = path.vertices[index - 1];
            let bsdf = scene.bsdf_at(&hit);
            let mut vertex = surface_vertex(&hit, bsdf, wo_world, beta);
            if scene.features.shading_normals || scene.features.anisotropic {
                let n = scene.shading_normal(&hit);
                if n != hit.normal {
                    vertex.packed_shading = crate::math::octahedral_encode(n);
                }
                vertex.turn = scene.shading_turn(&hit, n);
            }
            if hit.light != NO_LIGHT {
                vertex.light = hit.light;
                vertex.emitted = scene.emitted(&hit, wo_world);
            }
            vertex.u_select = u_select;
            vertex.u_connect = u_connect;
            vertex.pdf_fwd = if previous.infinite {
                // A parallel beam: the disc's density, projected.
                scene.lights.disc_density(previous.light) * vertex.cos(ray.direction)
            } else {
                previous.area_density_at(pdf_direction, &vertex)
            };
            let Local { frame, wo, .. } = path.push(vertex);
            if path.len() >= max_vertices || bsdf.is_black() {
                break;
            }

            let u_lobe = if matches!(bsdf, Bsdf::Diffuse { .. }) {
                0.0
            } else {
                sampler.get_1d_for(lobe_dim, Domain::Bsdf)
            };
            let Some(sample) = bsdf.sample(wo, u_lobe, u_bsdf) else {
                break;
            };
            let weight = match transport {
                Transport::Radiance => {
                    relative /= bsdf.refraction_scale(wo, sample.wi);
                    sample.weight
                }
                Transport::Importance => {
                    importance_weight(bsdf, wo, sample.wi, path.local[index].normal, sample.weight)
                }
            };
            let (pdf_fwd, pdf_rev) = if sample.specular {
                (0.0, 0.0)
            } else {
                (sample.pdf, bsdf.pdf(sample.wi, wo))
            };
            path.vertices[index].delta = sample.specular;
            beta *= weight;
            relative *= weight;
            path.vertices[index - 1].pdf_rev = pdf_rev * path.local[index].to_previous;
            bounces += 1;
            if self.russian_roulette && bounces > self.rr_depth {
                let q = relative.max_element().min(1.0);
                if sampler.get_1d_for(roulette_dim, Domain::Other) >= q {
                    break;
                }
                beta /= q;
                relative /= q;
            }
            if !(beta.max_element() > 0.0) {
                break;
            }
            pdf_direction = pdf_fwd;
            ray = hit.spawn_ray(frame.to_world(sample.wi));
            counts.bounce += 1;
        }
    }
}
