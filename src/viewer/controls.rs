//! Each technique's controls, one function per settings struct: the
//! viewer's side of the settings that each technique owns in its own file.

use crate::integrator::ambient_occlusion::AoSettings;
use crate::integrator::bdpt::{BdptSettings, MAX_BOUNCES, MAX_LIGHT_PATHS};
use crate::integrator::light::LightSettings;
use crate::integrator::mcrt::McrtSettings;
use crate::integrator::path::PathSettings;
use crate::integrator::photon::PhotonSettings;
use crate::integrator::radiosity::{Radiosity, RadiosityDisplay};
use crate::integrator::sppm::SppmSettings;
use crate::integrator::vcm::VcmSettings;
use crate::integrator::whitted::WhittedSettings;
use crate::integrator::{
    GlassShadows, IntegratorKind, IntegratorOptions, MisHeuristic, PathLength, Strategy,
};
use crate::radiosity::{FormFactorMethod, RadiositySolver};
use crate::scene::UNBOUNDED_DEPTH;
use eframe::egui::{self, RichText};

/// The chosen technique's controls; `merge_scale` (pixels per unit of a
/// radius given as a fraction of the diagonal, and the frame's width)
/// shows a merge radius in pixels.
pub fn technique(
    ui: &mut egui::Ui,
    options: &mut IntegratorOptions,
    merge_scale: Option<(f32, u32)>,
) {
    match options.kind {
        IntegratorKind::Whitted => whitted(ui, &mut options.whitted),
        IntegratorKind::Mcrt => mcrt(ui, &mut options.mcrt),
        IntegratorKind::Path => path(ui, &mut options.path),
        IntegratorKind::AmbientOcclusion => ambient_occlusion(ui, &mut options.ao),
        IntegratorKind::Light => light(ui, &mut options.light),
        IntegratorKind::Bdpt => bdpt(ui, &mut options.bdpt),
        IntegratorKind::Photon => photon(ui, &mut options.photon),
        IntegratorKind::Sppm => sppm(ui, &mut options.sppm, merge_scale),
        IntegratorKind::Vcm => vcm(ui, &mut options.vcm, merge_scale),
        IntegratorKind::Radiosity => radiosity(ui, &mut options.radiosity),
    }
}

fn whitted(ui: &mut egui::Ui, s: &mut WhittedSettings) {
    ui.add(slider(&mut s.max_depth, 0..=32).text("Max specular depth"));
    ui.add(slider(&mut s.ambient, 0.0..=0.5).text("Ambient"));
    ui.horizontal(|ui| {
        ui.label("Glass shadows");
        ui.radio_value(&mut s.glass_shadows, GlassShadows::Opaque, "Opaque");
        ui.radio_value(&mut s.glass_shadows, GlassShadows::Tinted, "Tinted");
    });
}

fn mcrt(ui: &mut egui::Ui, s: &mut McrtSettings) {
    max_depth(ui, &mut s.max_depth);
    ui.add(slider(&mut s.shadow_rays, 0..=16).text("Shadow rays N"));
    ui.add(slider(&mut s.glossy_rays, 0..=16).text("Glossy rays M"));
    if s.shadow_rays + s.glossy_rays == 0 {
        s.shadow_rays = 1;
    }
    mis_heuristic(ui, &mut s.mis);
    seen_emitters(ui, &mut s.exact_seen_emitters);
    let rays = u64::from(s.glossy_rays).pow(s.max_depth.clamp(1, 17) - 1);
    if rays > 100_000 {
        ui.label(
            RichText::new(format!("M^(D-1) = {rays} rays per sample: slow"))
                .color(egui::Color32::YELLOW),
        );
    }
}

fn path(ui: &mut egui::Ui, s: &mut PathSettings) {
    unbounded_max_depth(ui, &mut s.length);
    ui.horizontal(|ui| {
        ui.label("Strategy");
        ui.radio_value(&mut s.strategy, Strategy::Bsdf, "BSDF");
        ui.radio_value(&mut s.strategy, Strategy::Light, "Light");
        ui.radio_value(&mut s.strategy, Strategy::Mis, "MIS");
    });
    if s.strategy == Strategy::Mis {
        mis_heuristic(ui, &mut s.mis);
    }
    roulette(ui, &mut s.length);
    seen_emitters(ui, &mut s.exact_seen_emitters);
}

fn ambient_occlusion(ui: &mut egui::Ui, s: &mut AoSettings) {
    let mut limited = s.distance > 0.0;
    ui.checkbox(&mut limited, "Distance limit")
        .on_hover_text("Occluders farther than this fraction of the scene's size do not count");
    if !limited {
        s.distance = 0.0;
    } else {
        if s.distance == 0.0 {
            s.distance = 0.1;
        }
        ui.add(
            slider(&mut s.distance, 0.001..=1.0)
                .logarithmic(true)
                .text("Distance (of the scene's diagonal)"),
        );
    }
}

fn light(ui: &mut egui::Ui, s: &mut LightSettings) {
    unbounded_max_depth(ui, &mut s.length);
    roulette(ui, &mut s.length);
}

