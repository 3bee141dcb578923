//! The radiosity system L_i = E_i + ρ_i Σ_j F_ij L_j (in radiance: B = π L
//! for diffuse surfaces, so both sides divide by π) and its solvers:
//! Jacobi and Gauss–Seidel gathering, and progressive refinement by
//! shooting the patch with the most unshot power (Southwell; a patch's
//! elements shoot together, Cohen et al.'s substructuring), with the
//! ambient term of Cohen et al. 1988 for display.

use super::element::Element;
use super::form_factor::{
    EXPOSURE_POINTS, FormFactorMethod, element_to_element, exposure, sent_radiance,
};
use super::mesh::Mesh;
use crate::accel::Geometry;
use crate::math::Rgb;
use rayon::prelude::*;

/// Which solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadiositySolver {
    Jacobi,
    #[default]
    GaussSeidel,
    /// Progressive refinement: shoot the element with the most unshot power.
    Progressive,
    /// Hierarchical radiosity: links refined by the BF oracle (see `hierarchy`).
    Hierarchical,
}

impl RadiositySolver {
    pub const ALL: [RadiositySolver; 4] = [
        RadiositySolver::Jacobi,
        RadiositySolver::GaussSeidel,
        RadiositySolver::Progressive,
        RadiositySolver::Hierarchical,
    ];

    pub fn name(self) -> &'static str {
        match self {
            RadiositySolver::Jacobi => "jacobi",
            RadiositySolver::GaussSeidel => "gauss-seidel",
            RadiositySolver::Progressive => "progressive",
            RadiositySolver::Hierarchical => "hierarchical",
        }
    }
}

/// The solvers of the full form factor matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatrixSolver {
    Jacobi,
    GaussSeidel,
    Progressive,
}

impl RadiositySolver {
    /// The matrix solver, or None for the hierarchical one.
    pub fn matrix(self) -> Option<MatrixSolver> {
        match self {
            RadiositySolver::Jacobi => Some(MatrixSolver::Jacobi),
            RadiositySolver::GaussSeidel => Some(MatrixSolver::GaussSeidel),
            RadiositySolver::Progressive => Some(MatrixSolver::Progressive),
            RadiositySolver::Hierarchical => None,
        }
    }
}

/// The form factors of every element pair, row-major. Each row is estimated
/// on its own (not filled in by reciprocity, A_i F_ij = A_j F_ji), so that
/// it conserves energy: a closed scene's rows sum to 1.
pub struct FormFactors {
    n: usize,
    values: Vec<f32>,
    /// Shadow rays cast to estimate them.
    pub rays: u64,
}

impl FormFactors {
    /// Bytes the matrix of `n` elements takes.
    pub fn bytes(n: usize) -> usize {
        n * n * std::mem::size_of::<f32>()
    }

    /// Estimates every F_ij with `samples` samples per pair, in parallel over rows.
    pub fn compute(
        geometry: &Geometry,
        mesh: &Mesh,
        method: FormFactorMethod,
        samples: u32,
    ) -> FormFactors {
        let elements = &mesh.elements;
        let n = elements.len();
        let mut values = vec![0.0f32; n * n];
        let rays: u64 = values
            .par_chunks_mut(n.max(1))
            .enumerate()
            .map(|(i, row)| {
                let mut rays = 0u64;
                for (j, f) in row.iter_mut().enumerate() {
                    if j == i {
                        continue;
                    }
                    let keys = (i as u32, (i * n + j) as u32);
                    let exchange = element_to_element(
                        geometry,
                        &elements[i],
                        &elements[j],
                        method,
                        samples,
                        keys,
                    );
                    *f = exchange.f;
                    rays += exchange.rays as u64;
                }
                rays
            })
            .sum();
        FormFactors { n, values, rays }
    }

    /// F_ij.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f32 {
        self.values[i * self.n + j]
    }

    /// Σ_j F_ij: the share of light leaving i that reaches other elements.
    pub fn row_sum(&self, i: usize) -> f32 {
        self.row(i).iter().sum()
    }

    /// Row i: F_i0 .. F_i(n-1).
    #[inline]
    pub fn row(&self, i: usize) -> &[f32] {
        &self.values[i * self.n..(i + 1) * self.n]
    }
}

/// The solution and what the solver needs between steps.
pub struct Solution {
    /// Radiance per element.
    pub radiance: Vec<Rgb>,
    /// Progressive refinement: radiance not yet shot, as sent from each
    /// element's open part (see `exposure`).
    pub unshot: Vec<Rgb>,
    /// Per element, the share light can leave from
    /// ([`super::form_factor::exposure`]); 1 until measured.
    pub exposure: Vec<f32>,
    /// The ambient term added for display (progressive with ambient).
    pub ambient: Rgb,
    pub steps: u64,
}

impl Solution {
    /// L = E, everything unshot.
    pub fn new(mesh: &Mesh) -> Solution {
        let emission: Vec<Rgb> = mesh.elements.iter().map(|e| e.emission).collect();
        Solution {
            radiance: emission.clone(),
            unshot: emission,
            exposure: vec![1.0; mesh.elements.len()],
            ambient: Rgb::ZERO,
            steps: 0,
        }
    }

    /// Measures every element's exposure; returns the rays cast.
    pub fn measure_exposure(&mut self, geometry: &Geometry, mesh: &Mesh) -> u64 {
        let measured: Vec<(f32, u32)> = mesh
            .elements
            .par_iter()
            .map(|e| exposure(geometry, &mesh.two_sided, e, EXPOSURE_POINTS))
            .collect();
        self.exposure = measured.iter().map(|m| m.0).collect();
        measured.iter().map(|m| u64::from(m.1)).sum()
    }

