//! Discontinuity meshing (issue 39): the lines a square light and a square
//! occluder cast lie where similar triangles put them, the pieces tile the
//! receivers without straddling a line, and on the Cornell box the mesh
//! beats a uniform one of as many elements.

use glam::Vec3A;
use tracelab::integrator::radiosity::{Radiosity, RadiosityDisplay};
use tracelab::integrator::{IntegratorKind, IntegratorOptions};
use tracelab::radiosity::RadiositySolver;
use tracelab::radiosity::discontinuity::{self, Event};
use tracelab::scene::Scene;

/// The penumbra's outer and the umbra's boundary on the floor of
/// tests/data/penumbra.toml: |x| or |z| = 1.25 and 0.75.
const OUTER: f32 = 1.25;
const INNER: f32 = 0.75;

/// The coordinate (0: x, 2: z) and value of the line `ends` lies on, if
/// it lies on one of the eight.
fn line_of(ends: [Vec3A; 2]) -> Option<(usize, f32)> {
    [0, 2].into_iter().find_map(|axis| {
        let (a, b) = (ends[0][axis], ends[1][axis]);
        [-OUTER, -INNER, INNER, OUTER]
            .into_iter()
            .find(|&value| (a - value).abs() < 1e-3 && (b - value).abs() < 1e-3)
            .map(|value| (axis, value))
    })
}

#[test]
fn penumbra_lines_fall_where_similar_triangles_put_them_and_pieces_never_straddle_them() {
    let scene = Scene::load(&crate::common::repo_path("tests/data/penumbra.toml")).unwrap();
    let lines = discontinuity::find(&scene);
    let geometry = &scene.geometry;
    let on_floor = |t: usize| geometry.triangles()[t].iter().all(|v| v.y.abs() < 1e-6);
    // Per line, the intervals of the other coordinate it was traced over
    // (a VE and an EV event of these parallel squares share a plane, so
    // lines may come twice).
    let mut spans = std::collections::HashMap::new();
    for (t, segments) in lines.segments.iter().enumerate() {
        for s in segments {
            assert!(on_floor(t), "a line off the floor: {s:?}");
            assert_ne!(s.event, Event::Contact, "the occluder floats: {s:?}");
            let (axis, value) =
                line_of(s.ends).unwrap_or_else(|| panic!("a line off the eight: {s:?}"));
            let (a, b) = (s.ends[0][2 - axis], s.ends[1][2 - axis]);
            spans
                .entry((axis, value.to_bits()))
                .or_insert_with(Vec::new)
                .push((a.min(b), a.max(b)));
        }
    }
    // Each of the eight spans the outer square's side, from -1.25 to 1.25
    // (the two floor triangles' parts together), without gaps.
    assert_eq!(spans.len(), 8, "{spans:?}");
    for (line, intervals) in &mut spans {
        intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut reach = intervals[0].0;
        assert!((reach + OUTER).abs() < 0.01, "{line:?} starts at {reach}");
        for &(start, end) in intervals.iter() {
            assert!(
                start <= reach + 0.01,
                "{line:?}: a gap from {reach} to {start}"
            );
            reach = reach.max(end);
        }
        assert!((reach - OUTER).abs() < 0.01, "{line:?} ends at {reach}");
    }
    // Pieces of about 0.3 m, on either base: they tile the floor, and within
    // the outer square (where the lines run) none has corners on both sides
    // of one.
    use discontinuity::Base;
    for base in [
        Base::Delaunay { max_edge: 0.3 },
        Base::Regular {
            max_edge: 0.3,
            min_piece: 0.0,
        },
    ] {
        let (pieces, _) = discontinuity::split(&scene, &lines, Some(base));
        let mut area = 0.0;
        for (t, pieces) in pieces.iter().enumerate() {
            if !on_floor(t) {
                continue;
            }
            for p in pieces {
                let [a, b, c] = p.vertices;
                area += 0.5 * (b - a).cross(c - a).length();
                let [p0, p1, p2] = geometry.triangles()[t];
                assert!(
                    (b - a).cross(c - a).y * (p1 - p0).cross(p2 - p0).y > 0.0,
                    "a piece wound unlike its triangle: {p:?} in {:?}",
                    geometry.triangles()[t]
                );
                let centroid = (a + b + c) / 3.0;
                for axis in [0, 2] {
                    let across = 2 - axis;
                    // (Fans stop a thousandth short of the occluder's corners.)
                    if centroid[across].abs() > OUTER - 0.05 {
                        continue;
                    }
                    for value in [-OUTER, -INNER, INNER, OUTER] {
                        let sides = p.vertices.map(|v| v[axis] - value);
                        // Within 5 mm: where two lines meet, the fan's end and the
                        // merging of points a thousandth of the triangle apart leave that.
                        let straddles =
                            sides.iter().any(|&d| d > 5e-3) && sides.iter().any(|&d| d < -5e-3);
                        assert!(!straddles, "{p:?} straddles {axis} = {value}");
                    }
                }
            }
        }
        assert!(
            (area - 16.0).abs() < 1e-3,
            "{base:?}: floor pieces cover {area} m² of 16"
        );
    }
}

