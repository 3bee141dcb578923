//! The `tracelab` binary: renders, comparisons, and a clear message with a
//! non-zero exit for every kind of bad input (never a panic).

use crate::common::{TempDir, repo_path, temp_dir};
use std::path::Path;
use std::process::{Command, Output, Stdio};

pub(crate) fn tracelab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .output()
        .expect("binary runs")
}

pub(crate) fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a failed run with `code` whose stderr contains every `needle`.
pub(crate) fn assert_fails(o: &Output, code: i32, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    for n in needles {
        assert!(err.contains(n), "expected `{n}` in: {err}");
    }
}

pub(crate) const CAMERA: &str =
    "[camera]\neye = [0, 1, -3]\nlook_at = [0, 1, 0]\nfov_y = 40\nwidth = 16\nheight = 16\n";

/// Writes `files` into a fresh directory and returns the directory.
pub(crate) fn scene_dir(name: &str, files: &[(&str, &str)]) -> TempDir {
    let dir = temp_dir(name);
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

fn render_scene(dir: &Path, extra: &[&str]) -> Output {
    let scene = dir.join("scene.toml");
    let out = dir.join("out.exr");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "2",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    tracelab(&args)
}

const MESH_SCENE: &str = "[camera]\neye = [0, 1, -3]\nlook_at = [0, 1, 0]\nfov_y = 40\nwidth = 16\nheight = 16\n\n[[mesh]]\nfile = \"mesh.obj\"\n";

#[test]
fn renders_the_cornell_box_and_compares_images() {
    let dir = temp_dir("cli-render");
    let exr = dir.join("cb.exr");
    let png = dir.join("cb.png");
    let scene = repo_path("scenes/cornell_box.toml");
    let o = tracelab(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "--width",
        "32",
        "--height",
        "32",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(
        summary.starts_with("spp 4 |")
            && summary.contains("non-finite 0")
            && summary.contains("M paths/s"),
        "{summary}"
    );
    let o = tracelab(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "--width",
        "32",
        "--height",
        "32",
        "--sampler",
        "stratified",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(image::open(&png).unwrap().width() == 32);

    // Samples spread by noise after 2 spp: the summary gives the spread.
    let o = tracelab(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "8",
        "--width",
        "32",
        "--height",
        "32",
        "--sampler",
        "sobol",
        "--distribute",
        "2",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("samples spread by noise after 2 spp; per pixel "),
        "{}",
        stderr(&o)
    );
    assert_fails(
        &tracelab(&[
            "render",
            scene.to_str().unwrap(),
            "--adaptive",
            "0.1",
            "--distribute",
            "2",
        ]),
        2,
        &["--distribute"],
    );

    let o = tracelab(&["compare", exr.to_str().unwrap(), exr.to_str().unwrap()]);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.starts_with("RMSE 0.000000 | relative MSE 0.000000 | mean relative error 0.000000"),
        "{out}"
    );
    assert!(
        out.contains("| RMSE without the worst 0.1% of pixels 0.000000"),
        "{out}"
    );
    // Different sizes and missing files are errors, not panics.
    let reference = repo_path("tests/data/cornell_box_path_ref.exr");
    assert_fails(
        &tracelab(&[
            "compare",
            exr.to_str().unwrap(),
            reference.to_str().unwrap(),
        ]),
        1,
        &["images differ in size: 32x32 vs 256x256"],
    );
    assert_fails(
        &tracelab(&["compare", "nowhere.exr", exr.to_str().unwrap()]),
        1,
        &["nowhere.exr", "cannot read image"],
    );
    let garbage = dir.join("garbage.exr");
    std::fs::write(&garbage, "not an image").unwrap();
    assert_fails(
        &tracelab(&["compare", garbage.to_str().unwrap(), exr.to_str().unwrap()]),
        1,
        &["garbage.exr"],
    );
}

#[test]
fn malformed_toml_names_file_and_line() {
    let dir = scene_dir(
        "cli-toml",
        &[(
            "scene.toml",
            "[camera]\neye == [0, 1, -3]\nlook_at = [0, 0, 0]\n",
        )],
    );
    assert_fails(&render_scene(&dir, &[]), 1, &["scene.toml:2:"]);
}

#[test]
fn unknown_keys_are_rejected_with_their_line() {
    let text = format!("{CAMERA}colour = \"red\"\n");
    let dir = scene_dir("cli-unknown-key", &[("scene.toml", &text)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["scene.toml:7:", "unknown field `colour`"],
    );
    let text = format!("{CAMERA}\n[materials.glass]\ntype = \"dielectric\"\nalbedo = [1, 1, 1]\n");
    let dir = scene_dir("cli-wrong-field", &[("scene.toml", &text)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["scene.toml:8:", "field `albedo` does not apply"],
    );
}

#[test]
fn unknown_material_names_the_entry() {
    let text =
        format!("{CAMERA}\n[[sphere]]\ncenter = [0, 1, 0]\nradius = 0.5\nmaterial = \"gold\"\n");
    let dir = scene_dir("cli-material", &[("scene.toml", &text)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["scene.toml:8:", "unknown material `gold`"],
    );
}

#[test]
fn bad_camera_values_are_explained() {
    let text = CAMERA.replace("fov_y = 40", "fov_y = 400");
    let dir = scene_dir("cli-fov", &[("scene.toml", &text)]);
    assert_fails(&render_scene(&dir, &[]), 1, &["scene.toml:1:", "fov_y"]);
}

#[test]
fn non_finite_obj_vertex_names_the_line() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 nan 1\nf 1 2 3\n";
    let dir = scene_dir("cli-nan", &[("scene.toml", MESH_SCENE), ("mesh.obj", obj)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["mesh.obj:3: vertex coordinate `nan` is not finite"],
    );
    let obj = "v 0 0 0\nv 1 0 inf\nv 0 1 1\nf 1 2 3\n";
    let dir = scene_dir("cli-inf", &[("scene.toml", MESH_SCENE), ("mesh.obj", obj)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["mesh.obj:2: vertex coordinate `inf` is not finite"],
    );
}

#[test]
fn out_of_range_face_index_names_the_line() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 1\n\nf 1 2 9\n";
    let dir = scene_dir("cli-face", &[("scene.toml", MESH_SCENE), ("mesh.obj", obj)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["mesh.obj:5: face vertex index 9 is out of range"],
    );
}

#[test]
fn texture_and_normal_indices_are_checked_too() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/-3 3/1\n";
    let dir = scene_dir(
        "cli-bad-vt",
        &[("scene.toml", MESH_SCENE), ("mesh.obj", obj)],
    );
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["mesh.obj:5: face texture coordinate index -3 is out of range: 1 defined so far"],
    );
}

#[test]
fn missing_obj_and_mtl_are_named() {
    let dir = scene_dir("cli-missing-obj", &[("scene.toml", MESH_SCENE)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["scene.toml:8:", "mesh file `mesh.obj` not found"],
    );
    let obj = "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 1\nf 1 2 3\n";
    let dir = scene_dir(
        "cli-missing-mtl",
        &[("scene.toml", MESH_SCENE), ("mesh.obj", obj)],
    );
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["mesh.obj:1: material library `gone.mtl` not found"],
    );
    assert_fails(
        &tracelab(&["render", "no/such/scene.toml", "--out", "x.exr"]),
        1,
        &["no/such/scene.toml", "cannot read scene file"],
    );
}

#[test]
fn unknown_integrator_or_sampler_is_a_usage_error() {
    let scene = repo_path("scenes/cornell_box.toml");
    let s = scene.to_str().unwrap();
    assert_fails(
        &tracelab(&["render", s, "--integrator", "magic", "--out", "x.exr"]),
        2,
        &["invalid value 'magic'", "path"],
    );
    assert_fails(
        &tracelab(&["render", s, "--sampler", "perfect", "--out", "x.exr"]),
        2,
        &["invalid value 'perfect'", "stratified"],
    );
}

#[test]
fn absurd_resolutions_are_refused() {
    let scene = repo_path("scenes/cornell_box.toml");
    let dir = temp_dir("cli-res");
    let out = dir.join("x.exr");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    assert_fails(
        &tracelab(&["render", s, "--width", "0", "--out", o]),
        1,
        &["resolution 0x256 is outside 1..=16384"],
    );
    assert_fails(
        &tracelab(&["render", s, "--width", "1000000", "--out", o]),
        1,
        &["resolution 1000000x256 is outside"],
    );
    let text = CAMERA.replace("width = 16", "width = 0");
    let dir = scene_dir("cli-res-scene", &[("scene.toml", &text)]);
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["scene.toml:1:", "resolution 0x16"],
    );
    assert!(!out.exists());
}

#[test]
fn unwritable_output_fails_before_rendering() {
    let scene = repo_path("scenes/cornell_box.toml");
    let s = scene.to_str().unwrap();
    assert_fails(
        &tracelab(&["render", s, "--out", "/nonexistent-dir/x.exr"]),
        1,
        &["/nonexistent-dir/x.exr", "cannot write output"],
    );
    assert_fails(
        &tracelab(&["render", s, "--out", "x.jpg"]),
        1,
        &["x.jpg", "must end in .exr"],
    );
}

#[test]
fn degenerate_triangles_and_zero_area_emitters_are_dropped_with_a_count() {
    let mtl = "newmtl lamp\nKd 0 0 0\nKe 5 5 5\nnewmtl white\nKd 0.5 0.5 0.5\n";
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n\
               usemtl white\nf 1 2 3\nf 1 2 4\n\
               usemtl lamp\nf 1 1 3\nf 2 3 3\n";
    let dir = scene_dir(
        "cli-degenerate",
        &[
            ("scene.toml", MESH_SCENE),
            ("mesh.obj", obj),
            ("m.mtl", mtl),
        ],
    );
    let o = render_scene(&dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning:")
            && stderr(&o).contains("dropped 3 degenerate triangle(s) of 4"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("no light source"), "{}", stderr(&o));
}

#[test]
fn unreadable_reference_images_are_named() {
    let dir = temp_dir("cli-bad-reference");
    let garbage = dir.join("reference.exr");
    std::fs::write(&garbage, "not an EXR").unwrap();
    let scene = repo_path("scenes/cornell_box.toml");
    assert_fails(
        &tracelab(&[
            "bench",
            scene.to_str().unwrap(),
            "--reference",
            garbage.to_str().unwrap(),
            "--config",
            "path:independent",
            "--max-spp",
            "1",
        ]),
        1,
        &["reference.exr"],
    );
}

#[test]
fn bench_plots_are_png_or_svg_by_extension() {
    let dir = temp_dir("cli-bench-plots");
    let scene = repo_path("scenes/cornell_box.toml");
    let reference = repo_path("tests/data/cornell_box_path_ref.exr");
    let (png, svg) = (dir.join("rmse.png"), dir.join("rmse.svg"));
    let bench = |plot: &Path, plot_time: &Path| {
        tracelab(&[
            "bench",
            scene.to_str().unwrap(),
            "--reference",
            reference.to_str().unwrap(),
            "--config",
            "path:sobol",
            "--max-spp",
            "2",
            "--plot",
            plot.to_str().unwrap(),
            "--plot-time",
            plot_time.to_str().unwrap(),
        ])
    };
    let o = bench(&png, &svg);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"), "a PNG, not SVG text");
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    // Another extension fails before any rendering, naming the file.
    let jpg = dir.join("rmse.jpg");
    let o = bench(&jpg, &svg);
    assert_fails(&o, 1, &["rmse.jpg", ".svg or .png"]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains("measuring"));
    assert!(!jpg.exists());
}

#[test]
fn malformed_mtl_statements_name_file_and_line() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    let mtl = "newmtl a\nKs 0.1 0.1 0.1\nKd 0.5\n";
    let dir = scene_dir(
        "cli-bad-mtl",
        &[
            ("scene.toml", MESH_SCENE),
            ("mesh.obj", obj),
            ("m.mtl", mtl),
        ],
    );
    assert_fails(
        &render_scene(&dir, &[]),
        1,
        &["m.mtl:3:", "`Kd` needs three finite numbers"],
    );
}

#[test]
fn typo_guards_refuse_runaway_renders() {
    let scene = repo_path("scenes/cornell_box.toml");
    let s = scene.to_str().unwrap();
    assert_fails(
        &tracelab(&["render", s, "--spp", "100000000", "--out", "x.exr"]),
        1,
        &["--spp 100000000 is above the limit", "--max-spp"],
    );
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "mcrt",
            "--glossy-rays",
            "5",
            "--max-depth",
            "20",
            "--out",
            "x.exr",
        ]),
        1,
        &["rays per sample", "--max-branch-rays"],
    );
    assert_fails(
        &tracelab(&["render", s, "--offset", "fixed:-1", "--out", "x.exr"]),
        2,
        &["fixed:EPS"],
    );
    assert_fails(
        &tracelab(&["render", s, "--debug-sample", "1,2", "--spp", "1"]),
        2,
        &["X,Y,S"],
    );
}

