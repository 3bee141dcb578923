//! Radiosity: the rendering equation for perfectly diffuse surfaces,
//! discretised into elements of constant radiance,
//!
//!   L_i = E_i + ρ_i Σ_j F_ij L_j,
//!
//! with form factors F_ij by ray casting or by the point-to-polygon contour
//! integral times visibility (`crate::radiosity`), solved by Jacobi or
//! Gauss–Seidel sweeps or by progressive refinement (shooting, with the
//! ambient term for display). A solver technique: each step is a sweep or a
//! shot, after which the whole image is redrawn from the solution.
//!
//! Display (16 camera rays per pixel; mirrors and glass are traced from the
//! camera until a diffuse surface, the classic two-pass combination, so
//! caustics are missing), at the first diffuse hit:
//!
//! - `flat`: the radiance of the element hit;
//! - `smooth`: interpolated from the element's vertices, each the
//!   area-weighted mean of the elements that share it on the same plane;
//! - `gather`: emitted light, direct light by light sampling (one shadow
//!   ray), and indirect light by one cosine-sampled ray that reads L - E of
//!   the element it lands on: path tracing's first bounce with the mesh's
//!   solution in place of the rest, so it agrees with path tracing up to
//!   the mesh's error in the indirect term.

use super::{IntegratorOptions, RayCounts, Solver, SolverProgress, Technique};
use crate::math::{Frame, Ray, Rgb};
use crate::radiosity::{
    Element, FormFactorMethod, FormFactors, Hierarchy, HierarchySettings, Mesh, RadiositySolver,
    Solution, solve,
};
use crate::sampling::warp::square_to_cosine_hemisphere;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::scene::material::Bsdf;

/// Most elements (the form factor matrix of 16 384 elements takes 1 GiB).
pub const MAX_ELEMENTS: usize = 16_384;
/// Specular bounces a display ray follows to reach a diffuse surface.
const SPECULAR_DEPTH: u32 = 8;

/// Settings of the radiosity technique.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radiosity {
    pub solver: RadiositySolver,
    /// Longest element edge, as a fraction of the scene's diagonal.
    pub patch_size: f32,
    pub form_factors: FormFactorMethod,
    /// Samples per element pair.
    pub form_factor_samples: u32,
    /// Progressive refinement: add the ambient term to the display.
    pub ambient: bool,
    /// Stop after this many steps (0: when converged).
    pub iterations: u32,
    pub display: RadiosityDisplay,
    /// Hierarchical: the BF oracle's threshold, relative to the emitted power.
    pub epsilon: f32,
}

/// How the solution is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadiosityDisplay {
    /// Each element's constant radiance.
    Flat,
    /// Radiance interpolated from the elements' vertices.
    Smooth,
    /// Direct light sampled, indirect gathered from the solution.
    #[default]
    Gather,
}

impl RadiosityDisplay {
    pub const ALL: [RadiosityDisplay; 3] = [
        RadiosityDisplay::Flat,
        RadiosityDisplay::Smooth,
        RadiosityDisplay::Gather,
    ];

    pub fn name(self) -> &'static str {
        match self {
            RadiosityDisplay::Flat => "flat",
            RadiosityDisplay::Smooth => "smooth",
            RadiosityDisplay::Gather => "gather",
        }
    }
}

impl Technique for Radiosity {
    const SUMMARY: &'static str = "Radiosity: diffuse elements, form factors by ray casting, Jacobi, Gauss-Seidel or progressive refinement.";

    fn from_options(options: &IntegratorOptions) -> Self {
        Radiosity {
            solver: options.radiosity_solver,
            patch_size: options.patch_size,
            form_factors: options.form_factor_method,
            form_factor_samples: options.form_factor_samples.max(1),
            ambient: options.radiosity_ambient,
            iterations: options.radiosity_iterations,
            display: options.radiosity_display,
            epsilon: options.radiosity_epsilon,
        }
    }

    fn describe(&self) -> String {
        format!(
            "radiosity ({}{}, patch size {}, form factors {:?} x {}, {} display)",
            self.solver.name(),
            if self.solver == RadiositySolver::Progressive && self.ambient {
                " + ambient"
            } else {
                ""
            },
            self.patch_size,
            self.form_factors,
            self.form_factor_samples,
            self.display.name()
        )
    }
}

/// The full-matrix model: a uniform mesh, every pair's form factor, the solution.
pub struct MatrixModel {
    pub mesh: Mesh,
    pub form_factors: FormFactors,
    pub solution: Solution,
    /// Smooth display: per element, its three vertices' radiance.
    vertex_radiance: Vec<[Rgb; 3]>,
}

/// What a radiosity solver works on.
pub enum Model {
    Matrix(MatrixModel),
    Hierarchical(Hierarchy),
}

/// The model and where its solve stands.
pub struct RadiosityState {
    pub model: Model,
    steps: u64,
    residual: f64,
}

impl RadiosityState {
    /// The full-matrix model, unless the solver is hierarchical.
    pub fn matrix(&self) -> Option<&MatrixModel> {
        match &self.model {
            Model::Matrix(m) => Some(m),
            Model::Hierarchical(_) => None,
        }
    }