/// Every line of tests/data/penumbra.toml bounds a penumbra 0.5 m wide
/// (from |x| = 0.75 to 1.25: the light's 0.5 m times 1 m past the occluder
/// over 1 m before it), and a limit on the width keeps the lines of
/// narrower penumbrae only.
#[test]
fn lines_know_their_penumbras_width_and_a_limit_keeps_the_narrow_ones() {
    use discontinuity::Base;
    let scene = Scene::load(&crate::common::repo_path("tests/data/penumbra.toml")).unwrap();
    let lines = discontinuity::find(&scene);
    let all: Vec<_> = lines.segments.iter().flatten().collect();
    assert!(!all.is_empty());
    for s in &all {
        for w in s.penumbra {
            assert!((w - 0.5).abs() < 5e-3, "width {w} m, not 0.5: {s:?}");
        }
    }
    let on_line = |max_penumbra: f32| {
        let kept = lines.narrower_than(max_penumbra);
        let (pieces, _) =
            discontinuity::split(&scene, &kept, Some(Base::Delaunay { max_edge: 0.3 }));
        let flagged = pieces
            .iter()
            .flatten()
            .filter(|p| p.on_line.contains(&true))
            .count();
        (flagged, pieces.iter().map(Vec::len).sum::<usize>())
    };
    let (wide, wide_pieces) = on_line(0.51);
    let (narrow, narrow_pieces) = on_line(0.49);
    assert!(wide > 0, "no piece on a line with every line kept");
    assert_eq!(narrow, 0, "a line kept for a penumbra wider than the limit");
    assert!(
        narrow_pieces < wide_pieces,
        "{narrow_pieces} pieces without lines, {wide_pieces} with"
    );
}

/// The limit is a length, so the lines kept do not depend on the scene's
/// units: tests/data/penumbra.toml in metres, in millimetres and in units
/// of 1/1024 m, with limits on both sides of its 0.5 m penumbrae. At the
/// power of two the arithmetic is the same, and so are the pieces; at 1000
/// rounding moves the traced lines, and spade's refinement makes other
/// pieces (docs/validation.md, "Lines only where they pay").
#[test]
fn the_penumbra_limit_does_not_depend_on_the_scenes_units() {
    use discontinuity::Base;
    let input = |scale: f32| {
        let path = crate::common::repo_path("tests/data/penumbra.toml");
        let input = tracelab::scene::load::load_scene_file(&path, &Default::default()).unwrap();
        Scene::build(tracelab::stress::transform(input, scale, Vec3A::ZERO)).unwrap()
    };
    let pieces = |scene: &Scene, scale: f32, limit: f32| {
        let lines = discontinuity::find(scene).narrower_than(limit * scale);
        let base = Base::Delaunay {
            max_edge: 0.3 * scale,
        };
        let (pieces, _) = discontinuity::split(scene, &lines, Some(base));
        (lines.count(), pieces.iter().map(Vec::len).sum::<usize>())
    };
    let metres = input(1.0);
    for limit in [0.3, 0.7] {
        let a = pieces(&metres, 1.0, limit);
        let b = pieces(&input(1024.0), 1024.0, limit);
        assert_eq!(
            a, b,
            "limit {limit} m: (segments, pieces) at scales 1 and 1024"
        );
        let (segments, _) = pieces(&input(1000.0), 1000.0, limit);
        assert_eq!(segments, a.0, "limit {limit} m: segments in m and in mm");
    }
    assert_ne!(
        pieces(&metres, 1.0, 0.3),
        pieces(&metres, 1.0, 0.7),
        "the limit changed nothing"
    );
}

