//! Bidirectional path tracing: its strategies add up to its image, it agrees
//! with path tracing and light tracing on the Cornell box, the caustic scene
//! and the indirectly lit room, and a wrong MIS weight is caught. Progressive
//! photon mapping converges to path tracing's image as its radius shrinks.
//!
//! Agreement is the block z-test of `strategies.rs` (8x8 blocks of a 64x64
//! render, |z| < 4.5 over 192 block-channels). Splatting estimators render
//! in 1-spp passes, for which the film's standard error is exact.

use crate::common::{cornell_box, render_with, repo_path};
use crate::strategies::{SIZE, assert_agree, blocks, largest_block_z};
use std::sync::Arc;
use tracelab::film::FilmSnapshot;
use tracelab::integrator::photon::PhotonMap2Pass;
use tracelab::integrator::sppm::PhotonMapper;
use tracelab::integrator::strategy_images::{StrategyImages, strategy_index};
use tracelab::integrator::vcm::Vcm;
use tracelab::integrator::{Bdpt, Integrator, LightTracer, MultiPassIntegrator, PathTracer};
use tracelab::render::{RenderSettings, Session};
use tracelab::sampling::{Sampler, SamplerKind};
use tracelab::scene::Scene;

fn scene(name: &str) -> Scene {
    let mut scene = Scene::load(&repo_path(&format!("scenes/{name}"))).expect("scene loads");
    scene.set_resolution(SIZE, SIZE);
    scene
}

/// Renders in passes of 1 spp for splatting estimators (their film's
/// standard error is then exact), 8 otherwise.
pub(crate) fn render(scene: Scene, integrator: Integrator, spp: u32, seed: u64) -> FilmSnapshot {
    let pass = if matches!(integrator, Integrator::Splatting(_)) {
        1
    } else {
        8
    };
    let (snapshot, stats) = render_with(
        scene,
        integrator,
        SamplerKind::Independent,
        spp,
        seed,
        0,
        pass,
    );
    assert_eq!(stats.non_finite, 0);
    snapshot
}

#[test]
fn weighted_strategy_images_sum_to_the_image() {
    strategy_images_sum_to_the_image(Bdpt::default());
    // With light subpaths for light tracing alone, the extra ones splat too.
    strategy_images_sum_to_the_image(Bdpt {
        light_paths: 3,
        light_path_vertices: 3,
        ..Bdpt::default()
    });
}

fn strategy_images_sum_to_the_image(bdpt: Bdpt) {
    let mut scene = cornell_box();
    scene.set_resolution(32, 32);
    let spp = 4;
    let sampler = Sampler::new(SamplerKind::Independent, 7, spp);
    let (strategies, _) = StrategyImages::render(&scene, &bdpt, &sampler, spp);
    let (image, _) = render_with(
        scene,
        Integrator::from(bdpt),
        SamplerKind::Independent,
        spp,
        7,
        0,
        spp,
    );
    // The session sums in 32.32 fixed point, the strategy images in f64:
    // both are exact to about 1e-6 of a pixel's value here.
    let mut largest = 0.0f64;
    for (p, pixel) in image.image.pixels.iter().enumerate() {
        for c in 0..3 {
            let sum: f64 = strategies.weighted.iter().map(|s| f64::from(s[p][c])).sum();
            let expected = f64::from(pixel[c]);
            largest = largest.max((sum - expected).abs() / expected.abs().max(1e-3));
        }
    }
    assert!(largest < 1e-4, "strategy sum off by {largest:e} (relative)");
    // Direct light seen from the first hit is made by three strategies;
    // unweighted, each estimates all of it, so their means agree.
    let mean = |image: &Vec<[f32; 3]>| image.iter().map(|p| f64::from(p[0])).sum::<f64>();
    let direct =
        [(0, 3), (1, 2), (2, 1)].map(|(s, t)| mean(&strategies.unweighted[strategy_index(s, t)]));
    assert!(
        (direct[1] - direct[2]).abs() < 0.1 * direct[1],
        "light sampling {} vs light tracing {}",
        direct[1],
        direct[2]
    );
}

