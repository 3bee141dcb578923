//! Chi-square goodness-of-fit tests of every sampling routine against the pdf
//! it claims (after Nori's `chi2test` and Mitsuba's `ChiSquare`).
//!
//! Directions are histogrammed over the whole sphere in (cos theta, phi)
//! cells; expected counts integrate the claimed pdf over each cell (dω =
//! d cos theta d phi) with a fine midpoint rule. Cells expecting fewer than 5
//! samples are pooled. The null hypothesis "samples follow the pdf" is
//! rejected at significance 1%, Šidák-corrected for the number of tests in
//! this file and `chi2_rough.rs`, so a correct sampler fails with probability < 1% overall
//! (and, with fixed seeds, deterministically passes once it passes).

use glam::{Vec2, Vec3A};
use std::f64::consts::PI;
use tracelab::accel::{Geometry, NO_LIGHT, TriangleInput};
use tracelab::lab::stats::{ChiSquare, gamma_q, sidak};
use tracelab::lab::warps::{Domain, Histogram};
use tracelab::math::{Frame, Rgb};
use tracelab::sampling::hash::{hash_combine, to_unit_float};
use tracelab::sampling::warp::*;
use tracelab::scene::light::{Light, LightSampling, Lights, PlanarEmitter};
use tracelab::scene::material::{Bsdf, fresnel_dielectric};

/// Number of `assert_fits` calls here and in `chi2_rough.rs` (the
/// significance is split over them).
const TESTS_IN_FILE: f64 = 70.0;
pub(crate) const SAMPLES: u64 = 500_000;

/// Uniform numbers for test `seed`, sample `i`.
pub(crate) fn uniform(seed: u64, i: u64, dim: u64) -> f32 {
    to_unit_float(hash_combine(hash_combine(seed, i), dim))
}

/// Chi-square test of observed against expected counts (the lab's, which
/// pools cells expecting fewer than 5 samples).
pub(crate) fn assert_fits(name: &str, observed: &[f64], expected: &[f64]) {
    let test = ChiSquare::test(observed, expected);
    let alpha = sidak(0.01, TESTS_IN_FILE as usize);
    eprintln!(
        "{name}: chi2 {:.1}, dof {}, p {:.4}",
        test.chi2, test.dof, test.p_value
    );
    assert!(
        test.passes(alpha),
        "{name}: chi2 = {:.1} with {} dof, p = {:.2e} < {alpha:.2e}, {} samples where {:.2} expected",
        test.chi2,
        test.dof,
        test.p_value,
        test.stray,
        test.stray_expected
    );
}

/// Histograms `SAMPLES` directions from `sample` (None = sample lost) and
/// compares them with `pdf` (solid angle) integrated over each cell, as
/// `tracelab lab warps` does.
pub(crate) fn check_directions(
    name: &str,
    sample: impl FnMut(u64) -> Option<Vec3A>,
    pdf: impl Fn(Vec3A) -> f64,
) {
    let histogram = Histogram::new(Domain::Sphere, SAMPLES, sample, pdf);
    assert_eq!(
        histogram.invalid, 0,
        "{name}: directions not of unit length"
    );
    assert_fits(name, &histogram.observed, &histogram.expected);
}

#[test]
fn cosine_hemisphere() {
    check_directions(
        "cosine hemisphere",
        |i| {
            Some(square_to_cosine_hemisphere(Vec2::new(
                uniform(1, i, 0),
                uniform(1, i, 1),
            )))
        },
        |w| cosine_hemisphere_pdf(w) as f64,
    );
}

#[test]
fn phong_lobe() {
    let exponent = 12.0;
    check_directions(
        "phong lobe n=12",
        |i| {
            Some(square_to_phong_lobe(
                Vec2::new(uniform(2, i, 0), uniform(2, i, 1)),
                exponent,
            ))
        },
        |w| phong_lobe_pdf(w.z, exponent) as f64,
    );
}

#[test]
fn uniform_cone() {
    check_directions(
        "uniform cone cos_max=0.8",
        |i| {
            Some(square_to_uniform_cone(
                Vec2::new(uniform(3, i, 0), uniform(3, i, 1)),
                0.8,
            ))
        },
        |w| {
            if w.z >= 0.8 {
                uniform_cone_pdf(0.8) as f64
            } else {
                0.0
            }
        },
    );
}

