//! Every sampling routine of the renderer against the pdf it claims (after
//! Nori's warptest): the warped points on their domain, the histogram of
//! many samples, the pdf integrated over the same cells, and Pearson's χ².
//! The routines are called here exactly as the renderer calls them: the
//! warps of [`crate::sampling::warp`], the lights' `sample` and
//! `sample_emission`, the dielectric's `sample`.

use super::report::{Cell, Check, Figure, Heatmap, Report, Series, SeriesStyle, Table};
use super::stats::{ChiSquare, PointSet, sidak};
use super::{Cancelled, LabSettings, Progress};
use crate::accel::{Geometry, TriangleInput};
use crate::math::{Ray, Rgb};
use crate::sampling::SamplerKind;
use crate::sampling::hash::hash_combine;
use crate::sampling::warp::*;
use crate::scene::light::{Light, LightSampling, Lights, PlanarEmitter};
use crate::scene::material::{Bsdf, fresnel_dielectric};
use glam::{Vec2, Vec3A};
use std::f64::consts::PI;

pub const TEXT: &str = "A warp turns uniform points in the unit square into points on a \
domain (hemisphere, disk, triangle, a light) and must know the density it produces: the \
renderer divides by it. Left: the first points, seen from above for directions. Middle: \
where 10^6 samples landed. Right: what the claimed pdf predicts for the same cells. \
Pearson's χ² compares the two; a p-value below the Šidák-corrected 1% level means the \
pdf is wrong (or the sampler is). The last row feeds cosine-weighted directions to the \
uniform pdf on purpose: it must fail, or the test could not catch anything.";

/// Significance for the whole family of tests below.
pub const ALPHA: f64 = 0.01;

/// The domain a routine's samples live on, and how it is cut into cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Directions: 20 cells in cos θ ∈ [−1, 1] × 40 in φ (dω = d cos θ dφ).
    Sphere,
    /// The unit disk: 10 cells in r² × 20 in φ (equal areas).
    Disk,
    /// The unit square of a shape's parameters (barycentrics, s and t): 16 × 16.
    Square,
}

impl Domain {
    /// (columns, rows): columns along φ or x.
    pub fn grid(self) -> (usize, usize) {
        match self {
            Domain::Sphere => (40, 20),
            Domain::Disk => (20, 10),
            Domain::Square => (16, 16),
        }
    }

    /// Whether the columns wrap around (φ).
    fn wraps(self) -> bool {
        !matches!(self, Domain::Square)
    }

    /// The cell of `p` (a direction, a disk point with z = 0, or (u, v, 0)),
    /// or None outside the domain.
    pub fn cell_of(self, p: Vec3A) -> Option<usize> {
        let (cols, rows) = self.grid();
        let (col, row) = match self {
            Domain::Sphere => {
                let phi = (p.y as f64).atan2(p.x as f64).rem_euclid(2.0 * PI);
                (phi / (2.0 * PI), (p.z.clamp(-1.0, 1.0) as f64 + 1.0) * 0.5)
            }
            Domain::Disk => {
                let r2 = (p.x * p.x + p.y * p.y) as f64;
                if r2 > 1.0 + 1e-6 {
                    return None;
                }
                let phi = (p.y as f64).atan2(p.x as f64).rem_euclid(2.0 * PI);
                (phi / (2.0 * PI), r2)
            }
            Domain::Square => {
                if !(-1e-6..=1.0 + 1e-6).contains(&p.x) || !(-1e-6..=1.0 + 1e-6).contains(&p.y) {
                    return None;
                }
                (p.x as f64, p.y as f64)
            }
        };
        let i = ((col * cols as f64) as usize).min(cols - 1);
        let j = ((row * rows as f64) as usize).min(rows - 1);
        Some(j * cols + i)
    }

