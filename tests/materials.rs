//! The material models added for real scenes, in every technique: path
//! tracing, light tracing, BDPT and VCM agree on a room of rough models
//! (block z-test of `strategies.rs`: 8x8 blocks of a 64x64 render, |z| <
//! 4.5); on the material preview scene, with Dirac lobes too (which light
//! tracing cannot see directly), BDPT and VCM agree with path tracing and
//! SPPM converges to the same mean.

use crate::bidirectional::render;
use crate::common::{load_scene_text, render_with, repo_path};
use crate::strategies::{SIZE, assert_agree};
use tracelab::integrator::vcm::Vcm;
use tracelab::integrator::{Bdpt, Integrator, LightTracer, MultiPassIntegrator, PathTracer};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

/// A closed room: rough conductors (GGX, Beckmann, anisotropic), a rough
/// glass ball, rough plastics and an Oren–Nayar block under a square lamp.
/// Every surface has a non-Dirac lobe, so light tracing sees all of it.
const ROUGH_ROOM: &str = r#"
[camera]
eye = [0.0, 1.0, 2.9]
look_at = [0.0, 0.9, 0.0]
fov_y = 50.0
width = 64
height = 64

[materials.white]
type = "diffuse"
albedo = [0.7, 0.7, 0.7]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [15.0, 15.0, 15.0]

[materials.copper]
type = "roughconductor"
conductor = "Cu"
distribution = "ggx"
alpha = 0.3

[materials.brushed]
type = "roughconductor"
conductor = "Al"
distribution = "ggx"
alpha_u = 0.15
alpha_v = 0.5
twosided = true

[materials.chrome]
type = "roughconductor"
conductor = "Cr"
distribution = "beckmann"
alpha = 0.4

[materials.frosted]
type = "roughdielectric"
int_ior = 1.5
distribution = "ggx"
alpha = 0.4

[materials.plastic]
type = "roughplastic"
diffuse_reflectance = [0.7, 0.2, 0.1]
distribution = "beckmann"
alpha = 0.3

[materials.wet]
type = "roughplastic"
diffuse_reflectance = [0.1, 0.3, 0.6]
distribution = "ggx"
alpha = 0.25
nonlinear = true

[materials.clay]
type = "roughdiffuse"
albedo = [0.6, 0.6, 0.4]
alpha = 0.7

[[quad]]
corner = [-1.5, 0.0, 1.5]
u = [3.0, 0.0, 0.0]
v = [0.0, 0.0, -3.0]
material = "white"

[[quad]]
corner = [-1.5, 2.0, -1.5]
u = [3.0, 0.0, 0.0]
v = [0.0, 0.0, 3.0]
material = "white"

[[quad]]
corner = [-1.5, 0.0, -1.5]
u = [3.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "plastic"

[[quad]]
corner = [-1.5, 0.0, 1.5]
u = [0.0, 0.0, -3.0]
v = [0.0, 2.0, 0.0]
material = "brushed"

[[quad]]
corner = [1.5, 0.0, -1.5]
u = [0.0, 0.0, 3.0]
v = [0.0, 2.0, 0.0]
material = "clay"

[[quad]]
corner = [-0.4, 1.99, -0.4]
u = [0.8, 0.0, 0.0]
v = [0.0, 0.0, 0.8]
material = "lamp"

[[sphere]]
center = [-0.7, 0.4, -0.3]
radius = 0.4
material = "copper"

[[sphere]]
center = [0.55, 0.35, 0.2]
radius = 0.35
material = "frosted"

[[sphere]]
center = [0.1, 0.3, -0.9]
radius = 0.3
material = "chrome"

[[sphere]]
center = [0.0, 1.2, -0.8]
radius = 0.25
material = "wet"
"#;

#[test]
fn every_technique_agrees_on_rough_materials() {
    let scene = load_scene_text("rough-room", ROUGH_ROOM);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        512,
        1,
    );
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 2);
    assert_agree("rough room, bdpt / path", &bdpt, &path);
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        512,
        3,
    );
    assert_agree("rough room, light / path", &light, &path);
    // Merges blur over their radius, which on these small spheres is a
    // visible bias at 1% of the diagonal (z 7.6 against BDPT) but not at
    // 0.4% (z 3.4), where merges still carry much of the glossy light.
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.004,
        ..Vcm::default()
    }));
    assert_agree("rough room, vcm / bdpt", &render(scene, vcm, 256, 4), &bdpt);
}

