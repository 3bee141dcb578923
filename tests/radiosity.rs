//! Radiosity against closed forms: a closed box of uniform emission and
//! reflectance (L = E / (1 - ρ) exactly, since its form factor rows sum to
//! 1), the same box in millimetres, metres and kilometres, the bad inputs,
//! and the Cornell box against photons, the peer and Mitsuba.

use crate::common::temp_dir;
use glam::Vec3A;
use tracelab::integrator::radiosity::{MAX_ELEMENTS, Radiosity};
use tracelab::integrator::{IntegratorKind, IntegratorOptions, Solver};
use tracelab::math::Rgb;
use tracelab::radiosity::{Element, Mesh, RadiositySolver};
use tracelab::scene::Scene;

/// A closed cube of side `scale` whose six walls all emit `emission` and
/// reflect `albedo`, normals inwards, seen from inside.
fn closed_box(scale: f32, name: &str) -> Scene {
    let s = scale;
    let faces = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, s], [s, 0.0, 0.0]),
        ([0.0, s, 0.0], [s, 0.0, 0.0], [0.0, 0.0, s]),
        ([0.0, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]),
        ([s, 0.0, 0.0], [0.0, 0.0, s], [0.0, s, 0.0]),
        ([0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0]),
        ([0.0, 0.0, s], [0.0, s, 0.0], [s, 0.0, 0.0]),
    ];
    let mut text = format!(
        "[camera]\neye = [{h}, {h}, {e}]\nlook_at = [{h}, {h}, {s}]\nfov_y = 60\nwidth = 8\nheight = 8\n\n\
         [materials.wall]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\nemission = [1.0, 1.0, 1.0]\n\n",
        h = 0.5 * s,
        e = 0.1 * s,
    );
    for (corner, u, v) in faces {
        text.push_str(&format!(
            "[[quad]]\ncorner = {corner:?}\nu = {u:?}\nv = {v:?}\nmaterial = \"wall\"\n\n"
        ));
    }
    let dir = temp_dir(name);
    let path = dir.join("box.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).expect("the box loads")
}

fn radiosity(solver: RadiositySolver, patch_size: f32) -> Radiosity {
    Radiosity {
        solver,
        patch_size,
        ambient: false,
        ..Radiosity::default()
    }
}

#[test]
fn a_closed_box_reaches_e_over_one_minus_rho_with_every_solver_at_any_scale() {
    let mut previous: Option<Vec<Rgb>> = None;
    for (k, scale) in [1e-3f32, 1.0, 1e3].into_iter().enumerate() {
        let scene = closed_box(scale, &format!("radiosity-box-{k}"));
        for solver in RadiositySolver::ALL {
            // The hierarchy refines down to 1/20 of the diagonal.
            let size = if solver == RadiositySolver::Hierarchical {
                0.05
            } else {
                0.3
            };
            let mut technique = radiosity(solver, size);
            if solver == RadiositySolver::Hierarchical {
                // Every wall emits, so every link carries light: the 0.1%
                // per leaf takes epsilon 2e-6 (460 884 links, 94% of the
                // leaves' full matrix; measured worst leaf 0.015% off, 0.075%
                // at 4e-6 with 385 896 links, 1.2% at 1e-5).
                technique.epsilon = 2e-6;
            }
            let mut state = technique.init(&scene).expect("meshes");
            if let Some(m) = state.matrix() {
                // Row sums of a closed box are 1: the contour integral tiles the hemisphere.
                for i in 0..m.mesh.elements.len() {
                    let sum: f32 = m.form_factors.row(i).iter().sum();
                    assert!((sum - 1.0).abs() < 1e-3, "row {i}: {sum}");
                }
            }
            let mut counts = Default::default();
            let progress = technique.step(&scene, &mut state, 100_000, &mut counts);
            assert!(progress.converged, "{solver:?}");
            let radiance: Vec<Rgb> = match state.matrix() {
                Some(m) => m.solution.radiance.clone(),
                None => {
                    let h = state.hierarchy().unwrap();
                    let (leaves, links) = h.counts();
                    // Refined: more leaves than the 12 patches.
                    assert!(leaves > 12, "{leaves} leaves, {links} links");
                    // Each leaf gathers through its own links and its
                    // ancestors', whose form factors are averages over the
                    // ancestors: how close single leaves come depends on
                    // epsilon (above); the area-weighted mean is right at any.
                    let (mut sum, mut area, mut worst) = (0.0f64, 0.0f64, 0.0f32);
                    for (e, l) in h.leaves() {
                        sum += (l.x * e.area) as f64;
                        area += e.area as f64;
                        worst = worst.max((l.x - 2.0).abs());
                    }
                    let mean = sum / area;
                    eprintln!(
                        "hierarchical, scale {scale}: {leaves} leaves, {links} links, mean {mean:.5}, worst leaf off by {worst:.4}"
                    );
                    assert!((mean - 2.0).abs() < 2e-3, "mean {mean}");
                    assert!(worst < 2e-3, "worst leaf {worst}");
                    continue;
                }
            };
            for l in &radiance {
                // E / (1 - ρ) = 2 within 0.1%; the residual stops at 1e-6 of the emitted power.
                assert!((l.x - 2.0).abs() < 2e-3, "{solver:?} at scale {scale}: {l}");
            }
            if solver == RadiositySolver::GaussSeidel {
                if let Some(p) = &previous {
                    for (a, b) in p.iter().zip(&radiance) {
                        assert!((a.x - b.x).abs() < 1e-4 * 2.0, "units changed the solution");
                    }
                }
                previous = Some(radiance.clone());
            }
        }
    }
}