/// The Cornell box by Gauss–Seidel with the smooth display, as `radiosity`
/// otherwise says: the image (its mean), its elements and its masked RMSE
/// against Mitsuba's path-traced reference.
fn cornell_radiosity(radiosity: Radiosity) -> ([f64; 3], u64, f64) {
    let options = IntegratorOptions {
        radiosity: Radiosity {
            solver: RadiositySolver::GaussSeidel,
            display: RadiosityDisplay::Smooth,
            ..radiosity
        },
        ..IntegratorOptions::of(IntegratorKind::Radiosity)
    };
    let (render, stats) = crate::common::render_with(
        crate::common::cornell_box(),
        options.build(),
        tracelab::sampling::SamplerKind::Independent,
        64,
        0,
        0,
        64,
    );
    let reference = crate::common::reference("cornell_box_path_ref.exr");
    let elements = stats.solver.map(|p| p.elements).unwrap_or(0);
    let rmse = crate::radiosity::masked_rmse(&render.image, &reference);
    (render.image.mean(), elements, rmse)
}

/// Gauss–Seidel on the Cornell box at patch size 0.15, smooth display,
/// against Mitsuba's path-traced reference with the light's pixels left
/// out. Solve and display are deterministic, so the bounds are the
/// measured figures with room for rounding, not a variance: the uniform
/// mesh of 824 elements measures 0.00499; split along the shadows'
/// discontinuities first, 817 elements 0.00449 and the same mean (842 and
/// 0.00475 while the pieces under the blocks were patches).
#[test]
fn discontinuity_meshing_beats_a_uniform_mesh_of_as_many_elements_on_the_cornell_box() {
    let render = |discontinuity: bool| {
        cornell_radiosity(Radiosity {
            patch_size: 0.15,
            discontinuity,
            ..Default::default()
        })
    };
    let (_, n_uniform, uniform_rmse) = render(false);
    let (mean, n_meshed, meshed_rmse) = render(true);
    eprintln!(
        "uniform {n_uniform} elements {uniform_rmse:.5}, discontinuity {n_meshed} elements {meshed_rmse:.5}"
    );
    assert!(
        n_meshed < n_uniform * 11 / 10,
        "{n_meshed} against {n_uniform} elements"
    );
    assert!(
        meshed_rmse < 0.0046 && meshed_rmse < uniform_rmse,
        "{meshed_rmse} against {uniform_rmse}"
    );
    let expected = crate::common::reference("cornell_box_path_ref.exr").mean();
    for c in 0..3 {
        assert!(
            (mean[c] / expected[c] - 1.0).abs() < 0.01,
            "{mean:?} vs {expected:?}"
        );
    }
}