    /// The hierarchy, if the solver is hierarchical.
    pub fn hierarchy(&self) -> Option<&Hierarchy> {
        match &self.model {
            Model::Hierarchical(h) => Some(h),
            Model::Matrix(_) => None,
        }
    }

    /// Every element (the hierarchy's leaves) with its radiance.
    pub fn elements(&self) -> Vec<(Element, Rgb)> {
        match &self.model {
            Model::Matrix(m) => m
                .mesh
                .elements
                .iter()
                .copied()
                .zip(m.solution.radiance.iter().copied())
                .collect(),
            Model::Hierarchical(h) => h.leaves().map(|(e, l)| (*e, l)).collect(),
        }
    }

    /// (elements, links): leaves and links, or elements and every ordered pair.
    pub fn counts(&self) -> (usize, usize) {
        match &self.model {
            Model::Matrix(m) => {
                let n = m.mesh.elements.len();
                (n, n * n.saturating_sub(1))
            }
            Model::Hierarchical(h) => h.counts(),
        }
    }
}

/// The residual at which the solution counts as converged.
const CONVERGED: f64 = 1e-6;

/// Most hierarchy nodes (about 120 bytes each, plus their links).
pub const MAX_NODES: usize = 4_000_000;

impl Solver for Radiosity {
    type State = RadiosityState;

    fn init(&self, scene: &Scene) -> crate::Result<RadiosityState> {
        if self.solver.matrix().is_none() {
            let settings = HierarchySettings {
                epsilon: self.epsilon,
                min_size: self.patch_size,
                method: self.form_factors,
                samples: self.form_factor_samples,
                max_nodes: MAX_NODES,
            };
            let hierarchy = Hierarchy::build(scene, settings).map_err(crate::Error::new)?;
            return Ok(RadiosityState {
                model: Model::Hierarchical(hierarchy),
                steps: 0,
                residual: 1.0,
            });
        }
        let mesh = Mesh::build(scene, self.patch_size, MAX_ELEMENTS).map_err(crate::Error::new)?;
        let form_factors = FormFactors::compute(
            &scene.geometry,
            &mesh,
            self.form_factors,
            self.form_factor_samples,
        );
        let solution = Solution::new(&mesh);
        let vertex_radiance = if self.display == RadiosityDisplay::Smooth {
            mesh.vertex_average(&solution.radiance)
        } else {
            Vec::new()
        };
        Ok(RadiosityState {
            model: Model::Matrix(MatrixModel {
                mesh,
                form_factors,
                solution,
                vertex_radiance,
            }),
            steps: 0,
            residual: 1.0,
        })
    }

    fn step(
        &self,
        scene: &Scene,
        state: &mut RadiosityState,
        steps: u32,
        counts: &mut RayCounts,
    ) -> SolverProgress {
        let limit = if self.iterations == 0 {
            u64::MAX
        } else {
            self.iterations as u64
        };
        for _ in 0..steps {
            if state.steps >= limit || state.residual <= CONVERGED {
                break;
            }
            state.steps += 1;
            match &mut state.model {
                Model::Matrix(m) => {
                    // The form factors' rays are counted with the first step.
                    if state.steps == 1 {
                        counts.shadow += m.form_factors.rays;
                    }
                    if let Some(solver) = self.solver.matrix() {
                        state.residual = solve::step(
                            solver,
                            &m.mesh,
                            &m.form_factors,
                            &mut m.solution,
                            self.ambient,
                        );
                    }
                }
                Model::Hierarchical(h) => {
                    let before = h.rays;
                    state.residual = h.step(&scene.geometry);
                    counts.shadow += h.rays - before;
                    if state.steps == 1 {
                        counts.shadow += before;
                    }
                }
            }
        }
        if self.display == RadiosityDisplay::Smooth {
            match &mut state.model {
                Model::Matrix(m) => m.vertex_radiance = m.mesh.vertex_average(&m.solution.radiance),
                Model::Hierarchical(h) => h.smooth(),
            }
        }
        let (elements, links) = state.counts();
        SolverProgress {
            steps: state.steps,
            residual: state.residual,
            converged: state.steps >= limit || state.residual <= CONVERGED,
            elements: elements as u64,
            links: links as u64,
        }
    }