#[test]
fn radiosity_refuses_what_it_cannot_solve() {
    let scene = closed_box(1.0, "radiosity-refusals");
    // Too fine a mesh for the form factor matrix: refused with the count.
    let e = Mesh::build(&scene, 1e-4, MAX_ELEMENTS, &[]).unwrap_err();
    assert!(e.contains("elements") && e.contains("--patch-size"), "{e}");
    let e = Mesh::build(&scene, 0.0, MAX_ELEMENTS, &[]).unwrap_err();
    assert!(e.contains("positive"), "{e}");
    // No emitter: the materials scene's lights are a quad (diffuse) ... so
    // build one without: the box with its emission removed.
    let mut dark = scene.clone();
    for m in &mut dark.materials {
        m.emission = Rgb::ZERO;
    }
    let e = Mesh::build(&dark, 0.3, MAX_ELEMENTS, &[]).unwrap_err();
    assert!(e.contains("emissive"), "{e}");
}

#[test]
fn the_ambient_term_shows_the_converged_level_early() {
    // In a uniform closed box, Cohen's ambient term makes the displayed
    // radiance E/(1 - ρ) = 2 exact before any shot, and the area-weighted
    // mean stays close after a few (the unshot light is what the term
    // spreads evenly); without it the display starts at E = 1 and three
    // shots of the twelve patches (triangles) raise it by about 3/12 ρ.
    let scene = closed_box(1.0, "radiosity-ambient");
    for ambient in [false, true] {
        let mut technique = radiosity(RadiositySolver::Progressive, 0.3);
        technique.ambient = ambient;
        let mut state = technique.init(&scene).unwrap();
        let mut counts = Default::default();
        technique.step(&scene, &mut state, 3, &mut counts);
        let m = state.matrix().unwrap();
        let s = &m.solution;
        let (mut sum, mut area) = (0.0f64, 0.0f64);
        for (l, e) in s.radiance.iter().zip(&m.mesh.elements) {
            sum += (l.x + e.reflectance.x * s.ambient.x) as f64 * e.area as f64;
            area += e.area as f64;
        }
        let mean = sum / area;
        eprintln!("ambient {ambient}: mean displayed radiance after 3 shots {mean:.4}");
        if ambient {
            assert!((mean - 2.0).abs() < 0.02, "{mean}");
        } else {
            assert!(mean < 1.2, "{mean}");
        }
    }
}

/// The walls of the Cornell box, in the peer's table's order.
const CORNELL_WALLS: [&str; 7] = [
    "floor",
    "ceiling",
    "back",
    "red wall",
    "green wall",
    "short block",
    "tall block",
];

/// Which wall a scene triangle of the Cornell box (millimetres, y up) lies on.
fn cornell_wall(v: [Vec3A; 3]) -> usize {
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    let top = v.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    let centroid = (v[0] + v[1] + v[2]) / 3.0;
    match () {
        _ if n.y > 0.99 && top < 1.0 => 0,
        _ if n.y < -0.99 && centroid.y > 548.0 => 1,
        _ if n.z < -0.99 && centroid.z > 559.0 => 2,
        _ if centroid.x > 549.0 => 3,
        _ if centroid.x < 1.0 => 4,
        _ if top < 166.0 => 5,
        _ => 6,
    }
}