    /// The point at fractions (a, b) of cell (i, j), and the cell's measure.
    fn cell_point(self, i: usize, j: usize, a: f64, b: f64) -> (Vec3A, f64) {
        let (cols, rows) = self.grid();
        let (col, row) = ((i as f64 + a) / cols as f64, (j as f64 + b) / rows as f64);
        match self {
            Domain::Sphere => {
                let (cos_theta, phi) = (-1.0 + 2.0 * row, 2.0 * PI * col);
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let w = Vec3A::new(
                    (sin_theta * phi.cos()) as f32,
                    (sin_theta * phi.sin()) as f32,
                    cos_theta as f32,
                );
                (w, 2.0 / rows as f64 * 2.0 * PI / cols as f64)
            }
            Domain::Disk => {
                let (r, phi) = (row.sqrt(), 2.0 * PI * col);
                let p = Vec3A::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, 0.0);
                // dA = r dr dφ = ½ d(r²) dφ.
                (p, 0.5 / rows as f64 * 2.0 * PI / cols as f64)
            }
            Domain::Square => (
                Vec3A::new(col as f32, row as f32, 0.0),
                1.0 / (rows * cols) as f64,
            ),
        }
    }
}

/// Observed and expected counts over a domain's cells.
#[derive(Clone, Debug)]
pub struct Histogram {
    pub domain: Domain,
    pub observed: Vec<f64>,
    pub expected: Vec<f64>,
    /// Samples outside the domain, non-finite, or (directions) not of unit length.
    pub invalid: u64,
}

impl Histogram {
    /// Counts `n` samples (None: the routine gave no sample, which the pdf
    /// must account for by integrating to less than 1) and integrates `pdf`
    /// over every cell by the midpoint rule on a 16 × 16 sub-grid, refined
    /// eightfold where the pdf is partly zero in a cell or next to one
    /// (a silhouette may clip a corner between sub-grid points).
    pub fn new(
        domain: Domain,
        n: u64,
        mut sample: impl FnMut(u64) -> Option<Vec3A>,
        pdf: impl Fn(Vec3A) -> f64,
    ) -> Histogram {
        let (cols, rows) = domain.grid();
        let mut observed = vec![0.0; cols * rows];
        let mut invalid = 0;
        for i in 0..n {
            let Some(p) = sample(i) else { continue };
            let unit = domain != Domain::Sphere || (p.length() - 1.0).abs() < 1e-4;
            match domain.cell_of(p) {
                Some(cell) if p.is_finite() && unit => observed[cell] += 1.0,
                _ => invalid += 1,
            }
        }
        let integrate = |i: usize, j: usize, sub: usize| -> (f64, bool) {
            let (mut sum, mut zeros, mut measure) = (0.0, 0usize, 0.0);
            for a in 0..sub {
                for b in 0..sub {
                    let (p, m) = domain.cell_point(
                        i,
                        j,
                        (a as f64 + 0.5) / sub as f64,
                        (b as f64 + 0.5) / sub as f64,
                    );
                    let value = pdf(p);
                    zeros += usize::from(value == 0.0);
                    sum += value;
                    measure = m;
                }
            }
            (
                sum * measure / (sub * sub) as f64,
                zeros > 0 && zeros < sub * sub,
            )
        };
        const SUB: usize = 16;
        let mut coarse = vec![0.0; cols * rows];
        let mut partial = vec![false; cols * rows];
        for j in 0..rows {
            for i in 0..cols {
                (coarse[j * cols + i], partial[j * cols + i]) = integrate(i, j, SUB);
            }
        }
        let covered = |i: isize, j: isize| -> bool {
            let i = if domain.wraps() {
                i.rem_euclid(cols as isize)
            } else {
                i
            };
            (0..rows as isize).contains(&j)
                && (0..cols as isize).contains(&i)
                && coarse[j as usize * cols + i as usize] > 0.0
        };
        let mut expected = coarse.clone();
        for j in 0..rows {
            for i in 0..cols {
                let k = j * cols + i;
                let (ii, jj) = (i as isize, j as isize);
                let near = (-1..=1).any(|di| (-1..=1).any(|dj| covered(ii + di, jj + dj)));
                if partial[k] || (coarse[k] == 0.0 && near) {
                    expected[k] = integrate(i, j, 8 * SUB).0;
                }
            }
        }
        for e in &mut expected {
            *e *= n as f64;
        }
        Histogram {
            domain,
            observed,
            expected,
            invalid,
        }
    }