#[test]
fn bidirectional_techniques_agree_with_path_tracing_on_every_material() {
    let mut scene = Scene::load(&repo_path("scenes/material_preview.toml")).unwrap();
    scene.set_resolution(SIZE, SIZE);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        512,
        5,
    );
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 6);
    assert_agree("material preview, bdpt / path", &bdpt, &path);
    // The preview's diagonal is twice the room's: 0.2% of it is the same
    // merge radius in metres.
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.002,
        ..Vcm::default()
    }));
    assert_agree(
        "material preview, vcm / path",
        &render(scene, vcm, 256, 7),
        &path,
    );
}

/// Importance sampling of an environment map: the irradiance of an upward
/// plane under the test sky (its sun 800 times the sky) estimated from the
/// map's density and from uniform directions, at equal sample counts. Both
/// means agree within 4 standard errors; the variance falls by more than
/// 10x (per sample; the cost per sample is measured in docs/performance.md).
#[test]
fn environment_importance_sampling_cuts_the_variance() {
    use tracelab::scene::environment::{Environment, Radiance};
    use tracelab::texture::Bitmap;
    let sky = std::sync::Arc::new(
        Bitmap::read(&repo_path("tests/data/materials/sky.exr"), false).unwrap(),
    );
    let importance = Environment::new(Radiance::Map(sky), 1.0, glam::Mat3A::IDENTITY);
    let uniform = importance.clone().with_uniform_sampling();
    let n = 200_000u64;
    let estimate = |env: &Environment, seed: u64| {
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for i in 0..n {
            let u =
                glam::Vec2::new(
                    tracelab::sampling::hash::to_unit_float(
                        tracelab::sampling::hash::hash_combine(seed, 2 * i),
                    ),
                    tracelab::sampling::hash::to_unit_float(
                        tracelab::sampling::hash::hash_combine(seed, 2 * i + 1),
                    ),
                );
            let x = env
                .sample(u)
                .map_or(0.0, |(d, le, pdf)| (le.x * d.y.max(0.0) / pdf) as f64);
            sum += x;
            sum_sq += x * x;
        }
        let mean = sum / n as f64;
        (mean, (sum_sq / n as f64 - mean * mean).max(0.0))
    };
    let (m_i, v_i) = estimate(&importance, 1);
    let (m_u, v_u) = estimate(&uniform, 2);
    eprintln!(
        "irradiance: importance {m_i:.3} (var {v_i:.3e}), uniform {m_u:.3} (var {v_u:.3e}), ratio {:.1}",
        v_u / v_i
    );
    let se = ((v_i + v_u) / n as f64).sqrt();
    assert!((m_i - m_u).abs() < 4.0 * se, "means {m_i} and {m_u} differ");
    assert!(v_u > 10.0 * v_i, "variance only {:.1}x lower", v_u / v_i);
}