fn check_bsdf(name: &str, bsdf: Bsdf, wo: Vec3A, seed: u64) {
    check_bsdf_events(name, bsdf, wo, seed);
}

#[test]
fn diffuse_bsdf_from_both_sides() {
    let bsdf = Bsdf::Diffuse {
        albedo: Rgb::splat(0.5),
    };
    check_bsdf(
        "diffuse, wo above",
        bsdf,
        Vec3A::new(0.3, 0.2, 0.9).normalize(),
        4,
    );
    check_bsdf(
        "diffuse, wo below",
        bsdf,
        Vec3A::new(0.3, 0.2, -0.9).normalize(),
        5,
    );
}

#[test]
fn glossy_bsdf() {
    let bsdf = Bsdf::glossy(Rgb::splat(0.3), Rgb::splat(0.6), 20.0);
    check_bsdf(
        "glossy n=20 at 40 deg",
        bsdf,
        Vec3A::new(40f32.to_radians().sin(), 0.0, 40f32.to_radians().cos()),
        6,
    );
    check_bsdf(
        "glossy n=20 at 80 deg",
        bsdf,
        Vec3A::new(80f32.to_radians().sin(), 0.0, 80f32.to_radians().cos()),
        7,
    );
}

/// Light sampling from `reference` (directions of the sampled points) against
/// the density `Lights::pdf` gives the point each direction hits on the light.
fn check_light(name: &str, seed: u64, reference: Vec3A, lights: &Lights, geometry: &Geometry) {
    check_directions(
        name,
        |i| {
            let u = Vec2::new(uniform(seed, i, 1), uniform(seed, i, 2));
            Some(lights.sample(reference, uniform(seed, i, 0), u)?.wi)
        },
        |w| match geometry.intersect(&tracelab::math::Ray::new(reference, w.normalize())) {
            Some(hit) => lights.pdf(0, reference, hit.point, hit.normal) as f64,
            None => 0.0,
        },
    );
}

/// Where the light tests look from: below the emitters of the two helpers.
const LIGHT_TEST_REFERENCE: Vec3A = Vec3A::new(0.2, -0.1, 0.0);

/// A flat emitter of radiance 1 spanned by `e1`, `e2` from `p0`, facing down
/// towards [`LIGHT_TEST_REFERENCE`], with area `fraction` |e1 x e2|; and the
/// geometry of `triangles`, to find where a direction lands on it.
fn emitter_above(
    p0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    fraction: f32,
    sampling: LightSampling,
    triangles: &[[Vec3A; 3]],
) -> (PlanarEmitter, Geometry) {
    let facing = e1.cross(e2).normalize();
    let emitter = PlanarEmitter {
        p0,
        e1,
        e2,
        normal: -facing * facing.z.signum(),
        area: fraction * e1.cross(e2).length(),
        radiance: Rgb::ONE,
        two_sided: false,
        sampling,
    };
    let inputs: Vec<TriangleInput> = triangles
        .iter()
        .map(|&vertices| TriangleInput {
            vertices,
            material: 0,
            uvs: None,
            normals: None,
        })
        .collect();
    (emitter, Geometry::build(&inputs, vec![]))
}

/// A reference point, a big emissive triangle above it, and the lights and
/// geometry to find where a direction lands on it.
fn triangle_light(sampling: LightSampling) -> (Vec3A, Lights, Geometry) {
    let [p0, p1, p2] = [
        Vec3A::new(-1.0, -1.5, 0.8),
        Vec3A::new(1.5, -0.5, 1.2),
        Vec3A::new(-0.5, 1.5, 0.5),
    ];
    let (emitter, geometry) = emitter_above(p0, p1 - p0, p2 - p0, 0.5, sampling, &[[p0, p1, p2]]);
    let lights = Lights::new(vec![Light::Triangle(emitter)]);
    (LIGHT_TEST_REFERENCE, lights, geometry)
}

#[test]
fn triangle_light_area_sampling_in_solid_angle() {
    let (reference, lights, geometry) = triangle_light(LightSampling::Area);
    check_light("triangle light", 8, reference, &lights, &geometry);
}