    /// Pearson's test of the histogram.
    pub fn chi_square(&self) -> ChiSquare {
        ChiSquare::test(&self.observed, &self.expected)
    }
}

/// The routines the lab tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Warp {
    UniformHemisphere,
    CosineHemisphere,
    PhongLobe,
    UniformSphere,
    SphereCone,
    ConcentricDisk,
    SphericalTriangle,
    TriangleByArea,
    ParallelogramByArea,
    /// Cosine samples judged by the uniform hemisphere's pdf: must fail.
    WrongPdf,
}

/// Phong exponent and cone aperture of the tests.
const PHONG_EXPONENT: f32 = 12.0;
const CONE_COS_MAX: f32 = 0.8;

impl Warp {
    pub const ALL: [Warp; 10] = [
        Warp::UniformHemisphere,
        Warp::CosineHemisphere,
        Warp::PhongLobe,
        Warp::UniformSphere,
        Warp::SphereCone,
        Warp::ConcentricDisk,
        Warp::SphericalTriangle,
        Warp::TriangleByArea,
        Warp::ParallelogramByArea,
        Warp::WrongPdf,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Warp::UniformHemisphere => "uniform hemisphere (square_to_uniform_cone, cos_max 0)",
            Warp::CosineHemisphere => "cosine hemisphere (square_to_cosine_hemisphere)",
            Warp::PhongLobe => "Phong lobe n = 12 (square_to_phong_lobe)",
            Warp::UniformSphere => "uniform sphere (square_to_uniform_sphere)",
            Warp::SphereCone => "sphere cone cos_max 0.8 (square_to_uniform_cone)",
            Warp::ConcentricDisk => "concentric disk (square_to_concentric_disk)",
            Warp::SphericalTriangle => "spherical triangle (triangle light, solid angle)",
            Warp::TriangleByArea => "triangle by area (triangle light emission)",
            Warp::ParallelogramByArea => "parallelogram by area (quad light emission)",
            Warp::WrongPdf => "WRONG on purpose: cosine samples, uniform pdf",
        }
    }

    pub fn domain(self) -> Domain {
        match self {
            Warp::ConcentricDisk => Domain::Disk,
            Warp::TriangleByArea | Warp::ParallelogramByArea => Domain::Square,
            _ => Domain::Sphere,
        }
    }

    /// The sample for uniform numbers `u` (a direction, a disk point or the
    /// shape's parameters), by the renderer's own routine.
    pub fn sample(self, scenes: &Fixtures, u: Vec2) -> Option<Vec3A> {
        match self {
            Warp::UniformHemisphere => Some(square_to_uniform_cone(u, 0.0)),
            Warp::CosineHemisphere | Warp::WrongPdf => Some(square_to_cosine_hemisphere(u)),
            Warp::PhongLobe => Some(square_to_phong_lobe(u, PHONG_EXPONENT)),
            Warp::UniformSphere => Some(square_to_uniform_sphere(u)),
            Warp::SphereCone => Some(square_to_uniform_cone(u, CONE_COS_MAX)),
            Warp::ConcentricDisk => Some(square_to_concentric_disk(u).extend(0.0).into()),
            Warp::SphericalTriangle => {
                Some(scenes.solid_angle.sample(scenes.reference, 0.0, u)?.wi)
            }
            Warp::TriangleByArea => {
                let s = scenes.triangle.sample_emission(0.0, u, Vec2::splat(0.5))?;
                Some(scenes.parameters(s.point))
            }
            Warp::ParallelogramByArea => {
                let s = scenes
                    .parallelogram
                    .sample_emission(0.0, u, Vec2::splat(0.5))?;
                Some(scenes.parameters(s.point))
            }
        }
    }

    /// The density the routine claims at `p`, on its domain's measure.
    pub fn pdf(self, scenes: &Fixtures, p: Vec3A) -> f64 {
        match self {
            Warp::UniformHemisphere | Warp::WrongPdf => {
                if p.z >= 0.0 {
                    uniform_cone_pdf(0.0) as f64
                } else {
                    0.0
                }
            }
            Warp::CosineHemisphere => cosine_hemisphere_pdf(p) as f64,
            Warp::PhongLobe => phong_lobe_pdf(p.z, PHONG_EXPONENT) as f64,
            Warp::UniformSphere => UNIFORM_SPHERE_PDF as f64,
            Warp::SphereCone => {
                if p.z >= CONE_COS_MAX {
                    uniform_cone_pdf(CONE_COS_MAX) as f64
                } else {
                    0.0
                }
            }
            Warp::ConcentricDisk => {
                if p.x * p.x + p.y * p.y <= 1.0 {
                    1.0 / PI
                } else {
                    0.0
                }
            }
            Warp::SphericalTriangle => {
                let ray = Ray::new(scenes.reference, p.normalize());
                match scenes.geometry.intersect(&ray) {
                    Some(hit) => scenes
                        .solid_angle
                        .pdf(0, scenes.reference, hit.point, hit.normal)
                        as f64,
                    None => 0.0,
                }
            }
            Warp::TriangleByArea | Warp::ParallelogramByArea => {
                let triangle = self == Warp::TriangleByArea;
                if p.x < 0.0 || p.y < 0.0 || (triangle && p.x + p.y > 1.0) {
                    return 0.0;
                }
                // The light's density by area (1 / area), times the area of
                // the parameter square: density in (s, t).
                let lights = if triangle {
                    &scenes.triangle
                } else {
                    &scenes.parallelogram
                };
                let s = lights.sample_emission(0.0, Vec2::splat(0.25), Vec2::splat(0.5));
                s.map_or(0.0, |s| {
                    s.pdf_position as f64 * scenes.e1.cross(scenes.e2).length() as f64
                })
            }
        }
    }
}