/// Area-weighted mean radiance of each wall of the Cornell box.
fn wall_means(scene: &Scene, elements: &[(Element, Rgb)]) -> Vec<Rgb> {
    let triangles = scene.geometry.triangles();
    let mut sums = vec![(Rgb::ZERO, 0.0f32); CORNELL_WALLS.len()];
    for (e, l) in elements.iter().filter(|(e, _)| e.emission == Rgb::ZERO) {
        let s = &mut sums[cornell_wall(triangles[e.triangle as usize])];
        s.0 += e.area * *l;
        s.1 += e.area;
    }
    sums.iter().map(|(sum, area)| *sum / *area).collect()
}

/// The same means by an independent estimator: photons shot from the light
/// and followed until roulette ends them (no bounce limit in practice); a
/// wall's mean radiance is ρ times the power arriving on it over π times its
/// area. Which wall a photon lies on follows from its point and normal.
fn photon_wall_means(scene: &Scene, photons: u32, key: u64, max_bounces: u32) -> Vec<Rgb> {
    let mut areas = vec![0.0f32; CORNELL_WALLS.len()];
    let mut albedo = vec![Rgb::ZERO; CORNELL_WALLS.len()];
    for (i, v) in scene.geometry.triangles().iter().enumerate() {
        let material = &scene.materials[scene.geometry.triangle_material(i) as usize];
        if material.emission != Rgb::ZERO {
            continue;
        }
        let wall = cornell_wall(*v);
        areas[wall] += 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        if let tracelab::scene::material::Bsdf::Diffuse { albedo: a } = material.bsdf {
            albedo[wall] = a;
        }
    }
    let mut counts = Default::default();
    let (landed, _) = tracelab::integrator::photon_map::shoot(
        scene,
        photons,
        key,
        max_bounces,
        |_| (true, false),
        &mut counts,
    );
    let mut power = vec![Rgb::ZERO; CORNELL_WALLS.len()];
    for p in &landed {
        let (x, n) = (p.point, p.normal);
        let wall = match () {
            _ if n.y > 0.99 && x.y < 1.0 => 0,
            _ if n.y < -0.99 && x.y > 548.0 => 1,
            _ if n.z < -0.99 && x.z > 559.0 => 2,
            _ if n.x < -0.99 && x.x > 540.0 => 3,
            _ if n.x > 0.99 && x.x < 1.0 => 4,
            // The blocks: the nearer of their centres (in x, z).
            _ if (x.x - 186.0).powi(2) + (x.z - 169.0).powi(2)
                < (x.x - 368.0).powi(2) + (x.z - 351.0).powi(2) =>
            {
                5
            }
            _ => 6,
        };
        power[wall] += p.power;
    }
    (0..CORNELL_WALLS.len())
        .map(|w| albedo[w] * power[w] / (photons as f32 * std::f32::consts::PI * areas[w]))
        .collect()
}

