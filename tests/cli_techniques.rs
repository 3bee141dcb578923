//! The command line of the techniques and tools beyond rendering: the Monte
//! Carlo lab, radiosity's report, BDPT's strategy images and the photon
//! mappers' settings; clear messages and exit codes for bad input.

use crate::cli::{CAMERA, assert_fails, scene_dir, stderr, tracelab};
use crate::common::{repo_path, temp_dir};

#[test]
fn lab_prints_tables_writes_csv_and_plots_and_refuses_bad_names() {
    let dir = temp_dir("lab-cli");
    let csv = dir.join("coins.csv");
    let plot = dir.join("coins.svg");
    let o = tracelab(&[
        "lab",
        "coins",
        "--runs",
        "2000",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("0.187500") && out.contains("[holds]"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("table,n,exact,"), "{text}");
    // 11 rows (n = 1 ... 1024) and the header.
    assert_eq!(text.lines().count(), 12);
    assert!(std::fs::read_to_string(&plot).unwrap().starts_with("<svg"));
    // A bad plot name is refused before any work; an unknown experiment too.
    let o = tracelab(&["lab", "coins", "--plot", "x.jpg"]);
    assert_fails(&o, 1, &["x.jpg", ".svg or .png"]);
    let o = tracelab(&["lab", "point-sets", "--n", "1000000"]);
    assert_fails(&o, 1, &["O(N^2)", "65536"]);
    let o = tracelab(&["lab", "pi", "--runs", "0"]);
    assert_fails(&o, 1, &["at least 1"]);
    let o = tracelab(&["lab", "dice"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("point-sets"));
}

#[test]
fn radiosity_reports_rows_and_refuses_bad_input() {
    let dir = temp_dir("radiosity-cli");
    let csv = dir.join("rows.csv");
    let o = tracelab(&[
        "radiosity",
        repo_path("scenes/cornell_box.toml").to_str().unwrap(),
        "--reference",
        repo_path("tests/data/cornell_box_path_ref.exr")
            .to_str()
            .unwrap(),
        "--patch-size",
        "0.3",
        "--ff-rays",
        "4",
        "--display",
        "smooth",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = std::fs::read_to_string(&csv).unwrap();
    assert!(rows.starts_with("steps,elements,links,"), "{rows}");
    // Gauss-Seidel converges in a few sweeps; each row's masked RMSE is a number.
    let last = rows.lines().last().unwrap();
    let masked: f64 = last.rsplit(',').next().unwrap().parse().unwrap();
    assert!(masked > 0.0 && masked < 0.05, "{last}");
    // A scene without diffuse emitters, a patch size out of range.
    let dark = scene_dir(
        "radiosity-dark",
        &[(
            "dark.toml",
            &format!(
                "{CAMERA}[materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
                 [[quad]]\ncorner = [-1, 0, -1]\nu = [2, 0, 0]\nv = [0, 0, 2]\nmaterial = \"white\"\n"
            ),
        )],
    );
    let o = tracelab(&[
        "render",
        dark.join("dark.toml").to_str().unwrap(),
        "--integrator",
        "radiosity",
        "--out",
        dark.join("x.exr").to_str().unwrap(),
    ]);
    assert_fails(&o, 1, &["emissive"]);
    let o = tracelab(&[
        "render",
        repo_path("scenes/cornell_box.toml").to_str().unwrap(),
        "--integrator",
        "radiosity",
        "--patch-size",
        "0",
        "--out",
        dark.join("y.exr").to_str().unwrap(),
    ]);
    assert_fails(&o, 1, &["patch size"]);
}

/// A sweep prints one converged row per value and the slope of links
/// against elements, writes them and the plot, and refuses what it cannot do.
#[test]
fn radiosity_sweeps_report_the_scaling_of_links() {
    let dir = temp_dir("radiosity-sweep");
    let (csv, plot) = (dir.join("sweep.csv"), dir.join("links.svg"));
    let scene = repo_path("scenes/cornell_box.toml");
    let reference = repo_path("tests/data/cornell_box_path_ref.exr");
    let base = [
        "radiosity",
        scene.to_str().unwrap(),
        "--reference",
        reference.to_str().unwrap(),
        "--display",
        "flat",
    ];
    let with = |extra: &[&str]| {
        let mut all = base.to_vec();
        all.extend_from_slice(extra);
        tracelab(&all)
    };
    let o = with(&[
        "--solver",
        "hierarchical",
        "--patch-size",
        "0.05",
        "--sweep-epsilon",
        "1e-3,3e-4",
        "--sweep-patch-size",
        "0.2,0.1",
        "--csv",
        csv.to_str().unwrap(),
        "--scaling-plot",
        plot.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("over the epsilon sweep") && out.contains("over the patch size sweep"),
        "{out}"
    );
    let rows = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = rows.lines().collect();
    assert_eq!(lines.len(), 5, "{rows}");
    assert!(
        lines[1].starts_with("epsilon,0.001,") && lines[4].starts_with("patch size,0.1,"),
        "{rows}"
    );
    // A smaller epsilon and a smaller patch size both refine: more elements.
    let elements = |line: &str| line.split(',').nth(3).unwrap().parse::<u64>().unwrap();
    assert!(
        elements(lines[2]) > elements(lines[1]) && elements(lines[4]) > elements(lines[3]),
        "{rows}"
    );
    assert!(
        std::fs::read_to_string(&plot)
            .unwrap()
            .contains("links against elements")
    );
    assert_fails(
        &with(&["--sweep-epsilon", "1e-3"]),
        1,
        &["needs --solver hierarchical"],
    );
    assert_fails(
        &with(&["--sweep-patch-size", "0"]),
        1,
        &["--sweep-patch-size values"],
    );
    assert_fails(
        &with(&["--scaling-plot", plot.to_str().unwrap()]),
        1,
        &["--scaling-plot needs"],
    );
}

#[test]
fn bidirectional_and_photon_settings_are_checked() {
    let scene = repo_path("scenes/cornell_box.toml");
    let s = scene.to_str().unwrap();
    let dir = temp_dir("cli-strategies");
    let strategies = dir.join("pyramid");
    assert_fails(
        &tracelab(&["render", s, "--strategies", strategies.to_str().unwrap()]),
        1,
        &["--strategies needs --integrator bdpt"],
    );
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "photon",
            "--k",
            "0",
            "--out",
            "x.exr",
        ]),
        1,
        &["k 0 is not in 1..=256"],
    );
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "sppm",
            "--alpha",
            "1.5",
            "--out",
            "x.exr",
        ]),
        1,
        &["alpha 1.5 is not in (0, 1]"],
    );
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "sppm",
            "--radius",
            "0",
            "--out",
            "x.exr",
        ]),
        1,
        &["radius 0 is not a fraction"],
    );
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "vcm",
            "--alpha",
            "0",
            "--out",
            "x.exr",
        ]),
        1,
        &["alpha 0 is not in (0, 1]"],
    );
    // A flag whose setting the technique does not have is refused, not
    // silently dropped.
    assert_fails(
        &tracelab(&[
            "render",
            s,
            "--integrator",
            "light",
            "--shadow-rays",
            "2",
            "--out",
            "x.exr",
        ]),
        1,
        &["--shadow-rays or --glossy-rays is not a setting of light"],
    );
    // The viewer takes the same flags, with --integrator; alone, a
    // setting would silently change nothing it shows.
    #[cfg(feature = "viewer")]
    assert_fails(
        &tracelab(&["view", "--max-depth", "3"]),
        1,
        &["the viewer takes a technique's settings with --integrator"],
    );
    let vcm = dir.join("vcm.exr");
    let o = tracelab(&[
        "render",
        s,
        "--integrator",
        "vcm",
        "--spp",
        "2",
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        vcm.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(vcm.is_file());
    // The pyramid: every strategy of up to 2 bounces and the sheets.
    let o = tracelab(&[
        "render",
        s,
        "--integrator",
        "bdpt",
        "--max-depth",
        "2",
        "--spp",
        "1",
        "--width",
        "16",
        "--height",
        "16",
        "--strategies",
        strategies.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for file in [
        "s0_t2.exr",
        "s2_t2_unweighted.exr",
        "s3_t1.exr",
        "sum.exr",
        "strategies_weighted.png",
    ] {
        assert!(strategies.join(file).is_file(), "{file} missing");
    }
}
