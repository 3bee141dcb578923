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
//! Display (ray-cast, 16 camera rays per pixel): a camera ray reads the
//! radiance of the element it hits first; mirrors and glass are traced from
//! the camera until a diffuse surface (the classic two-pass combination), so
//! caustics are missing.

use super::{IntegratorOptions, RayCounts, Solver, SolverProgress, Technique};
use crate::math::{Frame, Ray, Rgb};
use crate::radiosity::{FormFactorMethod, FormFactors, Mesh, RadiositySolver, Solution, solve};
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
        }
    }

    fn describe(&self) -> String {
        format!(
            "radiosity ({}{}, patch size {}, form factors {:?} x {})",
            self.solver.name(),
            if self.solver == RadiositySolver::Progressive && self.ambient {
                " + ambient"
            } else {
                ""
            },
            self.patch_size,
            self.form_factors,
            self.form_factor_samples
        )
    }
}

/// The mesh, its form factors and the current solution.
pub struct RadiosityState {
    pub mesh: Mesh,
    pub form_factors: FormFactors,
    pub solution: Solution,
    residual: f64,
}

/// The residual at which the solution counts as converged.
const CONVERGED: f64 = 1e-6;

impl Solver for Radiosity {
    type State = RadiosityState;

    fn init(&self, scene: &Scene) -> crate::Result<RadiosityState> {
        let mesh = Mesh::build(scene, self.patch_size, MAX_ELEMENTS).map_err(crate::Error::new)?;
        let form_factors = FormFactors::compute(
            &scene.geometry,
            &mesh,
            self.form_factors,
            self.form_factor_samples,
        );
        let solution = Solution::new(&mesh);
        Ok(RadiosityState {
            mesh,
            form_factors,
            solution,
            residual: 1.0,
        })
    }

    fn step(
        &self,
        _: &Scene,
        state: &mut RadiosityState,
        steps: u32,
        counts: &mut RayCounts,
    ) -> SolverProgress {
        // The form factors' rays are counted with the first step.
        if state.solution.steps == 0 {
            counts.shadow += state.form_factors.rays;
        }
        let limit = if self.iterations == 0 {
            u64::MAX
        } else {
            self.iterations as u64
        };
        for _ in 0..steps {
            if state.solution.steps >= limit || state.residual <= CONVERGED {
                break;
            }
            state.residual = solve::step(
                self.solver,
                &state.mesh,
                &state.form_factors,
                &mut state.solution,
                self.ambient,
            );
        }
        SolverProgress {
            steps: state.solution.steps,
            residual: state.residual,
            converged: state.solution.steps >= limit || state.residual <= CONVERGED,
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
                    let Some(element) = element_hit(scene, state, &hit) else {
                        // Spheres are not patches: their own emission only.
                        return weight * material.emitted(hit.normal, -ray.direction);
                    };
                    let e = &state.mesh.elements[element];
                    let mut radiance = state.solution.radiance[element];
                    // One-sided emitters are dark from behind.
                    if e.normal.dot(ray.direction) > 0.0 {
                        radiance -= e.emission;
                    }
                    return weight * (radiance + e.reflectance * state.solution.ambient);
                }
            }
        }
        Rgb::ZERO
    }

    fn display_spp(&self) -> u32 {
        16
    }
}

/// The element a camera ray's hit lies in (None for spheres).
fn element_hit(
    scene: &Scene,
    state: &RadiosityState,
    hit: &crate::accel::SurfaceHit,
) -> Option<usize> {
    let triangle = hit.primitive as usize;
    let [a, b, c] = *scene.geometry.triangles().get(triangle)?;
    // Barycentrics by the areas of the sub-triangles (in the plane).
    let n = (b - a).cross(c - a);
    let inv = 1.0 / n.length_squared();
    let b1 = (hit.point - a).cross(c - a).dot(n) * inv;
    let b2 = (b - a).cross(hit.point - a).dot(n) * inv;
    state.mesh.element_at(
        triangle,
        b1.clamp(0.0, 1.0),
        b2.clamp(0.0, 1.0 - b1.clamp(0.0, 1.0)),
    )
}