#[test]
fn cornell_wall_means_agree_with_photons_and_the_peer() {
    let scene = Scene::load(std::path::Path::new("scenes/cornell_box.toml")).unwrap();
    // Eight independent batches: their spread gives each mean's standard error.
    const BATCHES: usize = 8;
    let batches: Vec<Vec<Rgb>> = (0..BATCHES as u64)
        .map(|key| photon_wall_means(&scene, 200_000, key, 7))
        .collect();
    let photons: Vec<Rgb> = (0..CORNELL_WALLS.len())
        .map(|w| batches.iter().map(|b| b[w]).sum::<Rgb>() / BATCHES as f32)
        .collect();
    let standard_error: Vec<Rgb> = (0..CORNELL_WALLS.len())
        .map(|w| {
            let m = photons[w];
            let var = batches.iter().map(|b| (b[w] - m) * (b[w] - m)).sum::<Rgb>()
                / (BATCHES * (BATCHES - 1)) as f32;
            Rgb::new(var.x.sqrt(), var.y.sqrt(), var.z.sqrt())
        })
        .collect();
    // RenderPark (rpkCpp, hierarchical Galerkin, epsilon 1e-7), from the issue.
    let peer = [
        [0.1093, 0.0730, 0.0199],
        [0.0957, 0.0573, 0.0135],
        [0.1663, 0.1095, 0.0297],
        [0.1385, 0.0093, 0.0021],
        [0.0347, 0.0755, 0.0046],
        [0.1091, 0.0783, 0.0203],
        [0.1571, 0.0941, 0.0263],
    ];
    // Like the peer's and the photons' light, eight Jacobi sweeps from L = E
    // hold eight bounces.
    let mut technique = radiosity(RadiositySolver::Jacobi, 0.1);
    technique.iterations = 8;
    let mut state = technique.init(&scene).unwrap();
    let mut counts = Default::default();
    technique.step(&scene, &mut state, 100, &mut counts);
    let solved = wall_means(&scene, &state.elements());
    for (w, name) in CORNELL_WALLS.iter().enumerate() {
        let (s, p, r) = (solved[w], photons[w], peer[w]);
        eprintln!(
            "{name:>12}: Jacobi x 8 {:.4} {:.4} {:.4} | photons {:.4} {:.4} {:.4} (s.e. {:.2}%) | peer {:.4} {:.4} {:.4}",
            s.x,
            s.y,
            s.z,
            p.x,
            p.y,
            p.z,
            100.0 * standard_error[w].x / p.x,
            r[0],
            r[1],
            r[2]
        );
        for c in 0..3 {
            if r[c] < 0.005 {
                continue; // two or three significant digits only
            }
            // Photons and peer agree within 0.4% (measured; the photons'
            // standard error is 0.1-0.3%, 1% is over 3 of them). The
            // uniform mesh of patch size 0.1 measures within 0.3% of the
            // photons and 0.4% of the peer; it was 1.2% short on the short
            // block before elements sent from their open part only (the
            // floor around a block averaged in the dark under it).
            assert!(
                (p[c] / r[c] - 1.0).abs() < 0.01,
                "{name}: photons {p} vs peer {r:?}"
            );
            assert!(
                (s[c] / p[c] - 1.0).abs() < 0.01,
                "{name}: solved {s} vs photons {p}"
            );
            assert!(
                (s[c] / r[c] - 1.0).abs() < 0.01,
                "{name}: solved {s} vs peer {r:?}"
            );
        }
    }
}

/// Hierarchical radiosity against Mitsuba's path-traced Cornell box, as the
/// issue measured the peer: the smooth display at 16 rays per pixel, the
/// pixels that see the light (reference above 1) left out. Solve and display
/// are deterministic (fixed seeds, any thread count), so the bounds are the
/// measured figures with room for rounding, not a variance: ε 3e-5 measures
/// masked RMSE 0.00173 (the goal 0.0022) and a mean 0.1% low; the
/// bound 0.0020 fails the solver before exposure (0.00218) and a display
/// that gathers vertices of partly hidden leaves from inside the hidden part
/// (0.00210).
#[test]
fn hierarchical_radiosity_matches_mitsuba_on_the_cornell_box() {
    // One pass of up to 64 steps: the solve converges in 22.
    let (snapshot, stats) = hierarchical_cornell_box(3e-5, 64);
    assert!(
        stats.solver.is_some_and(|p| p.converged),
        "{:?}",
        stats.solver
    );
    let image = snapshot.image;
    let reference = crate::common::reference("cornell_box_path_ref.exr");
    let masked = masked_rmse(&image, &reference);
    let (mean, expected) = (image.mean(), reference.mean());
    eprintln!("hierarchical ε 3e-5: masked RMSE {masked:.5}, mean {mean:?} vs {expected:?}");
    assert!(masked < 0.0020, "masked RMSE {masked}");
    for c in 0..3 {
        assert!(
            (mean[c] / expected[c] - 1.0).abs() < 0.01,
            "{mean:?} vs {expected:?}"
        );
    }
}

/// RMSE over the pixels whose reference stays at or below 1 in every
/// channel: all but the 444 that see the light.
pub fn masked_rmse(image: &tracelab::image::Image, reference: &tracelab::image::Image) -> f64 {
    let (mut squared, mut kept) = (0.0f64, 0usize);
    for (p, r) in image.pixels.iter().zip(&reference.pixels) {
        if r.iter().all(|&v| v <= 1.0) {
            squared += (0..3).map(|c| ((p[c] - r[c]) as f64).powi(2)).sum::<f64>() / 3.0;
            kept += 1;
        }
    }
    (squared / kept as f64).sqrt()
}