/// A floor and a rough plastic ball under a spot, a directional light and
/// a constant environment.
const EVERY_LIGHT: &str = r#"
[camera]
eye = [0.0, -4.0, 2.5]
look_at = [0.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
fov_y = 35.0
width = 64
height = 64

[materials.floor]
type = "diffuse"
albedo = [0.4, 0.4, 0.4]

[materials.ball]
type = "roughplastic"
distribution = "ggx"
alpha = 0.3
diffuse_reflectance = [0.6, 0.3, 0.2]

[[quad]]
corner = [-20.0, -20.0, 0.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "floor"

[[sphere]]
center = [0.0, 0.0, 0.6]
radius = 0.6
material = "ball"

[[spot_light]]
position = [-2.0, -2.0, 2.0]
target = [0.0, 0.0, 0.3]
intensity = [20.0, 18.0, 15.0]

[[directional_light]]
direction = [0.8, 0.3, -0.5]
irradiance = [1.5, 1.2, 0.9]

[environment]
type = "constant"
radiance = [0.3, 0.35, 0.4]
"#;

/// Light from infinity and delta lights in light tracing and BDPT: particles from
/// the environment's and the directional light's discs and from the spot's
/// cone agree with path tracing's light samples (the floor fills the
/// frame, so no pixel sees the environment itself, which light tracing
/// cannot).
#[test]
fn light_tracing_agrees_with_path_tracing_under_every_light() {
    let text = EVERY_LIGHT;
    let scene = load_scene_text("every-light", text);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        256,
        21,
    );
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        256,
        22,
    );
    assert_agree("every light, light / path", &light, &path);
    // BDPT under all three lights at once, against path tracing.
    let scene = load_scene_text("every-light-bdpt", text);
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 25);
    assert_agree("every light, bdpt / path", &bdpt, &path);
    // VCM under all three: particles from the discs weighed by SmallVCM's
    // densities of lights at infinity; merges at 0.03% of the diagonal.
    // 1 024 samples: at 256 VCM's per-pixel standard errors miss its heavy
    // tail (one block 2.6% low with a standard error of 0.2%, where two
    // 20 s renders agree with path tracing to 0.4%), which path tracing's
    // smaller error since its shadow rays reach the spot (2026-11-28) made
    // a 4.9-sigma difference.
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.0003,
        ..Vcm::default()
    }));
    assert_agree(
        "every light, vcm / path",
        &render(scene, vcm, 1024, 29),
        &path,
    );
    // And looking up at an environment map, seen directly above the horizon.
    let sky = text
        .replace("look_at = [0.0, 0.0, 0.5]", "look_at = [0.0, 0.0, 2.5]")
        .replace(
            "type = \"constant\"\nradiance = [0.3, 0.35, 0.4]",
            &format!(
                "type = \"envmap\"\nfile = \"{}\"",
                repo_path("tests/data/materials/sky.exr").display()
            ),
        );
    assert!(sky.contains("envmap"));
    let scene = load_scene_text("sky-bdpt", &sky);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        256,
        26,
    );
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 27);
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.0003,
        ..Vcm::default()
    }));
    let vcm = render(scene, vcm, 256, 30);
    // Sky pixels are all but noiseless (standard errors near 1e-7): there
    // the two films may differ by their rounding (2e-6 measured), so a
    // block passes within 4.5 standard errors or 1e-5 of its value.
    for (name, film) in [("bdpt", &bdpt), ("vcm", &vcm)] {
        let (a, b) = (
            crate::strategies::blocks(film),
            crate::strategies::blocks(&path),
        );
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            for c in 0..3 {
                let (diff, se) = ((x.0[c] - y.0[c]).abs(), (x.1[c] + y.1[c]).sqrt());
                assert!(
                    diff <= 4.5 * se || diff <= 1e-5 * y.0[c],
                    "environment map seen, {name} / path: block {i} channel {c}: {} vs {} (se {se})",
                    x.0[c],
                    y.0[c]
                );
            }
        }
    }
    // Under the spot alone, against light tracing (not path tracing's
    // standard errors: beyond the spot's cone the far floor gets 1e-5 by
    // rare paths, whose spread path tracing's few non-zero samples
    // understate: z 10.8 there, all means within 0.02%).
    let spot_only = &text[..text.find("[[directional_light]]").unwrap()];
    let scene = load_scene_text("spot-light", spot_only);
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        256,
        23,
    );
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 24);
    assert_agree("spot light, bdpt / light", &bdpt, &light);
    // VCM too (the spot's falloff is in the particles' weights, its cone's
    // density in the MIS quantities); the 40 m floor makes the diagonal 57 m:
    // merges at 0.03% of it, 1.7 cm.
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.0003,
        ..Vcm::default()
    }));
    assert_agree(
        "spot light, vcm / light",
        &render(scene, vcm, 256, 28),
        &light,
    );
}

