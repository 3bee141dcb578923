//! Inputs the fuzz targets (fuzz/, see the README) once crashed on, replayed
//! the way each target feeds them: each must now load to a scene or fail
//! with an error naming a file, never panic.

use crate::common::{repo_path, temp_dir};
use tracelab::scene::load::{load_any, load_scene_file, parse_scene};
use tracelab::scene::{Limits, LoadOptions, Scene};

fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = repo_path(&format!("tests/data/fuzz/{target}"));
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| {
                    let path = e.unwrap().path();
                    (path.display().to_string(), std::fs::read(&path).unwrap())
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn check(name: &str, result: tracelab::Result<tracelab::scene::SceneInput>) {
    match result {
        Ok(input) => {
            let _ = Scene::build(input);
        }
        Err(e) => {
            let message = e.to_string();
            assert!(
                [".obj", ".mtl", ".toml", ".ply", ".xml"]
                    .iter()
                    .any(|f| message.contains(f)),
                "{name}: the error names no file: {message}"
            );
        }
    }
}

#[test]
fn obj_mtl_crashes_stay_fixed() {
    let marker = b"\n#MTL\n";
    let dir = temp_dir("fuzz-obj");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "[camera]\neye = [0, 1, 4]\nlook_at = [0, 0, 0]\nfov_y = 40\nwidth = 4\nheight = 4\n\n[[mesh]]\nfile = \"mesh.obj\"\n",
    )
    .unwrap();
    let cases = inputs("obj_mtl");
    assert!(cases.len() >= 5, "only {} cases", cases.len());
    for (name, data) in cases {
        let (obj, mtl) = match data.windows(marker.len()).position(|w| w == marker) {
            Some(i) => (&data[..i], &data[i + marker.len()..]),
            None => (&data[..], &[][..]),
        };
        std::fs::write(dir.join("mesh.obj"), obj).unwrap();
        std::fs::write(dir.join("mesh.mtl"), mtl).unwrap();
        check(&name, load_scene_file(&scene, &Limits::default()));
    }
}

/// The scene_toml target has not crashed (docs/validation.md); its
/// directory holds the edge cases its checks guard (coordinates past 1e15,
/// NaN and infinite fields, impossible cameras, unknown references, broken
/// syntax), replayed the way the target feeds them.
#[test]
fn scene_toml_crashes_stay_fixed() {
    let path = repo_path("scenes/fuzz.toml");
    let cases = inputs("scene_toml");
    let mut checked = 0;
    for (name, data) in &cases {
        let text = String::from_utf8_lossy(data);
        check(name, parse_scene(&path, &text, &Limits::default()));
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} cases ran");
}

/// The ply target's finds, loaded as bare meshes as the target loads them.
/// A header that declares an element twice once made the reader push
/// empty elements until memory ran out: every count is now checked
/// against the file's size first.
#[test]
fn ply_crashes_stay_fixed() {
    let cases = inputs("ply");
    assert!(!cases.is_empty());
    let dir = temp_dir("fuzz-ply");
    for (name, data) in cases {
        let path = dir.join("mesh.ply");
        std::fs::write(&path, data).unwrap();
        check(&name, load_any(&path, &LoadOptions::default()));
    }
}