    /// The radiance element i sends: its reflected light spread over its
    /// open part (a floor element half under a block is dark on its hidden
    /// half, and sends from the other half only).
    #[inline]
    fn exitant(&self, i: usize, e: &Element) -> Rgb {
        sent_radiance(self.radiance[i], e.emission, self.exposure[i])
    }
}

fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Emitted power (up to π, the same factor everywhere): Σ A_i lum(E_i).
pub fn emitted_power(mesh: &Mesh) -> f64 {
    mesh.elements
        .iter()
        .map(|e| e.area as f64 * luminance(e.emission) as f64)
        .sum()
}

/// One step: a sweep (Jacobi, Gauss–Seidel) or one shot (progressive).
/// Returns the residual: the power changed by the sweep, or the unshot
/// power, over the emitted power.
pub fn step(
    solver: MatrixSolver,
    mesh: &Mesh,
    f: &FormFactors,
    s: &mut Solution,
    ambient: bool,
) -> f64 {
    let elements = &mesh.elements;
    let emitted = emitted_power(mesh).max(f64::MIN_POSITIVE);
    s.steps += 1;
    match solver {
        MatrixSolver::Jacobi => {
            let sent: Vec<Rgb> = (0..elements.len())
                .map(|j| s.exitant(j, &elements[j]))
                .collect();
            let old = &s.radiance;
            let new: Vec<Rgb> = (0..elements.len())
                .into_par_iter()
                .map(|i| {
                    let gathered = f
                        .row(i)
                        .iter()
                        .zip(&sent)
                        .fold(Rgb::ZERO, |acc, (fij, l)| acc + *fij * *l);
                    elements[i].emission + elements[i].reflectance * gathered
                })
                .collect();
            let change: f64 = new
                .iter()
                .zip(old)
                .zip(elements)
                .map(|((a, b), e)| e.area as f64 * luminance((*a - *b).abs()) as f64)
                .sum();
            s.radiance = new;
            change / emitted
        }
        MatrixSolver::GaussSeidel => {
            // What each element sends, updated as the sweep goes.
            let mut sent: Vec<Rgb> = (0..elements.len())
                .map(|j| s.exitant(j, &elements[j]))
                .collect();
            let mut change = 0.0;
            for i in 0..elements.len() {
                let gathered = f
                    .row(i)
                    .iter()
                    .zip(&sent)
                    .fold(Rgb::ZERO, |acc, (fij, l)| acc + *fij * *l);
                let new = elements[i].emission + elements[i].reflectance * gathered;
                change += elements[i].area as f64 * luminance((new - s.radiance[i]).abs()) as f64;
                s.radiance[i] = new;
                sent[i] = s.exitant(i, &elements[i]);
            }
            change / emitted
        }
        MatrixSolver::Progressive => {
            // Cohen et al.'s substructuring: a shot is a patch (a scene
            // triangle), all of its elements at once, received by elements.
            let patches = elements
                .iter()
                .map(|e| e.triangle as usize + 1)
                .max()
                .unwrap_or(0);
            let mut power = vec![0.0f32; patches];
            for ((e, u), x) in elements.iter().zip(&s.unshot).zip(&s.exposure) {
                power[e.triangle as usize] += e.area * x * luminance(*u);
            }
            let Some(patch) = (0..patches).max_by(|&a, &b| power[a].total_cmp(&power[b])) else {
                return 0.0;
            };
            for shooter in (0..elements.len()).filter(|&k| elements[k].triangle as usize == patch) {
                let shot = s.unshot[shooter];
                s.unshot[shooter] = Rgb::ZERO;
                // L_j += ρ_j F_ji ΔL_i.
                for (j, e) in elements.iter().enumerate() {
                    let fji = f.get(j, shooter);
                    if fji == 0.0 {
                        continue;
                    }
                    let received = e.reflectance * shot * fji;
                    s.radiance[j] += received;
                    s.unshot[j] += sent_radiance(received, Rgb::ZERO, s.exposure[j]);
                }
            }
            let unshot: f64 = elements
                .iter()
                .zip(&s.unshot)
                .zip(&s.exposure)
                .map(|((e, u), x)| e.area as f64 * *x as f64 * luminance(*u) as f64)
                .sum();
            s.ambient = if ambient {
                ambient_term(mesh, f, &s.unshot)
            } else {
                Rgb::ZERO
            };
            unshot / emitted
        }
    }
}

/// Cohen et al.'s ambient term: the area-weighted unshot radiance, times
/// the interreflection factor. Cohen's 1 / (1 - ρ_avg) assumes a closed
/// scene, where all unshot light lands on some surface; in an open one (the
/// Cornell box has no front wall) only the area-weighted mean form factor
/// row sum f of it does, at each bounce: f / (1 - ρ_avg f). f = 1 gives
/// Cohen's term.
fn ambient_term(mesh: &Mesh, f: &FormFactors, unshot: &[Rgb]) -> Rgb {
    let total: f32 = mesh.elements.iter().map(|e| e.area).sum();
    let mut rho = Rgb::ZERO;
    let mut mean_unshot = Rgb::ZERO;
    let mut enclosed = 0.0;
    for (i, (e, u)) in mesh.elements.iter().zip(unshot).enumerate() {
        rho += e.reflectance * e.area;
        mean_unshot += *u * e.area;
        enclosed += f.row_sum(i) * e.area;
    }
    let (rho, enclosed) = (rho / total, enclosed / total);
    mean_unshot / total * enclosed / (Rgb::ONE - rho * enclosed).max(Rgb::splat(1e-3))
}