/// An environment map with NaN and infinite texels (read as 0) and one
/// texel of 1e6 (a sun a million times the sky), and a texture with NaN
/// texels: no non-finite sample reaches the film, in path tracing or light
/// tracing.
#[test]
fn extreme_texels_stay_finite() {
    let dir = crate::common::temp_dir("extreme-texels");
    let (w, h) = (16usize, 8usize);
    let mut pfm = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    for i in 0..w * h {
        let v = match i {
            5 => f32::NAN,
            9 => f32::INFINITY,
            40 => 1e6,
            _ => 0.5,
        };
        for _ in 0..3 {
            pfm.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(dir.join("sky.pfm"), &pfm).unwrap();
    let mut nan_texture = "PF\n2 2\n-1.0\n".to_string().into_bytes();
    for v in [f32::NAN, 0.5, 0.5, f32::NEG_INFINITY]
        .iter()
        .flat_map(|v| [*v; 3])
    {
        nan_texture.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(dir.join("albedo.pfm"), &nan_texture).unwrap();
    let text = format!(
        r#"
[camera]
eye = [0.0, -4.0, 2.5]
look_at = [0.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
fov_y = 60.0
width = 32
height = 32

[textures.bad]
type = "bitmap"
file = "{albedo}"

[materials.floor]
type = "diffuse"
albedo_texture = "bad"

[materials.ball]
type = "roughconductor"
conductor = "Cu"
distribution = "ggx"
alpha = 0.0001

[[quad]]
corner = [-3.0, -3.0, 0.0]
u = [6.0, 0.0, 0.0]
v = [0.0, 6.0, 0.0]
material = "floor"

[[sphere]]
center = [0.0, 0.0, 0.6]
radius = 0.6
material = "ball"

[environment]
type = "envmap"
file = "{sky}"
"#,
        albedo = dir.join("albedo.pfm").display(),
        sky = dir.join("sky.pfm").display()
    );
    let scene = load_scene_text("extreme-texels", &text);
    for integrator in [
        Integrator::from(PathTracer::default()),
        Integrator::from(LightTracer::default()),
    ] {
        let name = integrator.name();
        let (snapshot, stats) = render_with(
            scene.clone(),
            integrator,
            SamplerKind::Independent,
            16,
            3,
            0,
            1,
        );
        assert_eq!(stats.non_finite, 0, "{name}");
        assert!(
            snapshot
                .image
                .pixels
                .iter()
                .flatten()
                .all(|c| c.is_finite())
        );
    }
}

/// Shading normals: light tracing, BDPT and VCM (with Veach's adjoint
/// correction) agree with path tracing on a faceted sphere shaded smooth, diffuse and rough
/// plastic; without the correction it does not (the test sees it).
#[test]
fn light_tracing_agrees_with_path_tracing_under_shading_normals() {
    let dir = crate::common::temp_dir("smooth-sphere");
    // 12 x 6 quads: shading and geometric normals differ by up to 15 degrees.
    std::fs::write(
        dir.join("ball.obj"),
        crate::common::uv_sphere_obj(12, 6, true),
    )
    .unwrap();
    let text = format!(
        r#"
[camera]
eye = [0.0, -3.0, 1.6]
look_at = [0.0, 0.0, 0.6]
up = [0.0, 0.0, 1.0]
fov_y = 40.0
width = 64
height = 64

[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [6.0, 6.0, 6.0]

[materials.ball]
type = "roughplastic"
distribution = "ggx"
alpha = 0.3
diffuse_reflectance = [0.7, 0.4, 0.2]

[[quad]]
corner = [-20.0, -20.0, 0.0]
u = [40.0, 0.0, 0.0]
v = [0.0, 40.0, 0.0]
material = "floor"

[[quad]]
corner = [-0.3, -1.8, 2.5]
u = [0.0, 1.6, 0.0]
v = [1.6, 0.0, 0.0]
material = "lamp"

[[mesh]]
file = "{obj}"
translate = [0.0, 0.0, 0.6]
scale = 0.6
material = "ball"
"#,
        obj = dir.join("ball.obj").display()
    );
    let scene = load_scene_text("smooth-sphere", &text);
    assert!(scene.features.shading_normals);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        512,
        31,
    );
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        512,
        32,
    );
    assert_agree("shading normals, light / path", &light, &path);
    // Against light tracing: path tracing integrates the lamp's silhouette
    // pixels exactly, whose standard errors then understate BDPT's spread
    // there (z 5.3 in the block of its edge; BDPT and light tracing agree).
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 512, 34);
    assert_agree("shading normals, bdpt / light", &bdpt, &light);
    // VCM: connections as BDPT's, merges weighed by |wi·ns| / |wi·ng|;
    // merges of 1.7 cm (0.03% of the 57 m diagonal).
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.0003,
        ..Vcm::default()
    }));
    assert_agree(
        "shading normals, vcm / light",
        &render(scene.clone(), vcm, 512, 35),
        &light,
    );
    // Flat shading differs visibly from smooth (the normals matter here).
    let flat = load_scene_text(
        "flat-sphere",
        &text.replace(
            "material = \"ball\"\n",
            "material = \"ball\"\nface_normals = true\n",
        ),
    );
    assert!(!flat.features.shading_normals);
    let faceted = render(flat, Integrator::from(PathTracer::default()), 512, 33);
    let worst = crate::strategies::largest_block_z(&faceted, &path);
    assert!(worst > 4.5, "flat and smooth shading agree (z {worst:.2})");
}