/// The indirectly lit room (scenes/indirect.toml), hierarchical ε 3e-5,
/// patch size 0.005, smooth display, against BDPT with paths up to 100
/// bounces (5 034 spp, 330 s on 16 cores: `tracelab render
/// scenes/indirect.toml --integrator bdpt --max-depth 100 --sampler sobol
/// --time 330 --threads 16`; a second of 1 416 spp agrees in the mean to
/// 0.01% and to 0.0014 RMSE, so its own noise is about 0.0007). Radiosity
/// has every bounce: the room's walls are white, and the default depth of
/// 8 leaves a reference 4–8% dark. Deterministic like the Cornell box test
/// above: without the lines 0.00283, with them 0.00203 (before dark
/// sources kept their links, 0.00580 and 0.00456: the ceiling's lit spot
/// 9% low without lines, the ceiling beside the shade dark with both).
/// The coarse end of issue 39's Must 3 (docs/validation.md): contact lines
/// only (`max_penumbra` 0), one adaptive round from patch size 0.4 at
/// tolerance 1.6, make 216 elements (the pieces under the blocks are not
/// patches); adaptive subdivision's best mesh of at most as many in the
/// grid there (patch sizes 0.15-0.5, up to two rounds, tolerances 1-4) is
/// one round from 0.35 at tolerance 4 (212 elements). Deterministic, as
/// above: the measured figures are 0.00979 against 0.01190 (18% below),
/// and the test asks for 5% below.
#[test]
fn contact_lines_alone_beat_adaptive_subdivision_at_the_coarse_end() {
    let (_, n_adaptive, adaptive_rmse) = cornell_radiosity(Radiosity {
        patch_size: 0.35,
        adaptive_rounds: 1,
        adaptive_tolerance: 4.0,
        ..Default::default()
    });
    let (_, n_meshed, meshed_rmse) = cornell_radiosity(Radiosity {
        patch_size: 0.4,
        adaptive_rounds: 1,
        adaptive_tolerance: 1.6,
        discontinuity: true,
        max_penumbra: Some(0.0),
        ..Default::default()
    });
    eprintln!(
        "adaptive {n_adaptive} elements {adaptive_rmse:.5}, contact lines {n_meshed} elements {meshed_rmse:.5}"
    );
    assert!(
        n_adaptive <= n_meshed && n_meshed <= 220,
        "{n_meshed} against {n_adaptive} elements"
    );
    assert!(
        meshed_rmse < 0.95 * adaptive_rmse,
        "{meshed_rmse} against {adaptive_rmse}"
    );
}

/// The Cornell box's blocks stand on the floor: the pieces their contact
/// lines enclose, and only those, are found hidden, and they tile the
/// footprints (the published corners, in millimetres) to within rounding.
#[test]
fn the_pieces_under_the_blocks_are_found_hidden() {
    let scene = crate::common::cornell_box();
    let lines = discontinuity::find(&scene);
    let base = discontinuity::Base::Delaunay { max_edge: 100.0 };
    let (pieces, _) = discontinuity::split(&scene, &lines, Some(base));
    let corners: Vec<Vec<[Vec3A; 3]>> = pieces
        .iter()
        .map(|p| p.iter().map(|p| p.vertices).collect())
        .collect();
    let (meshed, from) = scene.with_pieces(&corners);
    let hidden = discontinuity::enclosed(&meshed, &from, &lines);
    // Corners in (x, z), from scenes/cornell_box.obj.
    let footprints = [
        [[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]],
        [
            [423.0, 247.0],
            [265.0, 296.0],
            [314.0, 456.0],
            [472.0, 406.0],
        ],
    ];
    let inside = |p: Vec3A, quad: &[[f32; 2]; 4]| {
        let sides = (0..4).map(|i| {
            let (a, b) = (quad[i], quad[(i + 1) % 4]);
            (b[0] - a[0]) * (p.z - a[1]) - (b[1] - a[1]) * (p.x - a[0])
        });
        let signs: Vec<f32> = sides.collect();
        signs.iter().all(|&s| s > 0.0) || signs.iter().all(|&s| s < 0.0)
    };
    let quad_area = |q: &[[f32; 2]; 4]| {
        0.5 * (0..4)
            .map(|i| q[i][0] * q[(i + 1) % 4][1] - q[(i + 1) % 4][0] * q[i][1])
            .sum::<f32>()
            .abs()
    };
    let mut hidden_area = 0.0;
    for (v, &h) in meshed.geometry.triangles().iter().zip(&hidden) {
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        let on_floor = v.iter().all(|p| p.y.abs() < 1e-3);
        let under = on_floor && footprints.iter().any(|q| inside(centroid, q));
        assert_eq!(h, under, "piece {v:?}: hidden {h}, under a block {under}");
        if h {
            hidden_area += 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        }
    }
    let expected: f32 = footprints.iter().map(quad_area).sum();
    assert!(
        (hidden_area / expected - 1.0).abs() < 1e-3,
        "hidden {hidden_area} mm², footprints {expected} mm²"
    );
}