#[test]
fn bidirectional_agrees_with_path_and_light_tracing() {
    let bdpt = Integrator::from(Bdpt::default());
    let path = Integrator::from(PathTracer::default());
    let light = Integrator::from(LightTracer::default());
    let cornell = render(scene("cornell_box.toml"), bdpt, 256, 1);
    assert_agree(
        "Cornell box, bdpt / path",
        &cornell,
        &render(scene("cornell_box.toml"), path, 512, 2),
    );
    let room = render(scene("indirect.toml"), bdpt, 256, 3);
    assert_agree(
        "indirect room, bdpt / path",
        &room,
        &render(scene("indirect.toml"), path, 1024, 4),
    );
    assert_agree(
        "indirect room, bdpt / light",
        &room,
        &render(scene("indirect.toml"), light, 1024, 5),
    );
    // Light tracing cannot see the glass ball itself (no connection reaches
    // the camera through a specular surface: those pixels are black), and
    // paths that see the lamp through the ball have tails too heavy for a
    // z-test at any affordable count (two path-traced renders of 8192 spp
    // differ by 6% in such blocks). The test therefore compares the blocks
    // without glass, where the caustic lies: BDPT against light tracing.
    let caustic = render(scene("caustic.toml"), bdpt, 256, 6);
    let particles = render(scene("caustic.toml"), light, 512, 7);
    let worst = largest_glass_free_z(&caustic, &particles);
    eprintln!("caustic without the glass, bdpt / light: largest z {worst:.2}");
    assert!(
        worst < 4.5,
        "caustic: a block differs by {worst:.2} standard errors"
    );
}

/// VCM adds merges to BDPT's connections; a merge weighed or normalised
/// wrongly shifts the caustic and the indirect light. At 64 x 64 an
/// iteration has only 4 096 light subpaths, so merges of the default radius
/// would weigh too little to be tested: a radius of 1% of the diagonal (a
/// pixel's width here) gives them a large share (merges counted 1.5 times
/// over fail). Light subpaths are shared by the pixels of an iteration, so
/// neighbouring pixels are slightly correlated; the block z-test still
/// holds with the usual bound.
#[test]
fn vertex_connection_and_merging_agrees_with_path_and_light_tracing() {
    let vcm = Integrator::MultiPass(MultiPassIntegrator::Vcm(Vcm {
        radius: 0.01,
        ..Vcm::default()
    }));
    assert_agree(
        "Cornell box, vcm / path",
        &render(scene("cornell_box.toml"), vcm, 256, 11),
        &render(
            scene("cornell_box.toml"),
            Integrator::from(PathTracer::default()),
            512,
            12,
        ),
    );
    assert_agree(
        "indirect room, vcm / bdpt",
        &render(scene("indirect.toml"), vcm, 256, 13),
        &render(
            scene("indirect.toml"),
            Integrator::from(Bdpt::default()),
            256,
            14,
        ),
    );
    let caustic = render(scene("caustic.toml"), vcm, 256, 15);
    let particles = render(
        scene("caustic.toml"),
        Integrator::from(LightTracer::default()),
        512,
        16,
    );
    let worst = largest_glass_free_z(&caustic, &particles);
    eprintln!("caustic without the glass, vcm / light: largest z {worst:.2}");
    assert!(
        worst < 4.5,
        "caustic: a block differs by {worst:.2} standard errors"
    );
}

/// Light subpaths for light tracing alone: their contributions count 1 / m
/// and light tracing's density m times in every weight; a share or a weight
/// left at one is a bias of the size of light tracing's part of the image.
#[test]
fn extra_light_paths_agree_with_path_tracing() {
    let bdpt = Integrator::from(Bdpt {
        light_paths: 4,
        light_path_vertices: 3,
        ..Bdpt::default()
    });
    let path = Integrator::from(PathTracer::default());
    assert_agree(
        "Cornell box, bdpt with 4 light paths / path",
        &render(scene("cornell_box.toml"), bdpt, 128, 21),
        &render(scene("cornell_box.toml"), path, 512, 22),
    );
    assert_agree(
        "indirect room, bdpt with 4 light paths / path",
        &render(scene("indirect.toml"), bdpt, 128, 23),
        &render(scene("indirect.toml"), path, 1024, 24),
    );
}

