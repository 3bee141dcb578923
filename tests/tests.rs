//! Integration tests, linked as one binary. Statistical tests use fixed seeds
//! and tolerances derived from the estimator's own variance; each says how.

mod common;

// Agreement with the Mitsuba 3 reference renders in tests/data.
mod reference;
// Each material model against Mitsuba 3 renders of the same scene.
mod material_references;
// Veach's scenes from Bitterli's Mitsuba files against Mitsuba 3 and Tungsten.
mod bitterli;
// Samples splatted through the pixel filter: errors as stated, and lower.
mod filtered_film;
// Mitsuba XML, PLY and serialized import: every element, every error.
mod import;
// A mesh without triangles, a -D the file never reads, an empty image: never silent.
mod import_silence;
// Blends of two BSDFs against the weighted sum of their parts.
mod import_blends;
// Mitsuba 3's principled BSDF against its own eval.
mod principled;
// Textured lights: sampled and hit where their texture says, in every technique.
mod emission_textures;
// Mitsuba sensors: the clips the importer does not apply are warnings.
mod import_sensor;
// What a shape gets where the file leaves its BSDF out.
mod import_defaults;
// What Mitsuba 3's documentation scenes use: textured roughness, references.
mod import_mitsuba_docs;
// White furnace: closed sphere with known radiance Le / (1 - albedo).
mod furnace;
// Chi-square goodness of fit of every sampling routine against its pdf.
mod chi2;
// The same for the rough models, the thin dielectric and the environment map.
mod chi2_rough;
// The Monte Carlo lab's experiments meet their closed-form statements.
mod lab;
// Form factors between squares and discs against closed forms; reciprocity.
mod form_factors;
// Radiosity: a closed box against its closed form at any scale, the Cornell box.
mod radiosity;
// Radiosity with clusters on a mesh of 100 000 triangles against path tracing.
mod clusters;
// Discontinuity meshing: penumbra lines where similar triangles put them.
mod discontinuity;
// BSDF energy conservation, reciprocity and sample/eval/pdf consistency.
mod bsdf;
// Whitted by hand, MC ray tracing's ray count.
mod estimators;
// Ambient occlusion of a plane and of a floor before a wall.
mod ambient_occlusion;
// NEE on/off and MIS variants converge to the same image.
mod strategies;
// Bidirectional path tracing: strategy images, agreement, a wrong weight caught.
mod bidirectional;
// Microfacet, plastic, conductor and thin glass models in every technique.
mod materials;
// A textured, normal-mapped glTF asset: path tracing and BDPT agree.
mod gltf_assets;
// Opacity masks in every technique and importer.
mod masks;
// Same seed, same film, whatever the thread count or pass split.
mod determinism;
// Motion blur: a moving occluder against a case solved by hand.
mod motion;
// Replaying samples, flagging extreme ones, clamping.
mod diagnostics;
// Robust ray offsets at every scale; a fixed epsilon fails.
mod stress;
// Every scene in scenes/ renders without non-finite samples.
mod scenes;
// Inputs that once crashed the fuzz targets.
mod fuzz_regressions;
// The command line: renders, comparisons and every kind of bad input.
mod cli;
// The command line of the lab, radiosity, BDPT's strategies and photon mapping.
mod cli_techniques;
// The viewer driven through egui_kittest (needs the default `viewer` feature).
#[cfg(feature = "viewer")]
mod viewer;