#[test]
fn triangle_light_spherical_triangle_sampling() {
    // Arvo's sampling: the density must be constant, 1 / solid angle.
    let (reference, lights, geometry) = triangle_light(LightSampling::SolidAngle);
    check_light(
        "triangle light, solid angle",
        12,
        reference,
        &lights,
        &geometry,
    );
    // A small far triangle (solid angle below the f32-safe range) falls back
    // to area sampling consistently in sample and pdf.
    let far = reference + Vec3A::new(0.0, 0.0, 300.0);
    let (_, lights, _) = triangle_light(LightSampling::SolidAngle);
    let s = lights.sample(far, 0.5, Vec2::new(0.3, 0.3));
    if let Some(s) = s {
        let pdf = lights.pdf(0, far, s.point, s.normal);
        assert!((pdf - s.pdf).abs() <= 1e-3 * pdf, "{pdf} vs {}", s.pdf);
    }
}

/// A reference point and a big emissive parallelogram above it, as two
/// triangles for the geometry and one light.
fn parallelogram_light(sampling: LightSampling) -> (Vec3A, Lights, Geometry) {
    let p0 = Vec3A::new(-1.0, -1.5, 0.8);
    let (e1, e2) = (Vec3A::new(2.5, 0.5, 0.2), Vec3A::new(0.3, 2.5, -0.4));
    let corner = p0 + e1 + e2;
    let halves = [[p0, p0 + e1, p0 + e2], [corner, p0 + e2, p0 + e1]];
    let (emitter, geometry) = emitter_above(p0, e1, e2, 1.0, sampling, &halves);
    let lights = Lights::new(vec![Light::Parallelogram(emitter)]);
    (LIGHT_TEST_REFERENCE, lights, geometry)
}

#[test]
fn parallelogram_light_area_sampling_in_solid_angle() {
    let (reference, lights, geometry) = parallelogram_light(LightSampling::Area);
    check_light("parallelogram light", 14, reference, &lights, &geometry);
}

#[test]
fn parallelogram_light_solid_angle_sampling() {
    // A half chosen by its share of the solid angle, then Arvo's sampling
    // in it: the density must be constant, 1 / (both halves' solid angle).
    let (reference, lights, geometry) = parallelogram_light(LightSampling::SolidAngle);
    check_light(
        "parallelogram light, solid angle",
        16,
        reference,
        &lights,
        &geometry,
    );
}

#[test]
fn triangle_light_points_are_uniform_by_area() {
    // Barycentric histogram: each of 10x10 cells of the (b1, b2) square
    // below the diagonal gets samples in proportion to its area in the triangle.
    let n = 400_000u64;
    let cells = 10;
    let mut observed = vec![0.0; cells * cells];
    for i in 0..n {
        let b = square_to_uniform_triangle(Vec2::new(uniform(9, i, 0), uniform(9, i, 1)));
        assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
        let (x, y) = (
            ((b.x * cells as f32) as usize).min(cells - 1),
            ((b.y * cells as f32) as usize).min(cells - 1),
        );
        observed[y * cells + x] += 1.0;
    }
    // Area of cell (x, y) inside b1 + b2 <= 1: full, half (on the diagonal) or none.
    let h = 1.0 / cells as f64;
    let expected: Vec<f64> = (0..cells * cells)
        .map(|k| {
            let (x, y) = (k % cells, k / cells);
            let area = if x + y + 1 < cells {
                h * h
            } else if x + y + 1 == cells {
                h * h / 2.0
            } else {
                0.0
            };
            area * 2.0 * n as f64
        })
        .collect();
    assert_fits("triangle barycentrics", &observed, &expected);
}

#[test]
fn sphere_light_solid_angle_sampling() {
    // Seen from the origin, the sphere subtends the cone cos theta >= 0.825,
    // whose rim crosses the middle of a row of cells.
    let reference = Vec3A::ZERO;
    let center = Vec3A::new(0.0, 0.0, 1.0);
    let radius = (1.0f32 - 0.825 * 0.825).sqrt();
    let (sampling, seed) = (LightSampling::SolidAngle, 10);
    let lights = Lights::new(vec![Light::Sphere {
        center,
        radius,
        radiance: Rgb::ONE,
        two_sided: false,
        sampling,
    }]);
    let geometry = Geometry::build(
        &[],
        vec![tracelab::accel::Sphere {
            center,
            radius,
            material: 0,
            light: NO_LIGHT,
        }],
    );
    check_light(
        "sphere light, solid angle",
        seed,
        reference,
        &lights,
        &geometry,
    );
}