#[test]
fn a_wrong_strategy_weight_is_caught() {
    // Light sampling's paths counted in full and by the other strategies:
    // the direct light comes out about 12% too bright.
    let faulty = Bdpt {
        faulty_strategy: Some((1, 2)),
        ..Bdpt::default()
    };
    let reference = render(
        scene("cornell_box.toml"),
        Integrator::from(PathTracer::default()),
        512,
        2,
    );
    let wrong = render(scene("cornell_box.toml"), Integrator::from(faulty), 256, 1);
    let worst = largest_block_z(&reference, &wrong);
    assert!(
        worst > 4.5,
        "a wrong weight went unnoticed (largest z {worst:.2})"
    );
}

/// The largest block z-score between `image` and the light tracer's `particles`
/// over the blocks where light tracing sees no glass (it cannot see
/// through it: those pixels are black).
fn largest_glass_free_z(image: &FilmSnapshot, particles: &FilmSnapshot) -> f64 {
    let glass_free: Vec<bool> = (0..(SIZE / 8) * (SIZE / 8))
        .map(|b| {
            let (bx, by) = (b % (SIZE / 8), b / (SIZE / 8));
            (0..64).all(|i| {
                let (x, y) = (bx * 8 + i % 8, by * 8 + i / 8);
                particles.image.pixels[(y * SIZE + x) as usize][1] > 0.0
            })
        })
        .collect();
    let kept = glass_free.iter().filter(|&&k| k).count();
    assert!(kept >= 48, "only {kept} blocks without glass");
    let mut worst = 0.0f64;
    for ((a, b), keep) in blocks(image).iter().zip(blocks(particles)).zip(glass_free) {
        for c in 0..3 {
            if keep {
                worst = worst.max(((a.0[c] - b.0[c]) / (a.1[c] + b.1[c]).sqrt()).abs());
            }
        }
    }
    worst
}

/// A 32x32 Cornell box, and path tracing's image of it at 4096 spp.
fn small_cornell_and_reference() -> (impl Fn() -> Scene, FilmSnapshot) {
    let small = || {
        let mut scene = cornell_box();
        scene.set_resolution(32, 32);
        scene
    };
    let (reference, _) = render_with(
        small(),
        Integrator::from(PathTracer::default()),
        SamplerKind::Independent,
        4096,
        1,
        0,
        256,
    );
    (small, reference)
}