#[test]
fn discontinuity_meshing_brings_the_indirect_room_within_two_percent() {
    let reference = crate::common::reference("indirect_bdpt_deep_ref.exr");
    let render = |discontinuity| indirect_room(RadiosityDisplay::Smooth, discontinuity);
    let (plain, meshed) = (render(false), render(true));
    let plain_rmse = crate::radiosity::masked_rmse(&plain, &reference);
    let meshed_rmse = crate::radiosity::masked_rmse(&meshed, &reference);
    let (mean, expected) = (meshed.mean(), reference.mean());
    eprintln!(
        "indirect room: plain {plain_rmse:.5}, discontinuity {meshed_rmse:.5}, mean {mean:?} vs {expected:?}"
    );
    // Issue 39's goal: half of 0.00580 (the figure before either change).
    assert!(plain_rmse < 0.0029, "{plain_rmse}");
    assert!(
        meshed_rmse < 0.0022 && meshed_rmse < plain_rmse,
        "{meshed_rmse} against {plain_rmse}"
    );
    for c in 0..3 {
        assert!(
            (mean[c] / expected[c] - 1.0).abs() < 0.02,
            "{mean:?} vs {expected:?}"
        );
    }
}

/// The gather display on the indirect room (discontinuity meshing,
/// hierarchical ε 3e-5, 16 samples per pixel, seed 0) samples the
/// solution's bright elements as well as cosine directions: masked RMSE
/// 0.0234 against the deep reference, where cosine rays alone measured
/// 0.110 (the ceiling's spot, which lights the room, is rarely met by
/// chance). An image's RMSE over 76 000 pixels varies little between seeds,
/// so 0.035 fails the cosine-only gather by a wide margin; the mean within
/// 2% (measured 1.002, 1.003, 1.004) fails a mis-weighted combination.
#[test]
fn the_gather_samples_the_solutions_bright_elements() {
    let reference = crate::common::reference("indirect_bdpt_deep_ref.exr");
    let image = indirect_room(RadiosityDisplay::Gather, true);
    let rmse = crate::radiosity::masked_rmse(&image, &reference);
    let (mean, expected) = (image.mean(), reference.mean());
    eprintln!("gather: masked RMSE {rmse:.4}, mean {mean:?} vs {expected:?}");
    assert!(rmse < 0.035, "{rmse}");
    for c in 0..3 {
        assert!(
            (mean[c] / expected[c] - 1.0).abs() < 0.02,
            "{mean:?} vs {expected:?}"
        );
    }
}

/// scenes/indirect.toml solved by hierarchical radiosity (ε 3e-5, patch
/// size 0.005) to convergence and shown with `display`.
fn indirect_room(display: RadiosityDisplay, discontinuity: bool) -> tracelab::image::Image {
    let scene = Scene::load(&crate::common::repo_path("scenes/indirect.toml")).unwrap();
    let options = IntegratorOptions {
        radiosity: tracelab::integrator::radiosity::Radiosity {
            solver: RadiositySolver::Hierarchical,
            epsilon: 3e-5,
            patch_size: 0.005,
            display,
            discontinuity,
            ..Default::default()
        },
        ..IntegratorOptions::of(IntegratorKind::Radiosity)
    };
    // A solver's pass is a step; once converged, passes add display samples.
    let (snapshot, stats) = crate::common::render_with(
        scene,
        options.build(),
        tracelab::sampling::SamplerKind::Independent,
        64,
        0,
        0,
        64,
    );
    assert!(
        stats.solver.is_some_and(|p| p.converged),
        "{:?}",
        stats.solver
    );
    snapshot.image
}
