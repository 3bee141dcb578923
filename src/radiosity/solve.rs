//! The radiosity system L_i = E_i + ρ_i Σ_j F_ij L_j (in radiance: B = π L
//! for diffuse surfaces, so both sides divide by π) and its solvers:
//! Jacobi and Gauss–Seidel gathering, and progressive refinement by
//! shooting the element with the most unshot power (Southwell), with the
//! ambient term of Cohen et al. 1988 for display.

use super::form_factor::{FormFactorMethod, element_to_element};
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
}

impl RadiositySolver {
    pub const ALL: [RadiositySolver; 3] = [
        RadiositySolver::Jacobi,
        RadiositySolver::GaussSeidel,
        RadiositySolver::Progressive,
    ];

    pub fn name(self) -> &'static str {
        match self {
            RadiositySolver::Jacobi => "jacobi",
            RadiositySolver::GaussSeidel => "gauss-seidel",
            RadiositySolver::Progressive => "progressive",
        }
    }
}

/// The form factors of every element pair, row-major, with F_ji from F_ij by
/// reciprocity (A_i F_ij = A_j F_ji), so each pair is estimated once.
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
        let rows: Vec<(Vec<f32>, u64)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut row = vec![0.0f32; n - i];
                let mut rays = 0u64;
                for (k, j) in (i + 1..n).enumerate() {
                    let key = (i * n + j) as u32;
                    let (f, r) = element_to_element(
                        geometry,
                        &elements[i],
                        &elements[j],
                        method,
                        samples,
                        key,
                    );
                    row[k + 1] = f;
                    rays += r as u64;
                }
                (row, rays)
            })
            .collect();
        let mut values = vec![0.0f32; n * n];
        let mut rays = 0;
        for (i, (row, r)) in rows.into_iter().enumerate() {
            rays += r;
            for (k, f) in row.into_iter().enumerate().skip(1) {
                let j = i + k;
                values[i * n + j] = f;
                values[j * n + i] = f * elements[i].area / elements[j].area;
            }
        }
        FormFactors { n, values, rays }
    }

    /// F_ij.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f32 {
        self.values[i * self.n + j]
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
    /// Progressive refinement: radiance not yet shot.
    pub unshot: Vec<Rgb>,
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
            ambient: Rgb::ZERO,
            steps: 0,
        }
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
    solver: RadiositySolver,
    mesh: &Mesh,
    f: &FormFactors,
    s: &mut Solution,
    ambient: bool,
) -> f64 {
    let elements = &mesh.elements;
    let emitted = emitted_power(mesh).max(f64::MIN_POSITIVE);
    s.steps += 1;
    match solver {
        RadiositySolver::Jacobi => {
            let old = &s.radiance;
            let new: Vec<Rgb> = (0..elements.len())
                .into_par_iter()
                .map(|i| {
                    let gathered = f
                        .row(i)
                        .iter()
                        .zip(old)
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
        RadiositySolver::GaussSeidel => {
            let mut change = 0.0;
            for i in 0..elements.len() {
                let gathered = f
                    .row(i)
                    .iter()
                    .zip(&s.radiance)
                    .fold(Rgb::ZERO, |acc, (fij, l)| acc + *fij * *l);
                let new = elements[i].emission + elements[i].reflectance * gathered;
                change += elements[i].area as f64 * luminance((new - s.radiance[i]).abs()) as f64;
                s.radiance[i] = new;
            }
            change / emitted
        }
        RadiositySolver::Progressive => {
            let Some(shooter) = (0..elements.len()).max_by(|&a, &b| {
                let power = |k: usize| elements[k].area * luminance(s.unshot[k]);
                power(a).total_cmp(&power(b))
            }) else {
                return 0.0;
            };
            let shot = s.unshot[shooter];
            s.unshot[shooter] = Rgb::ZERO;
            let area = elements[shooter].area;
            // L_j += ρ_j F_ji ΔL_i, with F_ji = F_ij A_i / A_j.
            for (j, e) in elements.iter().enumerate() {
                let fij = f.get(shooter, j);
                if fij == 0.0 {
                    continue;
                }
                let received = e.reflectance * shot * (fij * area / e.area);
                s.radiance[j] += received;
                s.unshot[j] += received;
            }
            let unshot: f64 = elements
                .iter()
                .zip(&s.unshot)
                .map(|(e, u)| e.area as f64 * luminance(*u) as f64)
                .sum();
            s.ambient = if ambient {
                ambient_term(mesh, &s.unshot)
            } else {
                Rgb::ZERO
            };
            unshot / emitted
        }
    }
}

/// Cohen et al.'s ambient term: the area-weighted unshot radiance times
/// the interreflection factor 1 / (1 - ρ_avg), ρ_avg the area-weighted mean
/// reflectance.
fn ambient_term(mesh: &Mesh, unshot: &[Rgb]) -> Rgb {
    let total: f32 = mesh.elements.iter().map(|e| e.area).sum();
    let mut rho = Rgb::ZERO;
    let mut mean_unshot = Rgb::ZERO;
    for (e, u) in mesh.elements.iter().zip(unshot) {
        rho += e.reflectance * e.area;
        mean_unshot += *u * e.area;
    }
    let rho = rho / total;
    mean_unshot / total / (Rgb::ONE - rho).max(Rgb::splat(1e-3))
}