fn bdpt(ui: &mut egui::Ui, s: &mut BdptSettings) {
    max_depth(ui, &mut s.length.max_depth);
    mis_heuristic(ui, &mut s.mis);
    roulette(ui, &mut s.length);
    ui.add(
        slider(&mut s.light_paths, 1..=MAX_LIGHT_PATHS)
            .text("Light paths per sample (the others for light tracing only)"),
    );
    if s.light_paths > 1 {
        ui.add(slider(&mut s.light_path_bounces, 0..=MAX_BOUNCES).text("Their bounces"));
    }
}

fn photon(ui: &mut egui::Ui, s: &mut PhotonSettings) {
    max_depth(ui, &mut s.max_depth);
    ui.add(
        slider(&mut s.photons, 0..=4_000_000)
            .logarithmic(true)
            .text("Photons per map (0: one per pixel)"),
    );
    ui.add(slider(&mut s.k, 1..=256).text("k (photons per estimate)"));
    ui.add(
        slider(&mut s.gather_radius, 1e-3..=0.2)
            .logarithmic(true)
            .text("Largest radius (of the scene's diagonal)"),
    );
}

fn sppm(ui: &mut egui::Ui, s: &mut SppmSettings, merge_scale: Option<(f32, u32)>) {
    max_depth(ui, &mut s.max_depth);
    ui.add(
        slider(&mut s.photons, 0..=4_000_000)
            .logarithmic(true)
            .text("Photons per iteration (0: one per pixel)"),
    );
    merge_radius(ui, &mut s.radius, &mut s.alpha, merge_scale);
}

fn vcm(ui: &mut egui::Ui, s: &mut VcmSettings, merge_scale: Option<(f32, u32)>) {
    unbounded_max_depth(ui, &mut s.length);
    mis_heuristic(ui, &mut s.mis);
    roulette(ui, &mut s.length);
    merge_radius(ui, &mut s.radius, &mut s.alpha, merge_scale);
}

fn radiosity(ui: &mut egui::Ui, s: &mut Radiosity) {
    ui.horizontal(|ui| {
        ui.label("Solver");
        for solver in RadiositySolver::ALL {
            ui.radio_value(&mut s.solver, solver, solver.name());
        }
    });
    if s.solver == RadiositySolver::Progressive {
        ui.checkbox(&mut s.ambient, "Ambient term");
    }
    if s.solver == RadiositySolver::Hierarchical {
        ui.add(
            slider(&mut s.epsilon, 1e-7..=1e-2)
                .logarithmic(true)
                .text("Epsilon (share of the emitted power)"),
        );
    }
    ui.add(
        // Hierarchical: the smallest element, which goes well below the
        // matrix solvers' sizes (the Cornell box runs use 0.002).
        slider(&mut s.patch_size, 0.001..=0.5)
            .logarithmic(true)
            .text("Patch size (of the scene's diagonal)"),
    );
    if s.solver != RadiositySolver::Hierarchical {
        ui.add(slider(&mut s.adaptive_rounds, 0..=4).text("Adaptive subdivision rounds"));
        if s.adaptive_rounds > 0 {
            ui.add(
                slider(&mut s.adaptive_tolerance, 0.05..=2.0)
                    .logarithmic(true)
                    .text("Tolerance (of the mean)"),
            );
            ui.add(
                slider(&mut s.adaptive_min_angle, 0.0..=30.0)
                    .text("Leave elements with angles under (°) whole"),
            )
            .on_hover_text(
                "Their four children would be as thin: 20° leaves the slivers beside \
                 discontinuity lines whole, which pays at coarse meshes",
            );
        }
    }
    ui.checkbox(&mut s.wireframe, "Wireframe (colour by level)");
    ui.checkbox(
        &mut s.discontinuity,
        "Discontinuity meshing (lines in cyan)",
    )
    .on_hover_text(
        "Split receivers along the umbra and penumbra boundaries of polygonal lights \
             before meshing, so that no element straddles a shadow's edge",
    );
    if s.discontinuity && s.solver != RadiositySolver::Hierarchical {
        ui.checkbox(&mut s.lines_on_regular_mesh, "Lines on the regular mesh")
            .on_hover_text(
                "Keep the elements of the mesh without lines and split only those a line \
                 crosses (better at fine meshes); off: every receiver meshed by Delaunay \
                 refinement (fewer pieces at coarse ones)",
            );
        if s.lines_on_regular_mesh {
            ui.add(
                slider(&mut s.min_piece_area, 0.0..=0.2).text("Smallest piece (of its element)"),
            )
            .on_hover_text(
                "An element that a line crosses stays whole where a piece would be \
                     smaller than this fraction of its area: fewer slivers, which pays at \
                     coarse meshes",
            );
        }
        let mut some = s.max_penumbra.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut some, "Only narrow penumbrae")
                .on_hover_text(
                    "Keep a penumbra's boundary lines only where it is narrower than this many \
                     patch sizes (contact lines are always kept): fewer lines, fewer pieces, \
                     which pays at coarse meshes",
                );
            if some {
                let mut m = s.max_penumbra.unwrap_or(0.5);
                ui.add(egui::Slider::new(&mut m, 0.0..=4.0).text("patch sizes"));
                s.max_penumbra = Some(m);
            } else {
                s.max_penumbra = None;
            }
        });
    }
    ui.horizontal(|ui| {
        ui.label("Form factors");
        let before = s.form_factors;
        ui.radio_value(
            &mut s.form_factors,
            FormFactorMethod::Analytic,
            "Contour integral",
        );
        ui.radio_value(
            &mut s.form_factors,
            FormFactorMethod::RayCast,
            "Ray casting",
        );
        // Each method starts from the count at which it is accurate.
        if s.form_factors != before {
            s.form_factor_samples = s.form_factors.default_samples();
        }
    });
    ui.horizontal(|ui| {
        ui.label("Display");
        for display in RadiosityDisplay::ALL {
            ui.radio_value(&mut s.display, display, display.name());
        }
    });
    ui.add(
        slider(&mut s.form_factor_samples, 1..=1024)
            .logarithmic(true)
            .text("Samples per pair"),
    );
}