/// A normal map (tests/data/materials/bumps.exr) on a rough plastic sphere
/// and on the floor, under a spot and an area light: light tracing, BDPT
/// and VCM agree with path tracing (block z-test), so the tilted normal is
/// the same for every technique and the adjoint's correction covers it.
#[test]
fn every_technique_agrees_under_a_normal_map() {
    let bumps = repo_path("tests/data/materials/bumps.exr");
    // The spot-lit room of EVERY_LIGHT with a lamp instead of the lights
    // at infinity, and the map on the floor and the ball.
    let spot_only = &EVERY_LIGHT[..EVERY_LIGHT.find("[[directional_light]]").unwrap()];
    let text = spot_only
        .replace(
            "albedo = [0.4, 0.4, 0.4]\n",
            "albedo = [0.4, 0.4, 0.4]\nnormal_map_texture = \"bumps\"\n",
        )
        .replace(
            "diffuse_reflectance = [0.6, 0.3, 0.2]\n",
            "diffuse_reflectance = [0.6, 0.3, 0.2]\nnormal_map_texture = \"bumps\"\n",
        )
        + &format!(
            r#"
[textures.bumps]
type = "bitmap"
file = {:?}
raw = true

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [3.0, 3.0, 3.0]

[[quad]]
corner = [0.2, -2.2, 3.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "lamp"
"#,
            bumps.display().to_string()
        );
    assert_eq!(text.matches("normal_map_texture").count(), 2);
    let scene = load_scene_text("normal-map", &text);
    assert!(scene.features.normal_maps && scene.features.shading_normals);
    let path = render(
        scene.clone(),
        Integrator::from(PathTracer::default()),
        256,
        51,
    );
    let light = render(
        scene.clone(),
        Integrator::from(LightTracer::default()),
        256,
        52,
    );
    assert_agree("normal map, light / path", &light, &path);
    let bdpt = render(scene.clone(), Integrator::from(Bdpt::default()), 256, 53);
    assert_agree("normal map, bdpt / path", &bdpt, &path);
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.0003,
        ..Vcm::default()
    }));
    assert_agree(
        "normal map, vcm / path",
        &render(scene, vcm, 256, 54),
        &path,
    );
}
