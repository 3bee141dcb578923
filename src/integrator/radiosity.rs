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
//!   ray), and indirect light read from the solution (L - E) where one
//!   cosine-sampled ray lands and at a point of one element chosen by the
//!   light it reflects, combined by the power heuristic: path tracing's
//!   first bounce with the mesh's solution in place of the rest, so it
//!   agrees with path tracing up to the mesh's error in the indirect term.

use super::{RayCounts, Solver, SolverProgress, Technique};
use crate::math::{Frame, Ray, Rgb};
use crate::radiosity::mesh::back_twins;
use crate::radiosity::{
    Element, FormFactorMethod, FormFactors, Hierarchy, HierarchySettings, Mesh, RadiositySolver,
    Solution, VertexField, solve,
};
use crate::sampling::SamplerKind;
use crate::sampling::{Domain, Sampler};
use crate::scene::Scene;
use crate::shortcuts::PrimaryPixel;
use lookup::{LINE_COLOUR, facing_surface, gather, level_colour, on_edge, on_line};

mod lookup;
mod meshed;
mod settings;
pub use meshed::Meshed;
use meshed::discontinuity_mesh;
pub use settings::RadiosityDisplay;

/// Most elements (the form factor matrix of 16 384 elements takes 1 GiB).
pub const MAX_ELEMENTS: usize = 16_384;
/// Specular bounces a display ray follows to reach a diffuse surface.
const SPECULAR_DEPTH: u32 = 8;

/// Gathers per display sample where a camera ray meets a patch's back (see
/// `look_up`): one left the outside of indirect.toml's lamp shade speckled
/// by the bright ceiling above it at 16 samples per pixel.
const BACK_GATHERS: u32 = 16;

/// The radiosity technique: its settings are all it holds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
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
    /// Matrix solvers: rounds of adaptive subdivision, and its tolerance
    /// (relative to the mean reflected radiance).
    pub adaptive_rounds: u32,
    pub adaptive_tolerance: f32,
    /// Matrix solvers: elements with an angle under this (degrees) are not
    /// split (20: the slivers beside lines on the regular mesh; docs/validation.md).
    pub adaptive_min_angle: f32,
    /// Draw the elements' edges over the image, coloured by level (and
    /// the discontinuity lines in cyan).
    pub wireframe: bool,
    /// Split receivers along the shadows' discontinuities first
    /// ([`crate::radiosity::discontinuity`]).
    pub discontinuity: bool,
    /// Matrix solvers with `discontinuity`: keep the regular elements of the
    /// mesh without lines and split only those a line crosses, instead of
    /// meshing every receiver by Delaunay refinement (better from about
    /// 2 000 elements on the Cornell box, worse below: docs/validation.md).
    pub lines_on_regular_mesh: bool,
    /// With `lines_on_regular_mesh`: a crossed element stays whole where a
    /// piece would be smaller than this fraction of its area (0: every
    /// crossed element is split). Fewer slivers pay at coarse meshes.
    pub min_piece_area: f32,
    /// Matrix solvers with `discontinuity`: keep a penumbra's boundary lines
    /// (D1) only where the penumbra is narrower than this many element
    /// sizes (`patch_size`); contact lines (D0) are always kept. None keeps
    /// every line. Fewer lines cost fewer pieces, which pays at coarse meshes
    /// (docs/validation.md).
    pub max_penumbra: Option<f32>,
}

impl Technique for Radiosity {
    const SUMMARY: &'static str = "Radiosity: diffuse elements, form factors by ray casting, Jacobi, Gauss-Seidel or progressive refinement.";

    type Settings = Radiosity;

    fn new(settings: &Radiosity) -> Self {
        Radiosity {
            form_factor_samples: settings.form_factor_samples.max(1),
            ..*settings
        }
    }