/// A slider that leaves a value from a scene file or the command line as
/// it is, even beyond the range its bar spans (edits stay within it): egui
/// clamps every value to that range by default, which turned a file's
/// depth of 100 into 32 without a word.
fn slider<Num: egui::emath::Numeric>(
    value: &mut Num,
    range: std::ops::RangeInclusive<Num>,
) -> egui::Slider<'_> {
    egui::Slider::new(value, range).clamping(egui::SliderClamping::Edits)
}

fn max_depth(ui: &mut egui::Ui, depth: &mut u32) {
    ui.add(slider(depth, 0..=32).text("Max depth (bounces)"));
}

/// The depth of a technique that Russian roulette can end, which may have
/// no limit (Mitsuba's -1); roulette stays on while it has none.
fn unbounded_max_depth(ui: &mut egui::Ui, length: &mut PathLength) {
    let mut unbounded = length.max_depth == UNBOUNDED_DEPTH;
    ui.horizontal(|ui| {
        if unbounded {
            ui.label("Max depth: no limit");
        } else {
            max_depth(ui, &mut length.max_depth);
        }
        let toggled = ui
            .checkbox(&mut unbounded, "No limit")
            .on_hover_text("Paths end by Russian roulette only, as Mitsuba's max_depth -1")
            .changed();
        if toggled {
            length.max_depth = if unbounded {
                UNBOUNDED_DEPTH
            } else {
                PathLength::default().max_depth
            };
        }
    });
    if unbounded {
        length.russian_roulette = true;
    }
}

fn mis_heuristic(ui: &mut egui::Ui, mis: &mut MisHeuristic) {
    if *mis == MisHeuristic::None {
        *mis = MisHeuristic::Power;
    }
    ui.horizontal(|ui| {
        ui.label("MIS");
        ui.radio_value(mis, MisHeuristic::Balance, "Balance");
        ui.radio_value(mis, MisHeuristic::Power, "Power");
    });
}

fn roulette(ui: &mut egui::Ui, length: &mut PathLength) {
    ui.horizontal(|ui| {
        let bounded = length.max_depth != UNBOUNDED_DEPTH;
        ui.add_enabled(
            bounded,
            egui::Checkbox::new(&mut length.russian_roulette, "Russian roulette"),
        )
        .on_disabled_hover_text("Without a depth limit, roulette ends the paths");
        if length.russian_roulette {
            ui.add(
                egui::DragValue::new(&mut length.rr_depth)
                    .range(0..=64)
                    .prefix("from "),
            );
        }
    });
}

fn seen_emitters(ui: &mut egui::Ui, exact: &mut bool) {
    ui.checkbox(exact, "Lights seen directly: exact per pixel")
        .on_hover_text(
            "A light seen through a pixel adds its exact share of the pixel's area \
             instead of being hit or missed by each camera ray: no noise on its rim",
        );
}

fn merge_radius(
    ui: &mut egui::Ui,
    radius: &mut f32,
    alpha: &mut f32,
    merge_scale: Option<(f32, u32)>,
) {
    ui.add(
        slider(radius, 1e-5..=0.05)
            .logarithmic(true)
            .text("First radius (of the scene's diagonal)"),
    );
    // The same words as the CLI's summary; a radius wider than an eighth
    // of the frame blurs what is in view (a narrow spot lost 96%).
    if let Some((per_unit, width)) = merge_scale {
        let pixels = *radius * per_unit;
        let said = crate::integrator::photon_map::describe_radius_in_pixels(width, Some(pixels));
        let text = said
            .trim()
            .trim_start_matches('(')
            .trim_end_matches(')')
            .replace("--radius", "radius");
        let wide = pixels > width as f32 / 8.0;
        ui.label(match wide {
            true => RichText::new(text).color(ui.visuals().warn_fg_color),
            false => RichText::new(text).weak(),
        });
    }
    ui.add(slider(alpha, 0.05..=1.0).text("Alpha (1: fixed radius, biased)"));
}