/// A session of a multi-pass technique on `scene`.
fn multi_pass_session(scene: Scene, technique: MultiPassIntegrator, seed: u64) -> Session {
    let settings = RenderSettings {
        integrator: Integrator::MultiPass(technique),
        sampler: SamplerKind::Independent,
        seed,
        planned_spp: 0,
        threads: 0,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    Session::new(Arc::new(scene), settings).expect("session starts")
}

#[test]
fn photon_mapping_converges_as_its_radius_shrinks() {
    let (small, reference) = small_cornell_and_reference();
    let sppm = PhotonMapper {
        photons: 20_000,
        ..PhotonMapper::default()
    };
    let session = multi_pass_session(small(), MultiPassIntegrator::Sppm(sppm), 3);
    let mut rmse = Vec::new();
    for iterations in [8, 128] {
        while session.stats().spp < iterations {
            assert!(session.render_pass(8));
        }
        rmse.push(
            session
                .snapshot()
                .image
                .compare(&reference.image)
                .unwrap()
                .rmse,
        );
    }
    // Bias (~ r^2) and variance (~ 1 / (r^2 N)) both fall as N^(-1/3) in
    // RMSE for alpha = 2/3; 16 times the iterations should divide the error
    // by 2.5. A fixed radius would stall at its bias, and a wrong
    // normalisation would not converge to path tracing at all.
    let slope = (rmse[1] / rmse[0]).ln() / 16f64.ln();
    eprintln!(
        "photon mapping RMSE {:.5} -> {:.5} over 8 -> 128 iterations: slope {slope:.3}",
        rmse[0], rmse[1]
    );
    assert!(slope < -0.2, "RMSE {rmse:?}: log-log slope {slope:.3}");
}

#[test]
fn jensens_photon_map_bias_shrinks_with_the_photon_count() {
    let (small, reference) = small_cornell_and_reference();
    let reference_red = reference.image.mean()[0];
    // The image's mean red, relative to path tracing's, after 64 iterations
    // of fresh maps: the average over maps leaves the density estimate's
    // bias. Its noise is about 1e-3 (two seeds differ by 1e-3); the bias is
    // -2.0% at 2 000 photons and about -0.25% at 32 000.
    let bias = |photons: u32| {
        let jensen = PhotonMap2Pass {
            photons,
            ..PhotonMap2Pass::default()
        };
        let session = multi_pass_session(small(), MultiPassIntegrator::Photon(jensen), 5);
        assert!(session.render_pass(64));
        session.snapshot().image.mean()[0] / reference_red - 1.0
    };
    let (few, many) = (bias(2_000), bias(32_000));
    eprintln!("photon map bias of the mean: {few:+.4} at 2 000 photons, {many:+.4} at 32 000");
    assert!(
        few.abs() > 0.008,
        "the bias at 2 000 photons should show: {few:+.4}"
    );
    assert!(many.abs() < few.abs() / 3.0, "{few:+.4} -> {many:+.4}");
}

/// BDPT's camera strategies estimate the traced sample's own pixel: they
/// are splatted through the filter from the camera ray's film position, as
/// path tracing's samples are (importance-sampled, they are added to that
/// pixel as they are: spread again by the Gaussian, whose weights at whole
/// pixels sum to 1.027, they once made this environment-lit scene 2.0%
/// brighter than path tracing, z 6.8). The whole image's mean (green: a
/// pixel's channels are correlated) has its standard error from the
/// pixels' summed as independent, times each film's correlation (about π
/// pixels a sample for the Gaussian); BDPT's light splats correlate
/// neighbours a little more, which the 4.5 bound leaves room for.
#[test]
fn bidirectional_agrees_with_path_tracing_under_a_gaussian_filter() {
    let gaussian = || {
        let mut s = scene("material_preview.toml");
        s.camera.filter = tracelab::filter::PixelFilter::gaussian();
        s
    };
    let bdpt = render(gaussian(), Integrator::from(Bdpt::default()), 64, 11);
    let path = render(gaussian(), Integrator::from(PathTracer::default()), 128, 12);
    let whole = |s: &FilmSnapshot| {
        let (mut sum, mut var) = (0.0f64, 0.0f64);
        // Green alone: the channels of a pixel are correlated.
        for (p, e) in s.image.pixels.iter().zip(&s.standard_error.pixels) {
            sum += p[1] as f64;
            var += (e[1] as f64).powi(2);
        }
        (sum, var * s.correlation)
    };
    let ((a, va), (b, vb)) = (whole(&bdpt), whole(&path));
    let z = (a - b) / (va + vb).sqrt();
    eprintln!(
        "Gaussian filter, bdpt / path: mean ratio {:.4}, z {z:.2}",
        a / b
    );
    assert!(z.abs() < 4.5, "the means differ by {z:.2} standard errors");
    assert_agree("Gaussian filter, bdpt / path", &bdpt, &path);
}

/// A ball alone under a uniform white sky, seen whole; `BSDF` stands for
/// its material.
const BALL_IN_THE_SKY: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, -5, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><float name="radius" value="1"/>BSDF</shape>
</scene>
"#;

/// A rough metal ball on a grey floor, a small bright lamp above, a dim sky.
const METAL_BALL: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -6, 2" target="0, 0, 0.8" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
  <shape type="rectangle">
    <transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/><translate x="1" y="-1" z="4"/></transform>
    <emitter type="area"><rgb name="radiance" value="40"/></emitter>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0" z="1"/><float name="radius" value="1"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf>
  </shape>
</scene>
"#;

/// A rough metal ball in a closed white box lit by a small lamp, seen
/// from inside: most pixels see the walls in the ball.
const BOXED_METAL_BALL: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0, -2.5, 0.3" target="0, 0, 0" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/><rfilter type="box"/></film>
  </sensor>
  <shape type="cube"><transform name="to_world"><scale value="3"/></transform><boolean name="flip_normals" value="true"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="0.3"/><rotate x="1" angle="180"/><translate x="0.5" y="0.5" z="2.9"/></transform>
    <emitter type="area"><rgb name="radiance" value="30"/></emitter>
  </shape>
  <shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf>
  </shape>
</scene>
"#;

/// The photon mappers against path tracing where light passes through
/// rough glass or is reflected by a rough metal:
/// - a rough glass ball (α 0.3) in a white sky, and a principled one half
///   diffuse, half transmitting: what leaves them towards the camera is
///   mostly sky that entered elsewhere. A lookup kept only the photons on
///   the camera's side of the surface, and SPPM read 0.61 and 0.93 of path
///   tracing's mean, Jensen's map 0.69 on the glass;
/// - a smooth plastic ball in the sky, whose coating's mirror image the
///   camera paths follow as often as the BSDF picks it (SPPM and Jensen's
///   map read 0.94 of path tracing's mean when they gathered only);
/// - the metal ball, which the camera paths now cross by sampling it, the
///   lamp's light there weighed by MIS (a weight of 1 on both of its
///   strategies would count the lamp's reflection twice);
/// - a metal ball in a closed white box at a depth of 2, where a photon's
///   bounces and those of the camera's chain to the wall must add up to
///   the depth: the walls seen in the ball show direct light only.
///
/// A photon mapper's pixels share each pass's photons, so the image mean's
/// spread is not the pixels' standard errors summed: it was measured over
/// eight seeds at these settings (standard deviations at most 0.78%,
/// 0.83% and 0.75% of the mean for SPPM, Jensen's map and VCM, in the
/// box). Each mean agrees with path tracing's within 4 of those, plus 2%
/// for the density estimates' bias (at most −1.0% in those seeds, VCM's on
/// the metal). Faults it caught as mutations: the lookup on one side only
/// (principled ball, SPPM −6.4%), the glossy light sample weighed 1 (glass
/// ball, SPPM +38%), photons counted as if the camera's chain had no
/// bounces (box, SPPM +19%, Jensen's map +14%).
#[test]
fn photon_mappers_agree_with_path_tracing_through_rough_glass_and_metal() {
    let dir = crate::common::temp_dir("photon_mappers_rough");
    let glass = r#"<bsdf type="roughdielectric"><float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/></bsdf>"#;
    let plastic = r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.3"/></bsdf>"#;
    let principled = r#"<bsdf type="principled"><rgb name="base_color" value="0.8"/><float name="spec_trans" value="0.5"/><float name="roughness" value="0.5"/></bsdf>"#;
    let scenes = [
        ("glass ball", BALL_IN_THE_SKY.replace("BSDF", glass), 8),
        (
            "principled ball",
            BALL_IN_THE_SKY.replace("BSDF", principled),
            8,
        ),
        ("plastic ball", BALL_IN_THE_SKY.replace("BSDF", plastic), 8),
        ("metal ball", METAL_BALL.to_string(), 8),
        (
            "boxed metal ball at depth 2",
            BOXED_METAL_BALL.to_string(),
            2,
        ),
    ];
    for (scene, text, max_depth) in scenes {
        let path = dir.join(format!("{}.xml", scene.replace(' ', "_")));
        std::fs::write(&path, text).expect("scene written");
        let load = || Scene::load(&path).expect("the scene loads");
        let (reference, _) = render_with(
            load(),
            Integrator::from(PathTracer {
                max_depth,
                ..PathTracer::default()
            }),
            SamplerKind::Independent,
            2048,
            7,
            0,
            64,
        );
        let expected = reference.image.mean()[1];
        let sppm = PhotonMapper {
            max_depth,
            photons: 20_000,
            radius: 0.01,
            ..PhotonMapper::default()
        };
        let jensen = PhotonMap2Pass {
            max_depth,
            photons: 50_000,
            ..PhotonMap2Pass::default()
        };
        let vcm = Vcm {
            max_depth,
            radius: 0.01,
            ..Vcm::default()
        };
        let techniques = [
            ("SPPM", MultiPassIntegrator::Sppm(sppm), 0.0078),
            ("Jensen's map", MultiPassIntegrator::Photon(jensen), 0.0083),
            ("VCM", MultiPassIntegrator::Vcm(vcm), 0.0075),
        ];
        for (name, technique, spread) in techniques {
            let session = multi_pass_session(load(), technique, 11);
            assert!(session.render_pass(128));
            assert_eq!(session.stats().non_finite, 0);
            let mean = session.snapshot().image.mean()[1];
            let tolerance = (4.0 * spread + 0.02) * expected;
            eprintln!(
                "{scene}, {name}: mean {mean:.5} against path tracing's {expected:.5} (tolerance {tolerance:.5})"
            );
            assert!(
                (mean - expected).abs() < tolerance,
                "{scene}, {name}: mean {mean} against path tracing's {expected} (tolerance {tolerance})"
            );
        }
    }
}
