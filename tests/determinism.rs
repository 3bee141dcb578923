//! An image is a function of (scene, settings, seed) only: not of the thread
//! count, the tile schedule or how the samples are split into passes.

use crate::common::{cornell_box, render_with};
use tracelab::integrator::{Integrator, PathTracer};
use tracelab::sampling::SamplerKind;

fn film(sampler: SamplerKind, threads: usize, pass: u32, seed: u64) -> Vec<[f32; 3]> {
    let mut scene = cornell_box();
    scene.set_resolution(48, 40);
    let (snapshot, _) = render_with(
        scene,
        Integrator::from(PathTracer::default()),
        sampler,
        16,
        seed,
        threads,
        pass,
    );
    // Bit patterns, so that -0.0 vs 0.0 or NaN payloads would count as different.
    assert!(snapshot.samples.iter().all(|&n| n == 16));
    snapshot.image.pixels
}

#[test]
fn same_seed_gives_a_bit_identical_film_with_one_and_two_threads() {
    for sampler in [SamplerKind::Independent, SamplerKind::Stratified] {
        let one = film(sampler, 1, 16, 5);
        let two = film(sampler, 2, 16, 5);
        let split = film(sampler, 2, 3, 5);
        let bits = |v: &Vec<[f32; 3]>| {
            v.iter()
                .flat_map(|p| p.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&one), bits(&two), "{sampler:?}: 1 vs 2 threads");
        assert_eq!(
            bits(&one),
            bits(&split),
            "{sampler:?}: one pass vs passes of 3"
        );
        assert_ne!(
            bits(&one),
            bits(&film(sampler, 2, 16, 6)),
            "{sampler:?}: the seed must matter"
        );
    }
}

/// Camera rays tested against their pixel's candidate triangles only
/// (`PrimaryCandidates`) find the hits the whole soup gives them, and shadow
/// rays tested against their voxel's occluders only (`ShadowVoxels`) get the answer
/// the traversal would give: the film is bit-identical with and without
/// either.
#[test]
fn camera_ray_candidates_and_shadow_voxels_change_no_pixel() {
    let mut scene = cornell_box();
    scene.set_resolution(48, 40);
    let lists = scene
        .primary_candidates()
        .expect("the Cornell box gets lists");
    let (mean, full) = lists.summary();
    assert!(
        mean < 4.0 && full == 0,
        "{mean} candidates per pixel, {full} full"
    );
    let voxels = scene
        .shortcuts
        .shadow_voxels(0)
        .expect("its light gets shadow voxels");
    let (clear, listed) = voxels.summary();
    assert!(
        clear > 0.3 && listed > 0.1,
        "{clear} clear, {listed} listed"
    );
    // Seen emitters come with the lists: sampled here, so that only the
    // lists differ.
    let render = |scene| {
        film_bits(
            scene,
            PathTracer {
                exact_seen_emitters: false,
                ..PathTracer::default()
            },
        )
    };
    let with_both = render(scene.clone());
    let mut without_lists = scene.clone();
    without_lists.shortcuts = without_lists.shortcuts.without_primary_candidates();
    assert_eq!(with_both, render(without_lists));
    let mut without_voxels = scene;
    without_voxels.shortcuts = without_voxels.shortcuts.without_shadow_voxels();
    assert_eq!(with_both, render(without_voxels));
}

/// With a tent filter whose samples are splatted (drawn uniformly in their
/// pixel), camera rays still test their pixel's candidates only, and the
/// seen emission, a box filter's pixel integral, is not read: the film is
/// bit-identical to the one without lists. Were the seen emission read, the
/// light's rim would differ.
#[test]
fn splatted_samples_use_the_lists_but_not_the_seen_emission() {
    let mut scene = cornell_box();
    scene.set_resolution(48, 40);
    let mut camera = scene.camera;
    camera.filter = tracelab::filter::PixelFilter::tent();
    scene.set_camera(camera);
    let lists = scene
        .primary_candidates()
        .expect("lists with a tent filter");
    assert!(lists.pixels_with_seen_emission() > 0);
    let render = |scene| film_bits(scene, PathTracer::default());
    let mut without_lists = scene.clone();
    without_lists.shortcuts = without_lists.shortcuts.without_primary_candidates();
    assert_eq!(render(scene.clone()), render(without_lists));
    let settings = tracelab::render::RenderSettings {
        integrator: Integrator::from(PathTracer::default()),
        sampler: SamplerKind::Sobol,
        seed: 3,
        planned_spp: 16,
        threads: 2,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    let session = tracelab::render::Session::new(std::sync::Arc::new(scene.clone()), settings)
        .expect("session starts");
    let report = session.shortcut_report().join("\n");
    assert!(
        report.contains("camera rays: their pixel's candidate triangles only"),
        "{report}"
    );
    assert!(report.contains("lights seen directly: sampled"), "{report}");
}

/// A path-traced film of 16 Sobol samples (seed 3, 2 threads), as bit
/// patterns.
fn film_bits(scene: tracelab::scene::Scene, tracer: PathTracer) -> Vec<u32> {
    let integrator = Integrator::from(tracer);
    let (snapshot, _) = render_with(scene, integrator, SamplerKind::Sobol, 16, 3, 2, 16);
    snapshot
        .image
        .pixels
        .iter()
        .flat_map(|p| p.map(f32::to_bits))
        .collect()
}