/// One step of hierarchical radiosity is direct light: against Mitsuba's
/// direct-only Cornell box (the goal 0.0021, the peer's figure with
/// 1 304 leaves). Deterministic like the test above; ε 1e-4 measures 0.00132.
/// The corner pixel the light covers 5.5% of (reference 0.945) took 0.0026
/// of RMSE on its own when the display sampled the light's edge instead of
/// adding the pixel's exact share of it, so the bound fails that display.
#[test]
fn one_hierarchical_step_matches_mitsuba_direct_light() {
    let (snapshot, stats) = hierarchical_cornell_box(1e-4, 1);
    assert_eq!(stats.solver.map(|p| p.steps), Some(1));
    let reference = crate::common::reference("cornell_box_direct_ref.exr");
    let masked = masked_rmse(&snapshot.image, &reference);
    eprintln!("hierarchical ε 1e-4, one step: masked RMSE {masked:.5}");
    assert!(masked < 0.0021, "masked RMSE {masked}");
}

/// The Cornell box by hierarchical radiosity (patch size 0.005, smooth
/// display), one pass of up to `steps` steps.
fn hierarchical_cornell_box(
    epsilon: f32,
    steps: u32,
) -> (tracelab::film::FilmSnapshot, tracelab::render::RenderStats) {
    let options = IntegratorOptions {
        radiosity: Radiosity {
            solver: RadiositySolver::Hierarchical,
            epsilon,
            patch_size: 0.005,
            display: tracelab::integrator::radiosity::RadiosityDisplay::Smooth,
            ..Radiosity::default()
        },
        ..IntegratorOptions::of(IntegratorKind::Radiosity)
    };
    crate::common::render_with(
        crate::common::cornell_box(),
        options.build(),
        tracelab::sampling::SamplerKind::Independent,
        steps,
        0,
        0,
        steps,
    )
}