#[test]
fn sphere_light_area_sampling_is_uniform_over_the_sphere() {
    // Area sampling picks the normal (and so the point) uniformly on the
    // sphere; its conversion to solid angle, d^2 / (|cos| A), is the one the
    // triangle test above checks, and the sphere furnace (area sampling from
    // inside) checks it for spheres. In solid angle its density diverges at
    // the silhouette, where a cell integral cannot be computed accurately.
    check_directions(
        "uniform sphere",
        |i| {
            Some(square_to_uniform_sphere(Vec2::new(
                uniform(11, i, 0),
                uniform(11, i, 1),
            )))
        },
        |_| UNIFORM_SPHERE_PDF as f64,
    );
}

#[test]
fn dielectric_chooses_reflection_with_fresnel_probability() {
    // Discrete two-outcome test per incidence angle, from outside and inside.
    let bsdf = Bsdf::Dielectric {
        eta: 1.5,
        tint: Rgb::ONE,
    };
    let n = 200_000u64;
    let mut observed = Vec::new();
    let mut expected = Vec::new();
    for (k, cos_o) in [0.95f32, 0.7, 0.3, 0.1, -0.95, -0.8]
        .into_iter()
        .enumerate()
    {
        let sin_o = (1.0 - cos_o * cos_o).sqrt();
        let wo = Vec3A::new(sin_o, 0.0, cos_o);
        let f = fresnel_dielectric(cos_o, 1.5).reflectance as f64;
        let mut reflected = 0.0;
        for i in 0..n {
            let s = bsdf
                .sample(wo, uniform(12 + k as u64, i, 0), Vec2::ZERO)
                .unwrap();
            assert!(s.specular);
            if s.wi.z * wo.z > 0.0 {
                reflected += 1.0;
            }
        }
        observed.extend([reflected, n as f64 - reflected]);
        expected.extend([f * n as f64, (1.0 - f) * n as f64]);
    }
    assert_fits("dielectric reflect/refract", &observed, &expected);
    // And the directions themselves obey the law of reflection and Snell's law.
    let frame = Frame::from_normal(Vec3A::Z);
    let wo = frame.to_local(Vec3A::new(0.5, 0.1, 0.7).normalize());
    let reflected = bsdf.sample(wo, 0.0, Vec2::ZERO).unwrap().wi;
    assert!((reflected - Vec3A::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
}

#[test]
fn chi_square_survival_function_is_right() {
    // Known values: Q(1, 1) = e^-1; chi2 with 10 dof at 18.307 has p = 0.05.
    assert!((gamma_q(1.0, 1.0) - (-1.0f64).exp()).abs() < 1e-10);
    assert!((gamma_q(5.0, 18.307 / 2.0) - 0.05).abs() < 1e-4);
    assert!((gamma_q(50.0, 40.0) - 0.929_665).abs() < 1e-5);
}

#[test]
fn thin_lens_points_are_uniform_over_the_aperture() {
    // Ray origins of a thin-lens camera, in units of the aperture radius on
    // the lens plane, histogrammed in rings and sectors: a uniform disk puts
    // (r2^2 - r1^2) / sectors of the samples in each cell.
    use tracelab::camera::Camera;
    let radius = 0.25;
    let camera = Camera::look_at(
        Vec3A::new(0.3, -0.2, 5.0),
        Vec3A::ZERO,
        Vec3A::Y,
        40.0,
        64,
        64,
        radius,
        5.0,
    );
    let (rings, sectors) = (10, 16);
    let mut observed = vec![0.0; rings * sectors];
    for i in 0..SAMPLES {
        let film = Vec2::new(uniform(14, i, 0) * 64.0, uniform(14, i, 1) * 64.0);
        let lens = Vec2::new(uniform(14, i, 2), uniform(14, i, 3));
        let ray = camera.generate_ray(film, lens);
        let offset = ray.origin - camera.eye;
        let (x, y) = (
            offset.dot(camera.right) / radius,
            offset.dot(camera.up) / radius,
        );
        let r = (x * x + y * y).sqrt();
        assert!(r <= 1.0 + 1e-5, "lens point outside the aperture: {r}");
        let ring = ((r * rings as f32) as usize).min(rings - 1);
        let phi = (y.atan2(x) as f64 + 2.0 * PI) % (2.0 * PI);
        let sector = ((phi / (2.0 * PI) * sectors as f64) as usize).min(sectors - 1);
        observed[ring * sectors + sector] += 1.0;
    }
    let expected: Vec<f64> = (0..rings * sectors)
        .map(|k| {
            let ring = (k / sectors) as f64 / rings as f64;
            let next = ring + 1.0 / rings as f64;
            (next * next - ring * ring) / sectors as f64 * SAMPLES as f64
        })
        .collect();
    assert_fits("thin lens aperture", &observed, &expected);
}

#[test]
fn every_sampler_is_uniform_in_1d_and_2d_projections() {
    // Numbers from many pixels and samples, in a 1D dimension and a 2D pair
    // deep in the path: each sampler must be uniform there (stratified ones
    // fit better than chance, which the upper-tail test accepts).
    use tracelab::sampling::{Sampler, SamplerKind};
    for kind in SamplerKind::ALL {
        let spp = 16;
        let mut sampler = Sampler::new(kind, 5, spp);
        let bins_1d = 64;
        let bins_2d = 16;
        let mut observed_1d = vec![0.0; bins_1d];
        let mut observed_2d = vec![0.0; bins_2d * bins_2d];
        // Two different dimensions must be independent of each other.
        let mut observed_cross = vec![0.0; bins_2d * bins_2d];
        let pixels = 8192;
        for pixel in 0..pixels {
            for s in 0..spp {
                sampler.start(pixel, s);
                for _ in 0..3 {
                    sampler.next_2d();
                }
                let u = sampler.next_1d();
                let p = sampler.next_2d();
                let w = sampler.next_1d();
                let bin = |v: f32| ((v * bins_2d as f32) as usize).min(bins_2d - 1);
                observed_cross[bin(w) * bins_2d + bin(u)] += 1.0;
                observed_1d[((u * bins_1d as f32) as usize).min(bins_1d - 1)] += 1.0;
                let (x, y) = (
                    ((p.x * bins_2d as f32) as usize).min(bins_2d - 1),
                    ((p.y * bins_2d as f32) as usize).min(bins_2d - 1),
                );
                observed_2d[y * bins_2d + x] += 1.0;
            }
        }
        let n = f64::from(pixels * spp);
        assert_fits(
            &format!("{kind:?} sampler, 1D"),
            &observed_1d,
            &vec![n / bins_1d as f64; bins_1d],
        );
        assert_fits(
            &format!("{kind:?} sampler, 2D"),
            &observed_2d,
            &vec![n / (bins_2d * bins_2d) as f64; bins_2d * bins_2d],
        );
        assert_fits(
            &format!("{kind:?} sampler, two 1D dimensions jointly"),
            &observed_cross,
            &vec![n / (bins_2d * bins_2d) as f64; bins_2d * bins_2d],
        );
    }
}

/// As [`check_bsdf`], for models with Dirac events as well: a Dirac sample
/// is dropped from the histogram (the pdf integrates to the probability of
/// the rest).
pub(crate) fn check_bsdf_events(name: &str, bsdf: Bsdf, wo: Vec3A, seed: u64) {
    check_directions(
        name,
        |i| {
            let s = bsdf.sample(
                wo,
                uniform(seed, i, 0),
                Vec2::new(uniform(seed, i, 1), uniform(seed, i, 2)),
            )?;
            if s.specular {
                return None;
            }
            let pdf = bsdf.pdf(wo, s.wi);
            assert!(
                (s.pdf - pdf).abs() <= 1e-3 * pdf.max(1.0),
                "{name}: sample pdf {} vs pdf() {pdf}",
                s.pdf
            );
            let weight = bsdf.eval(wo, s.wi) * s.wi.z.abs() / pdf;
            assert!(
                (s.weight - weight).abs().max_element() <= 1e-3 * weight.max_element().max(1.0),
                "{name}: weight {} vs {weight}",
                s.weight
            );
            Some(s.wi)
        },
        |w| bsdf.pdf(wo, w) as f64,
    );
}