/// The lights and geometry the light-sampling routines are tested on.
pub struct Fixtures {
    pub reference: Vec3A,
    pub solid_angle: Lights,
    pub geometry: Geometry,
    pub triangle: Lights,
    pub parallelogram: Lights,
    p0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

impl Fixtures {
    /// A tilted emitter above a point below it, as a triangle and as a parallelogram.
    pub fn new() -> Fixtures {
        let p0 = Vec3A::new(-1.0, -1.5, 0.8);
        let (e1, e2) = (Vec3A::new(2.5, 0.5, 0.4), Vec3A::new(0.3, 2.5, -0.3));
        let emitter = |area: f32, sampling| PlanarEmitter {
            p0,
            e1,
            e2,
            normal: Vec3A::new(0.0, 0.0, -1.0).dot(e1.cross(e2)).signum()
                * e1.cross(e2).normalize(),
            area,
            radiance: Rgb::ONE,
            two_sided: false,
            sampling,
        };
        let area = e1.cross(e2).length();
        let triangle = [p0, p0 + e1, p0 + e2];
        Fixtures {
            reference: Vec3A::new(0.2, -0.1, 0.0),
            solid_angle: Lights::new(vec![Light::Triangle(emitter(
                0.5 * area,
                LightSampling::SolidAngle,
            ))]),
            geometry: Geometry::build(
                &[TriangleInput {
                    vertices: triangle,
                    material: 0,
                    uvs: None,
                    normals: None,
                }],
                vec![],
            ),
            triangle: Lights::new(vec![Light::Triangle(emitter(
                0.5 * area,
                LightSampling::Area,
            ))]),
            parallelogram: Lights::new(vec![Light::Parallelogram(emitter(
                area,
                LightSampling::Area,
            ))]),
            p0,
            e1,
            e2,
        }
    }