/// A lamp facing up under a panel facing down; the camera above the panel
/// or below it, looking at it.
fn lit_panel(twin: bool, camera_above: bool, name: &str) -> Scene {
    let (eye, look_at) = if camera_above {
        ([0.0, 3.0, 0.01], [0.0, 0.0, 0.0])
    } else {
        ([0.0, 0.2, 0.01], [0.0, 1.0, 0.0])
    };
    let mut text = format!(
        "[camera]\neye = {eye:?}\nlook_at = {look_at:?}\nfov_y = 20\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
         [materials.lamp]\ntype = \"diffuse\"\nalbedo = [0.0, 0.0, 0.0]\nemission = [4.0, 4.0, 4.0]\n\n\
         [[quad]]\ncorner = [-0.25, 0.0, -0.25]\nu = [0.0, 0.0, 0.5]\nv = [0.5, 0.0, 0.0]\nmaterial = \"lamp\"\n\n"
    );
    // The twin (facing up) first: of equal hits the first stored wins.
    if twin {
        text.push_str(
            "[[quad]]\ncorner = [-0.5, 1.0, -0.5]\nu = [0.0, 0.0, 1.0]\nv = [1.0, 0.0, 0.0]\nmaterial = \"white\"\n\n",
        );
    }
    text.push_str(
        "[[quad]]\ncorner = [-0.5, 1.0, -0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 0.0, 1.0]\nmaterial = \"white\"\n",
    );
    let dir = temp_dir(name);
    let path = dir.join("panel.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).expect("the panel loads")
}

/// Patches are one-sided. Seen from behind, a thin panel lit on its front
/// must not show its front's light (path tracing finds none there: nothing
/// lights its top; the display showed 0.14 before it gathered there), and of
/// two coincident quads facing apart the one facing the camera is shown,
/// whichever the ray met.
#[test]
fn radiosity_shows_a_thin_panel_from_either_side() {
    let image = |scene: Scene| {
        let options = IntegratorOptions {
            radiosity: Radiosity {
                solver: RadiositySolver::Hierarchical,
                epsilon: 1e-4,
                patch_size: 0.05,
                display: tracelab::integrator::radiosity::RadiosityDisplay::Smooth,
                ..Radiosity::default()
            },
            ..IntegratorOptions::of(IntegratorKind::Radiosity)
        };
        crate::common::render_with(
            scene,
            options.build(),
            tracelab::sampling::SamplerKind::Independent,
            16,
            0,
            0,
            16,
        )
        .0
        .image
    };
    let top = image(lit_panel(false, true, "panel-top"));
    let brightest = top.pixels.iter().flatten().fold(0.0f32, |m, &v| m.max(v));
    assert!(brightest < 1e-6, "the panel's unlit top shows {brightest}");
    // From below the panel fills the view: its lit face, E ρ F about 0.14.
    let lit = image(lit_panel(false, false, "panel-below"));
    let twins = image(lit_panel(true, false, "panel-twins"));
    eprintln!(
        "panel from below: {:?}, with its twin quad {:?}",
        lit.mean(),
        twins.mean()
    );
    assert!(lit.mean()[0] > 0.1, "{:?}", lit.mean());
    // The same solution pixel by pixel, whichever quad a ray met. Gathering
    // where a ray met the twin from behind is right only on average: its
    // noise moved pixels by up to 1.4% (the mean by 0.6%).
    let worst = lit
        .pixels
        .iter()
        .zip(&twins.pixels)
        .map(|(a, b)| (a[0] - b[0]).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "pixels differ by up to {worst}");
}

/// A lamp on a floor, facing up, under a thin panel whose front faces up:
/// the lamp lights the panel's back, which lights the floor. Seen from the
/// side, the floor beside the lamp gets all its light from that back.
fn panel_over_lamp(name: &str) -> Scene {
    let text = "[camera]\neye = [1.8, 0.6, 0.0]\nlook_at = [1.0, 0.0, 0.0]\nfov_y = 20\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
         [materials.lamp]\ntype = \"diffuse\"\nalbedo = [0.0, 0.0, 0.0]\nemission = [4.0, 4.0, 4.0]\n\n\
         [[quad]]\ncorner = [-2.0, -0.001, -2.0]\nu = [0.0, 0.0, 4.0]\nv = [4.0, 0.0, 0.0]\nmaterial = \"white\"\n\n\
         [[quad]]\ncorner = [-0.25, 0.0, -0.25]\nu = [0.0, 0.0, 0.5]\nv = [0.5, 0.0, 0.0]\nmaterial = \"lamp\"\n\n\
         [[quad]]\ncorner = [-0.5, 1.0, -0.5]\nu = [0.0, 0.0, 1.0]\nv = [1.0, 0.0, 0.0]\nmaterial = \"white\"\n";
    let dir = temp_dir(name);
    let path = dir.join("panel.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).expect("the scene loads")
}

/// The back of a thin surface lit from behind is a patch of its own: the
/// floor it lights agrees with path tracing (one-sided patches left it
/// black). Path tracing's image mean at 4 096 Sobol samples per pixel moves
/// by 0.1% between seeds; measured, Gauss–Seidel (patch 0.05) is within
/// 0.1% of it and the hierarchy (ε 1e-5, patch 0.02) 0.6% above. 6% is the
/// mesh's error allowed (constant elements on a floor lit by a 1 m panel).
#[test]
fn the_back_of_a_thin_surface_reflects_light() {
    let scene = panel_over_lamp("panel-over-lamp");
    let two_sided = tracelab::radiosity::mesh::exposed_backs(&scene);
    // The floor's back sees nothing, the lamp emits one way, the panel's
    // back sees the floor around the lamp.
    assert_eq!(two_sided, [false, false, false, false, true, true]);
    let render = |options: IntegratorOptions, spp, seed| {
        crate::common::render_with(
            scene.clone(),
            options.build(),
            tracelab::sampling::SamplerKind::Sobol,
            spp,
            seed,
            0,
            spp,
        )
        .0
        .image
        .mean()[0]
    };
    let path = render(IntegratorOptions::default(), 4096, 0);
    for (solver, patch_size) in [
        (RadiositySolver::GaussSeidel, 0.05),
        (RadiositySolver::Hierarchical, 0.02),
    ] {
        let options = IntegratorOptions {
            radiosity: Radiosity {
                solver,
                epsilon: 1e-5,
                patch_size,
                display: tracelab::integrator::radiosity::RadiosityDisplay::Smooth,
                ..Radiosity::default()
            },
            ..IntegratorOptions::of(IntegratorKind::Radiosity)
        };
        let radiosity = render(options, 16, 0);
        eprintln!(
            "floor lit by the panel's back: {solver:?} {radiosity:.5}, path tracing {path:.5}"
        );
        assert!(
            (radiosity / path - 1.0).abs() < 0.06,
            "{solver:?}: {radiosity} against {path}"
        );
    }
}