    fn describe(&self) -> String {
        format!(
            "radiosity ({}{}, patch size {}{}, form factors {:?} x {}, {} display)",
            self.solver.name(),
            if self.solver == RadiositySolver::Progressive && self.ambient {
                " + ambient"
            } else {
                ""
            },
            self.patch_size,
            self.meshing_summary(),
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
    /// Smooth display: the radiance at the elements' vertices.
    vertex_radiance: VertexField,
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
    /// Adaptive subdivision rounds done, and whether another would change nothing.
    rounds: u32,
    settled: bool,
    /// Seconds spent setting up (form factors, initial links) and in steps,
    /// and preparing the display.
    solve_seconds: f64,
    display_seconds: f64,
    /// Steps and elements the display was last prepared for: a converged
    /// solution's further passes only add samples to its image.
    displayed: Option<(u64, usize)>,
    /// Per scene triangle, the coincident one facing the other way
    /// ([`crate::radiosity::mesh::back_twins`]).
    back_twins: Vec<u32>,
    /// With discontinuity meshing, the scene split along the lines, which
    /// the solver and the display work on in place of the one given.
    meshed: Option<Meshed>,
    /// The elements the gather samples as light sources.
    senders: lookup::Senders,
}

impl RadiosityState {
    /// The scene the solution belongs to: `given`, or the one split along
    /// its discontinuities.
    pub fn scene<'a>(&'a self, given: &'a Scene) -> &'a Scene {
        self.meshed.as_ref().map_or(given, |m| &m.scene)
    }

    /// The discontinuity meshing, if asked for.
    pub fn meshed(&self) -> Option<&Meshed> {
        self.meshed.as_ref()
    }

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

    /// Bytes the model takes: elements and the form factor matrix, or the
    /// hierarchy's nodes and links.
    pub fn memory_bytes(&self) -> usize {
        match &self.model {
            Model::Matrix(m) => {
                let n = m.mesh.elements.len();
                FormFactors::bytes(n) + n * std::mem::size_of::<Element>()
            }
            Model::Hierarchical(h) => h.memory_bytes(),
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
        let start = std::time::Instant::now();
        let mut state = self.build(scene)?;
        state.solve_seconds = start.elapsed().as_secs_f64();
        Ok(state)
    }

    fn step(
        &self,
        scene: &Scene,
        state: &mut RadiosityState,
        steps: u32,
        counts: &mut RayCounts,
    ) -> SolverProgress {
        let meshed = state.meshed.as_ref().map(|m| m.scene.clone());
        let scene = meshed.as_deref().unwrap_or(scene);
        let start = std::time::Instant::now();
        let mut progress = self.solve(scene, state, steps, counts);
        state.solve_seconds += start.elapsed().as_secs_f64();
        let start = std::time::Instant::now();
        self.prepare_display(scene, state);
        state.display_seconds += start.elapsed().as_secs_f64();
        progress.solve_seconds = state.solve_seconds;
        progress.display_seconds = state.display_seconds;
        progress
    }

    fn radiance(
        &self,
        scene: &Scene,
        state: &RadiosityState,
        ray: Ray,
        pixel: PrimaryPixel<'_>,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        // As in the path tracer: where the pixel's share of a light is known
        // exactly, it is added here and the camera ray's own hit on the light
        // adds no emission. Cornell box, hierarchical ε 3e-5, one step
        // against the direct reference: masked RMSE 0.00278 -> 0.00105; 92%
        // of it was one pixel at the light's corner that no point saw lit.
        let seen = pixel.seen_emission;
        let scene = state.scene(scene);
        let looked_up = self.look_up(scene, state, ray, seen.is_some(), sampler, counts);
        looked_up + seen.unwrap_or(Rgb::ZERO)
    }

    fn notes(&self, state: &RadiosityState) -> Vec<String> {
        match &state.model {
            Model::Matrix(m) => m.mesh.notes.clone(),
            Model::Hierarchical(h) => h.notes.clone(),
        }
    }

    fn display_spp(&self) -> u32 {
        16
    }

    /// Flat and smooth displays look the solution up: only edges are noisy.
    /// Cornell box, ε 3e-6, smooth: masked RMSE 0.00216 with independent
    /// pixel samples, 0.00174 with these.
    fn display_sampler(&self) -> Option<SamplerKind> {
        (self.display != RadiosityDisplay::Gather).then_some(SamplerKind::Sobol)
    }
}

impl Radiosity {
    /// The form factors of `mesh` and a first solution with every element's
    /// exposure measured; the form factors' ray count includes the
    /// exposure's rays.
    fn matrix_system(&self, scene: &Scene, mesh: &Mesh) -> (FormFactors, Solution) {
        let mut form_factors = FormFactors::compute(
            &scene.geometry,
            mesh,
            self.form_factors,
            self.form_factor_samples,
        );
        let mut solution = Solution::new(mesh);
        form_factors.rays += solution.measure_exposure(&scene.geometry, mesh);
        (form_factors, solution)
    }

    /// The solution seen along a camera ray, through mirrors and glass;
    /// `seen_known`: the first hit's emission is accounted for elsewhere.
    fn look_up(
        &self,
        scene: &Scene,
        state: &RadiosityState,
        mut ray: Ray,
        seen_known: bool,
        sampler: &mut Sampler,
        counts: &mut RayCounts,
    ) -> Rgb {
        let mut weight = Rgb::ONE;
        let mut travelled = 0.0;
        for depth in 0..=SPECULAR_DEPTH {
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return Rgb::ZERO;
            };
            travelled += hit.t;
            if depth > 0 {
                counts.bounce += 1;
            }
            let bsdf = scene.bsdf_at(&hit);
            match bsdf.diffuse_albedo() {
                None => {
                    let frame = Frame::from_normal(hit.normal);
                    let wo = frame.to_local(-ray.direction);
                    let u = sampler.next_1d_for(Domain::Bsdf);
                    let Some(s) = bsdf.sample(wo, u, glam::Vec2::ZERO) else {
                        return Rgb::ZERO;
                    };
                    weight *= s.weight;
                    ray = hit.spawn_ray(frame.to_world(s.wi));
                }
                _ => {
                    let Some((surface, from_front)) =
                        facing_surface(scene, state, &hit, ray.direction)
                    else {
                        // Spheres are not patches: their own emission only.
                        return weight * scene.emitted(&hit, -ray.direction);
                    };
                    let e = &surface.element;
                    if self.wireframe {
                        if on_line(scene, state, &hit, travelled) {
                            return weight * LINE_COLOUR;
                        }
                        if on_edge(scene, &surface, travelled) {
                            return weight * level_colour(surface.level);
                        }
                    }
                    let seen_emission = if from_front && !(depth == 0 && seen_known) {
                        e.emission
                    } else {
                        Rgb::ZERO
                    };
                    let ambient = e.reflectance * surface.ambient;
                    // A triangle's back without a patch of its own (nothing
                    // lit it when the mesh was made: `exposed_backs`) has
                    // nothing in the solution; its front's would be wrong
                    // (indirect.toml's lamp shade read 28 outside where path
                    // tracing finds 0.15). There the display gathers (light
                    // sampled, one bounce into the solution), whatever its mode.
                    if !from_front && self.display != RadiosityDisplay::Gather {
                        let (mut sum, wo) = (Rgb::ZERO, -ray.direction);
                        for _ in 0..BACK_GATHERS {
                            sum += gather(scene, state, &hit, e.reflectance, wo, sampler, counts);
                        }
                        return weight * (sum / BACK_GATHERS as f32 + ambient);
                    }
                    let reflected = match (self.display, surface.smooth) {
                        (RadiosityDisplay::Gather, _) => gather(
                            scene,
                            state,
                            &hit,
                            e.reflectance,
                            -ray.direction,
                            sampler,
                            counts,
                        ),
                        (RadiosityDisplay::Smooth, Some(smooth)) => {
                            (smooth - e.emission).max(Rgb::ZERO)
                        }
                        _ => surface.radiance - e.emission,
                    };
                    return weight * (seen_emission + reflected + ambient);
                }
            }
        }
        Rgb::ZERO
    }

    /// The model: a mesh and its form factors, or the hierarchy.
    fn build(&self, scene: &Scene) -> crate::Result<RadiosityState> {
        // Patches are triangles of the scene's own: instances are copied.
        let flat = scene.flattened();
        let (meshed, mut notes) = if self.discontinuity {
            let scene = flat.as_ref().unwrap_or(scene);
            // The matrix solvers' elements are the pieces; the hierarchy
            // subdivides its own.
            let base = self.solver.matrix().map(|_| {
                use crate::radiosity::discontinuity::Base;
                let b = scene.geometry.bounds();
                let max_edge = self.patch_size * (b.max - b.min).length();
                let base = if self.lines_on_regular_mesh {
                    Base::Regular {
                        max_edge,
                        min_piece: self.min_piece_area,
                    }
                } else {
                    Base::Delaunay { max_edge }
                };
                (base, self.max_penumbra.map(|m| m * max_edge))
            });
            let (meshed, mut notes) = discontinuity_mesh(scene, base);
            if self.max_penumbra.is_some() && base.is_none() {
                notes.push(
                    "max penumbra ignored: the hierarchy keeps every line (it applies to the \
                     matrix solvers' meshes)"
                        .into(),
                );
            }
            (Some(meshed), notes)
        } else if let Some(flat) = flat {
            let note = format!(
                "instances copied for radiosity: {} triangles",
                flat.geometry.triangle_count()
            );
            (Some(Meshed::whole(flat)), vec![note])
        } else {
            (None, Vec::new())
        };
        let mut state = match &meshed {
            Some(m) => self.build_on(&m.scene, &m.hidden)?,
            None => self.build_on(scene, &[])?,
        };
        state.meshed = meshed;
        match &mut state.model {
            Model::Matrix(m) => notes.append(&mut m.mesh.notes),
            Model::Hierarchical(h) => notes.append(&mut h.notes),
        }
        match &mut state.model {
            Model::Matrix(m) => m.mesh.notes = notes,
            Model::Hierarchical(h) => h.notes = notes,
        }
        Ok(state)
    }

    /// The model of `scene`, triangles marked in `hidden` not patches.
    fn build_on(&self, scene: &Scene, hidden: &[bool]) -> crate::Result<RadiosityState> {
        if self.solver.matrix().is_none() {
            let settings = HierarchySettings {
                epsilon: self.epsilon,
                min_size: self.patch_size,
                method: self.form_factors,
                samples: self.form_factor_samples,
                max_nodes: MAX_NODES,
                clusters: crate::radiosity::cluster::ClusterKind::Oriented,
            };
            let hierarchy = Hierarchy::build(scene, settings, hidden).map_err(crate::Error::new)?;
            return Ok(RadiosityState {
                model: Model::Hierarchical(hierarchy),
                steps: 0,
                residual: 1.0,
                rounds: 0,
                settled: true,
                solve_seconds: 0.0,
                display_seconds: 0.0,
                displayed: None,
                back_twins: back_twins(&scene.geometry),
                meshed: None,
                senders: lookup::Senders::default(),
            });
        }
        let mesh =
            Mesh::build(scene, self.patch_size, MAX_ELEMENTS, hidden).map_err(crate::Error::new)?;
        let (form_factors, solution) = self.matrix_system(scene, &mesh);
        let vertex_radiance = if self.display == RadiosityDisplay::Smooth {
            mesh.vertex_radiance(&solution.radiance, &solution.exposure, &[])
        } else {
            VertexField::default()
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
            rounds: 0,
            settled: self.adaptive_rounds == 0,
            solve_seconds: 0.0,
            display_seconds: 0.0,
            displayed: None,
            back_twins: back_twins(&scene.geometry),
            meshed: None,
            senders: lookup::Senders::default(),
        })
    }

    /// The smooth display's vertex values of the current solution.
    fn prepare_display(&self, scene: &Scene, state: &mut RadiosityState) {
        let key = (state.steps, state.counts().0);
        if state.displayed == Some(key) {
            return;
        }
        state.displayed = Some(key);
        // Every display gathers somewhere (the backs of thin surfaces).
        state.senders = match &state.model {
            Model::Matrix(m) => lookup::Senders::new(
                m.mesh.elements.len(),
                m.mesh
                    .elements
                    .iter()
                    .zip(&m.solution.radiance)
                    .enumerate()
                    .map(|(k, (e, l))| (k, e, *l)),
            ),
            Model::Hierarchical(h) => {
                let (numbers, leaves) = h.numbered_leaves();
                lookup::Senders::new(numbers, leaves)
            }
        };
        if self.display == RadiosityDisplay::Smooth {
            let lines = state
                .meshed
                .as_ref()
                .map(Meshed::line_edges)
                .unwrap_or_default();
            match &mut state.model {
                Model::Matrix(m) => {
                    m.vertex_radiance =
                        m.mesh
                            .vertex_radiance(&m.solution.radiance, &m.solution.exposure, &lines)
                }
                Model::Hierarchical(h) => h.smooth(&scene.geometry),
            }
        }
    }

    /// Up to `steps` sweeps or shots, with adaptive rounds between solves.
    fn solve(
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
            if state.residual <= CONVERGED && !state.settled {
                self.subdivide(scene, state, counts);
            }
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
        let (elements, links) = state.counts();
        SolverProgress {
            steps: state.steps,
            residual: state.residual,
            converged: state.steps >= limit || (state.residual <= CONVERGED && state.settled),
            elements: elements as u64,
            links: links as u64,
            memory: state.memory_bytes() as u64,
            solve_seconds: 0.0,
            display_seconds: 0.0,
        }
    }

    /// One round of adaptive subdivision of a converged matrix model: the
    /// elements [`Mesh::steep`] flags are split, the form factors of the new
    /// mesh computed, and the solve goes on from the old solution (Jacobi,
    /// Gauss-Seidel) or starts over (progressive, whose unshot light belongs
    /// to the old form factors). Stops, with a note, where the new mesh
    /// would exceed the matrix's budget.
    fn subdivide(&self, scene: &Scene, state: &mut RadiosityState, counts: &mut RayCounts) {
        let Model::Matrix(m) = &mut state.model else {
            state.settled = true;
            return;
        };
        let lines = state
            .meshed
            .as_ref()
            .map(Meshed::line_edges)
            .unwrap_or_default();
        let (tolerance, min_angle) = (self.adaptive_tolerance, self.adaptive_min_angle);
        let steep = m
            .mesh
            .steep(&m.solution.radiance, tolerance, min_angle, &lines);
        let added = 3 * steep.iter().filter(|&&s| s).count();
        if added == 0 {
            state.settled = true;
            return;
        }
        if m.mesh.elements.len() + added > MAX_ELEMENTS {
            m.mesh.notes.push(format!(
                "adaptive subdivision stopped after {} rounds: the next would make {} elements, \
                 more than the {MAX_ELEMENTS} the form factor matrix fits in memory for",
                state.rounds,
                m.mesh.elements.len() + added
            ));
            state.settled = true;
            return;
        }
        let (mesh, origin) = m.mesh.refine(&steep);
        let (form_factors, mut solution) = self.matrix_system(scene, &mesh);
        counts.shadow += form_factors.rays;
        if self.solver != RadiositySolver::Progressive {
            solution.radiance = origin
                .iter()
                .map(|&k| m.solution.radiance[k as usize])
                .collect();
        }
        m.mesh = mesh;
        m.form_factors = form_factors;
        m.solution = solution;
        state.rounds += 1;
        state.residual = 1.0;
        state.settled = state.rounds >= self.adaptive_rounds;
    }
}