    /// (s, t) with `point = p0 + s e1 + t e2`, by the normal equations.
    fn parameters(&self, point: Vec3A) -> Vec3A {
        let d = point - self.p0;
        let (a, b, c) = (
            self.e1.dot(self.e1),
            self.e1.dot(self.e2),
            self.e2.dot(self.e2),
        );
        let (r1, r2) = (d.dot(self.e1), d.dot(self.e2));
        let det = a * c - b * b;
        Vec3A::new((r1 * c - r2 * b) / det, (a * r2 - b * r1) / det, 0.0)
    }
}

impl Default for Fixtures {
    fn default() -> Self {
        Fixtures::new()
    }
}

/// Incidence cosines of the dielectric test, from outside and from inside
/// (the last two beyond the critical angle: total internal reflection).
const DIELECTRIC_COSINES: [f32; 9] = [1.0, 0.9, 0.7, 0.5, 0.3, 0.1, -0.95, -0.8, -0.5];
const DIELECTRIC_ETA: f32 = 1.5;

/// `settings.n` samples per routine (independent numbers).
pub fn run(settings: &LabSettings, progress: &Progress) -> Result<Report, Cancelled> {
    let n = settings.n.max(1000);
    let fixtures = Fixtures::new();
    let stages = Warp::ALL.len() as u32 + 1;
    progress.plan(n as u64 * stages as u64);
    // Every routine except the deliberate failure, plus the dielectric.
    let tests = Warp::ALL.len() - 1 + 1;
    let alpha = sidak(ALPHA, tests);
    let mut table = Table {
        title: format!(
            "Chi-square tests, {n} samples each, significance {alpha:.2e} per test (1% Sidak-corrected for {tests} tests)"
        ),
        columns: [
            "routine", "cells", "dof", "chi2", "p-value", "stray", "result",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let mut report = Report {
        stages_planned: stages,
        ..Report::default()
    };
    for (k, warp) in Warp::ALL.into_iter().enumerate() {
        let mut set = PointSet::new(
            SamplerKind::Independent,
            hash_combine(settings.seed, k as u64),
            0,
            n,
        );
        let histogram = Histogram::new(
            warp.domain(),
            n as u64,
            |i| {
                if i % 65_536 == 0 {
                    // Cancelling stops counting; the partial histogram is dropped below.
                    let _ = progress.advance(65_536.min(n as u64 - i));
                }
                warp.sample(&fixtures, set.point_2d(i as u32))
            },
            |p| warp.pdf(&fixtures, p),
        );
        progress.check()?;
        let test = histogram.chi_square();
        let passes = test.passes(alpha) && histogram.invalid == 0;
        table.rows.push(vec![
            Cell::text(warp.name()),
            Cell::int(histogram.observed.len() as u64),
            Cell::int(test.dof as u64),
            Cell::fixed(test.chi2, 1),
            Cell::sci(test.p_value),
            Cell::int(test.stray as u64 + histogram.invalid),
            Cell::text(if passes { "pass" } else { "FAIL" }),
        ]);
        report.checks.push(if warp == Warp::WrongPdf {
            Check {
                statement: "the deliberately wrong pdf is rejected".into(),
                measured: format!("p = {:.2e}", test.p_value),
                holds: !passes,
            }
        } else {
            Check {
                statement: format!("{} passes chi2", warp.name()),
                measured: format!(
                    "chi2 {:.1}, dof {}, p = {:.4}",
                    test.chi2, test.dof, test.p_value
                ),
                holds: passes,
            }
        });
        report
            .figures
            .extend(figures(warp, &fixtures, &histogram, settings.seed));
        report.stages_done += 1;
        report.tables = vec![table.clone()];
        progress.publish(&report);
    }
    let (test, figure) = dielectric(settings.seed, n, progress)?;
    let passes = test.passes(alpha);
    table.rows.push(vec![
        Cell::text("dielectric reflect/refract choice (Bsdf::Dielectric, eta 1.5)"),
        Cell::int(2 * DIELECTRIC_COSINES.len() as u64),
        Cell::int(test.dof as u64),
        Cell::fixed(test.chi2, 1),
        Cell::sci(test.p_value),
        Cell::int(test.stray as u64),
        Cell::text(if passes { "pass" } else { "FAIL" }),
    ]);
    report.checks.push(Check {
        statement: "the dielectric chooses reflection with the Fresnel probability (chi2)".into(),
        measured: format!(
            "chi2 {:.1}, dof {}, p = {:.4}",
            test.chi2, test.dof, test.p_value
        ),
        holds: passes,
    });
    report.figures.push(figure);
    report.stages_done += 1;
    report.tables = vec![table];
    Ok(report)
}

/// Reflections counted at each incidence angle against n·F (Fresnel).
fn dielectric(seed: u64, n: u32, progress: &Progress) -> Result<(ChiSquare, Figure), Cancelled> {
    let bsdf = Bsdf::Dielectric {
        eta: DIELECTRIC_ETA,
        tint: Rgb::ONE,
    };
    let per_angle = n / DIELECTRIC_COSINES.len() as u32;
    let (mut observed, mut expected) = (Vec::new(), Vec::new());
    let mut measured_curve = Vec::new();
    for (k, &cos_o) in DIELECTRIC_COSINES.iter().enumerate() {
        let wo = Vec3A::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
        let f = fresnel_dielectric(cos_o, DIELECTRIC_ETA).reflectance as f64;
        let mut set = PointSet::new(
            SamplerKind::Independent,
            hash_combine(seed, 1000 + k as u64),
            0,
            per_angle,
        );
        let mut reflected = 0.0;
        for i in 0..per_angle {
            let u = set.point_2d(i);
            if let Some(s) = bsdf.sample(wo, u.x, u)
                && s.wi.z * wo.z > 0.0
            {
                reflected += 1.0;
            }
        }
        progress.advance(per_angle as u64)?;
        observed.extend([reflected, per_angle as f64 - reflected]);
        expected.extend([f * per_angle as f64, (1.0 - f) * per_angle as f64]);
        measured_curve.push((cos_o as f64, reflected / per_angle as f64));
    }
    let fresnel: Vec<(f64, f64)> = (0..=200)
        .map(|i| {
            let c = -1.0 + i as f64 / 100.0;
            (
                c,
                fresnel_dielectric(c as f32, DIELECTRIC_ETA).reflectance as f64,
            )
        })
        .collect();
    let figure = Figure::linear(
        "Dielectric: fraction of reflections against cos theta (eta 1.5)",
        ("cos theta of the incident direction", "reflected fraction"),
        (-1.0, 1.0),
        (0.0, 1.0),
        vec![
            Series::new("Fresnel reflectance", SeriesStyle::Guide, 7, &fresnel),
            Series::new("measured", SeriesStyle::Points, 3, &measured_curve),
        ],
    );
    Ok((ChiSquare::test(&observed, &expected), figure))
}

/// The warped points, the histogram and the integrated pdf of one routine.
fn figures(warp: Warp, fixtures: &Fixtures, histogram: &Histogram, seed: u64) -> [Figure; 3] {
    let shown = 1024;
    let mut set = PointSet::new(SamplerKind::Stratified, seed, 0, shown);
    let points: Vec<(f64, f64)> = (0..shown)
        .filter_map(|i| warp.sample(fixtures, set.point_2d(i)))
        .map(|p| (p.x as f64, p.y as f64))
        .collect();
    let (cols, rows) = warp.domain().grid();
    let range = match warp.domain() {
        Domain::Square => (0.0, 1.0),
        _ => (-1.0, 1.0),
    };
    let (x_label, y_label) = match warp.domain() {
        Domain::Sphere => ("x (seen from +z)", "y"),
        Domain::Disk => ("x", "y"),
        Domain::Square => ("s (first parameter)", "t"),
    };
    let scale = histogram
        .expected
        .iter()
        .chain(&histogram.observed)
        .fold(0.0f64, |m, v| m.max(*v));
    let heat = |values: &[f64]| Heatmap {
        width: cols,
        height: rows,
        values: values.iter().map(|v| v / scale.max(1e-300)).collect(),
    };
    let (hx, hy) = match warp.domain() {
        Domain::Sphere => ("phi / 2pi", "(cos theta + 1) / 2"),
        Domain::Disk => ("phi / 2pi", "r^2"),
        Domain::Square => ("s", "t"),
    };
    let map = |title: String, values: &[f64]| Figure {
        heatmap: Some(heat(values)),
        ..Figure::linear(title, (hx, hy), (0.0, 1.0), (0.0, 1.0), vec![])
    };
    let name = warp.name();
    [
        Figure::linear(
            format!("{name}: {} stratified points", points.len()),
            (x_label, y_label),
            range,
            range,
            vec![Series::new("samples", SeriesStyle::Points, 0, &points)],
        ),
        map(format!("{name}: histogram"), &histogram.observed),
        map(format!("{name}: integrated pdf"), &histogram.expected),
    ]
}