#[test]
fn debug_sample_prints_the_path() {
    let scene = repo_path("scenes/cornell_box.toml");
    let o = tracelab(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "--debug-sample",
        "128,200,3",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.contains("pixel (128, 200) sample 3"), "{out}");
    assert!(out.contains("vertex 0:"), "{out}");
    assert!(out.contains("sample value"), "{out}");
    assert_fails(
        &tracelab(&[
            "render",
            scene.to_str().unwrap(),
            "--debug-sample",
            "999,0,0",
        ]),
        1,
        &["outside the 256x256 image"],
    );
}

#[test]
fn stress_command_passes_robust_and_fails_fixed_epsilon() {
    let o = tracelab(&["stress", "--quick"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}{out}", stderr(&o));
    assert!(out.contains("cornell box scaled by 1e-4"), "{out}");
    assert!(!out.contains("FAIL"), "{out}");
    let o = tracelab(&["stress", "--quick", "--offset", "fixed:1e-3"]);
    assert_fails(&o, 1, &["stress cases failed"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("FAIL"));
}

/// The summary says which small-scene shortcuts apply, and why the others
/// do not.
#[test]
fn the_summary_says_which_shortcuts_apply_and_why_not() {
    let dir = temp_dir("cli-shortcuts");
    let out = dir.join("x.exr");
    let render = |scene: &str, extra: &[&str]| {
        let scene = repo_path(scene);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--spp",
            "1",
            "--width",
            "24",
            "--height",
            "24",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = tracelab(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let cornell = render("scenes/cornell_box.toml", &[]);
    assert!(
        cornell.contains("camera rays: their pixel's candidate triangles only"),
        "{cornell}"
    );
    assert!(
        cornell.contains("lights seen directly: integrated exactly over"),
        "{cornell}"
    );
    assert!(
        cornell.contains("shadow rays to light 0: no test from"),
        "{cornell}"
    );
    let spheres = render("scenes/materials.toml", &[]);
    assert!(
        spheres.contains("lights seen directly: sampled (the scene has spheres)")
            && spheres.contains("camera rays: the whole scene (the scene has spheres)"),
        "{spheres}"
    );
    let off = render("scenes/cornell_box.toml", &["--seen-emitters", "sampled"]);
    assert!(
        off.contains("lights seen directly: sampled (switched off)"),
        "{off}"
    );
}

/// Output piped into a reader that stops early (`tracelab compare a b |
/// head -1`) ends the process quietly: the print after the reader left
/// panicked ("failed printing to stdout: Broken pipe").
#[test]
fn output_into_a_pipe_closed_early_is_not_a_panic() {
    let exr = repo_path("tests/data/cornell_box_direct_ref.exr");
    let exr = exr.to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(["compare", exr, exr])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    // The reader is gone before the comparison (two EXR files) is printed.
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("binary ends");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
}