    fn radiance(
        &self,
        scene: &Scene,
        state: &RadiosityState,
        ray: Ray,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let mut ray = ray;
        let mut weight = Rgb::ONE;
        for depth in 0..=SPECULAR_DEPTH {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return Rgb::ZERO;
            };
            if depth > 0 {
                counts.bounce += 1;
            }
            let material = &scene.materials[hit.material as usize];
            match material.bsdf {
                Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => {
                    let frame = Frame::from_normal(hit.normal);
                    let wo = frame.to_local(-ray.direction);
                    let u = sampler.next_1d_for(Domain::Bsdf);
                    let Some(s) = material.bsdf.sample(wo, u, glam::Vec2::ZERO) else {
                        return Rgb::ZERO;
                    };
                    weight *= s.weight;
                    ray = hit.spawn_ray(frame.to_world(s.wi));
                }
                _ => {
                    let Some(surface) = surface_at(scene, state, &hit) else {
                        // Spheres are not patches: their own emission only.
                        return weight * material.emitted(hit.normal, -ray.direction);
                    };
                    let e = &surface.element;
                    let seen_emission = if e.normal.dot(ray.direction) < 0.0 {
                        e.emission
                    } else {
                        Rgb::ZERO
                    };
                    let ambient = e.reflectance * surface.ambient;
                    let reflected = match (self.display, surface.vertices) {
                        (RadiosityDisplay::Gather, _) => gather(
                            scene,
                            state,
                            &hit,
                            e.reflectance,
                            -ray.direction,
                            sampler,
                            counts,
                        ),
                        (RadiosityDisplay::Smooth, Some([l0, l1, l2])) => {
                            let b = surface.barycentrics;
                            ((1.0 - b.x - b.y) * l0 + b.x * l1 + b.y * l2 - e.emission)
                                .max(Rgb::ZERO)
                        }
                        _ => surface.radiance - e.emission,
                    };
                    return weight * (seen_emission + reflected + ambient);
                }
            }
        }
        Rgb::ZERO
    }

    fn display_spp(&self) -> u32 {
        16
    }
}

/// What the solution says at a surface point.
struct Surface {
    /// The element's radiance (emission included).
    radiance: Rgb,
    element: Element,
    /// The point's barycentrics in the element.
    barycentrics: glam::Vec2,
    /// Smooth display: the element's vertex radiance.
    vertices: Option<[Rgb; 3]>,
    ambient: Rgb,
}

/// The element a hit lies in and its solution (None for spheres and
/// surfaces that are not patches).
fn surface_at(
    scene: &Scene,
    state: &RadiosityState,
    hit: &crate::accel::SurfaceHit,
) -> Option<Surface> {
    let triangle = hit.primitive as usize;
    let [a, b, c] = *scene.geometry.triangles().get(triangle)?;
    let (b1, b2) = barycentrics(hit.point, [a, b, c]);
    let (b1, b2) = (b1.clamp(0.0, 1.0), b2.clamp(0.0, 1.0 - b1.clamp(0.0, 1.0)));
    let (radiance, element, vertices, ambient) = match &state.model {
        Model::Matrix(m) => {
            let k = m.mesh.element_at(triangle, b1, b2)?;
            (
                m.solution.radiance[k],
                m.mesh.elements[k],
                m.vertex_radiance.get(k).copied(),
                m.solution.ambient,
            )
        }
        Model::Hierarchical(h) => {
            let (radiance, element, vertices) = h.leaf_at(triangle, b1, b2)?;
            (radiance, *element, vertices, Rgb::ZERO)
        }
    };
    let (e1, e2) = barycentrics(hit.point, element.vertices);
    Some(Surface {
        radiance,
        element,
        barycentrics: glam::Vec2::new(e1, e2),
        vertices,
        ambient,
    })
}

/// Barycentrics (b1, b2) of `p` in the triangle `v`, by sub-triangle areas.
fn barycentrics(p: glam::Vec3A, [a, b, c]: [glam::Vec3A; 3]) -> (f32, f32) {
    let n = (b - a).cross(c - a);
    let inv = 1.0 / n.length_squared();
    (
        (p - a).cross(c - a).dot(n) * inv,
        (b - a).cross(p - a).dot(n) * inv,
    )
}

/// Reflected radiance at a diffuse hit: direct light by one light sample,
/// indirect by one cosine-sampled ray reading the solution (L - E) where it lands.
fn gather(
    scene: &Scene,
    state: &RadiosityState,
    hit: &crate::accel::SurfaceHit,
    reflectance: Rgb,
    wo: glam::Vec3A,
    sampler: &mut Sampler,
    counts: &mut RayCounts,
) -> Rgb {
    // The side the camera ray came from.
    let normal = if hit.normal.dot(wo) < 0.0 {
        -hit.normal
    } else {
        hit.normal
    };
    let mut direct = Rgb::ZERO;
    let u_select = sampler.next_1d_for(Domain::Light);
    let u_light = sampler.next_2d_for(Domain::Light);
    if let Some(ls) = scene.lights.sample(hit.point, u_select, u_light) {
        let cos = normal.dot(ls.wi);
        if cos > 0.0 {
            counts.shadow += 1;
            if !scene.geometry.occluded(&super::path::shadow_ray(hit, &ls)) {
                // f = ρ/π (Lambert).
                direct = reflectance * ls.radiance * (cos / (std::f32::consts::PI * ls.pdf));
            }
        }
    }
    let local = square_to_cosine_hemisphere(sampler.next_2d_for(Domain::Bsdf));
    let ray = hit.spawn_ray(Frame::from_normal(normal).to_world(local));
    counts.bounce += 1;
    let indirect = match scene.geometry.intersect(&ray) {
        Some(next) => match surface_at(scene, state, &next) {
            Some(s) => s.radiance - s.element.emission,
            None => Rgb::ZERO,
        },
        None => Rgb::ZERO,
    };
    // Cosine sampling: f cos / p = ρ.
    direct + reflectance * indirect
}
