//! White furnace: inside a closed surface of albedo a that emits Le
//! everywhere, radiance is Le + a L, so L = Le / (1 - a) in every direction.
//! With roulette and an unbounded depth the path tracer must find it, with
//! and without next-event estimation, for an analytic sphere (sphere light,
//! area sampling from inside) and for a triangle mesh (triangle lights).
//!
//! Tolerance: the image mean of each channel within 3 of its standard errors,
//! the standard error being sqrt(sum of per-pixel squared standard errors) / N.

use crate::common::{mean_and_standard_error, render};
use glam::Vec3A;
use tracelab::accel::{NO_LIGHT, Sphere, TriangleInput};
use tracelab::camera::Camera;
use tracelab::integrator::{Integrator, MisHeuristic, PathTracer};
use tracelab::math::Rgb;
use tracelab::sampling::SamplerKind;
use tracelab::scene::light::LightSampling;
use tracelab::scene::material::{Bsdf, Material};
use tracelab::scene::{Scene, SceneInput};

const ALBEDO: Rgb = Rgb::new(0.3, 0.5, 0.8);
const EMISSION: Rgb = Rgb::new(0.7, 0.5, 0.2);

fn furnace_material() -> Material {
    Material {
        name: "furnace".into(),
        bsdf: Bsdf::Diffuse { albedo: ALBEDO },
        emission: EMISSION,
        two_sided_emission: true,
        emission_texture: None,
        textures: Default::default(),
        opacity: Default::default(),
        normal_map: None,
        blend: None,
    }
}

fn camera() -> Camera {
    Camera::look_at(
        Vec3A::new(0.1, 0.2, 0.0),
        Vec3A::new(0.3, 0.1, 1.0),
        Vec3A::Y,
        90.0,
        16,
        16,
        0.0,
        1.0,
    )
}

fn sphere_furnace() -> Scene {
    Scene::build(SceneInput {
        warnings: Vec::new(),
        hints: Default::default(),
        environment: None,
        textures: Vec::new(),
        camera: camera(),
        materials: vec![furnace_material()],
        triangles: vec![],
        spheres: vec![Sphere {
            center: Vec3A::ZERO,
            radius: 1.0,
            material: 0,
            light: NO_LIGHT,
        }],
        point_lights: vec![],
        moving: vec![],
        instances: Default::default(),
        sphere_sampling: LightSampling::SolidAngle,
        triangle_sampling: LightSampling::Area,
    })
    .unwrap()
}

fn cube_furnace() -> Scene {
    // The 12 triangles of the cube [-1, 1]^3.
    let corner = |i: usize| {
        Vec3A::new(
            if i & 1 != 0 { 1.0 } else { -1.0 },
            if i & 2 != 0 { 1.0 } else { -1.0 },
            if i & 4 != 0 { 1.0 } else { -1.0 },
        )
    };
    let faces = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let mut triangles = Vec::new();
    for f in faces {
        let [a, b, c, d] = f.map(corner);
        triangles.push(TriangleInput {
            vertices: [a, b, c],
            material: 0,
            uvs: None,
            normals: None,
        });
        triangles.push(TriangleInput {
            vertices: [a, c, d],
            material: 0,
            uvs: None,
            normals: None,
        });
    }
    Scene::build(SceneInput {
        warnings: Vec::new(),
        hints: Default::default(),
        environment: None,
        textures: Vec::new(),
        camera: camera(),
        materials: vec![furnace_material()],
        triangles,
        spheres: vec![],
        point_lights: vec![],
        moving: vec![],
        instances: Default::default(),
        sphere_sampling: LightSampling::SolidAngle,
        triangle_sampling: LightSampling::Area,
    })
    .unwrap()
}

fn check_furnace(scene: Scene, nee: bool, mis: MisHeuristic) {
    let integrator = Integrator::from(PathTracer {
        max_depth: u32::MAX,
        nee,
        mis,
        ..Default::default()
    });
    let (snapshot, stats) = render(scene, integrator, SamplerKind::Independent, 256, 7);
    assert_eq!(stats.non_finite, 0);
    let (mean, se) = mean_and_standard_error(&snapshot);
    for c in 0..3 {
        let expected = (EMISSION[c] / (1.0 - ALBEDO[c])) as f64;
        let z = (mean[c] - expected) / se[c];
        assert!(
            z.abs() < 3.0,
            "channel {c}: {} vs {expected} ({z:.2} standard errors of {})",
            mean[c],
            se[c]
        );
    }
}

#[test]
fn sphere_furnace_with_nee_and_mis() {
    check_furnace(sphere_furnace(), true, MisHeuristic::Power);
}

#[test]
fn sphere_furnace_without_nee() {
    check_furnace(sphere_furnace(), false, MisHeuristic::Power);
}

#[test]
fn cube_furnace_with_nee_and_balance_mis() {
    check_furnace(cube_furnace(), true, MisHeuristic::Balance);
}

#[test]
fn cube_furnace_with_nee_without_mis() {
    check_furnace(cube_furnace(), true, MisHeuristic::None);
}

#[test]
fn cube_furnace_with_spherical_triangle_light_sampling() {
    // Every wall is a light sampled by its solid angle (the wall a point lies
    // on subtends none and falls back to area sampling): MIS weights mix both.
    for mis in [MisHeuristic::Power, MisHeuristic::None] {
        let mut scene = cube_furnace();
        scene.set_light_sampling(LightSampling::SolidAngle);
        check_furnace(scene, true, mis);
    }
}

#[test]
fn cube_furnace_without_nee() {
    check_furnace(cube_furnace(), false, MisHeuristic::Power);
}

#[test]
fn truncated_furnace_sums_the_geometric_series() {
    // Without roulette and with at most 2 bounces, L = Le (1 + a + a^2) exactly
    // in expectation; this checks the bounce count against its definition.
    let integrator = Integrator::from(PathTracer {
        max_depth: 2,
        russian_roulette: false,
        ..Default::default()
    });
    let (snapshot, _) = render(cube_furnace(), integrator, SamplerKind::Independent, 256, 3);
    let (mean, se) = mean_and_standard_error(&snapshot);
    for c in 0..3 {
        let a = ALBEDO[c] as f64;
        let expected = EMISSION[c] as f64 * (1.0 + a + a * a);
        let z = (mean[c] - expected) / se[c];
        assert!(
            z.abs() < 3.0,
            "channel {c}: {} vs {expected} ({z:.2} standard errors)",
            mean[c]
        );
    }
}
