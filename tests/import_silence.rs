//! What a user asked for and did not get is never silent: a mesh file
//! without triangles, a `-D` that the file never reads; an image of 0
//! bytes is called empty, not a decoder's riddle.

use crate::common::temp_dir;
use crate::import::{SENSOR, load, write_assets};
use tracelab::scene::{LoadOptions, Scene};

/// A mesh file without a face: a bare mesh is an error (nothing to render),
/// a scene's mesh a warning naming file and line; neither is silent.
#[test]
fn a_mesh_without_triangles_is_never_silent() {
    let dir = temp_dir("empty-mesh");
    write_assets(&dir);
    let e = Scene::load_with(&dir.join("empty.obj"), &LoadOptions::default())
        .expect_err("a bare mesh without triangles");
    assert!(e.to_string().contains("empty.obj: no triangles"), "{e}");
    let toml = dir.join("scene.toml");
    std::fs::write(
        &toml,
        "[camera]\neye = [0, 1, -3]\nlook_at = [0, 1, 0]\nfov_y = 40\nwidth = 4\nheight = 4\n\n\
         [[mesh]]\nfile = \"empty.obj\"\n\n[[point_light]]\nposition = [0, 2, 0]\nintensity = [1, 1, 1]\n",
    )
    .unwrap();
    let scene = Scene::load_with(&toml, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let w = scene.warnings.join("\n");
    assert!(
        w.contains("scene.toml:8: mesh file `empty.obj` holds no triangles"),
        "{w}"
    );
}

/// A `-D` the file never reads changes nothing, and says so: a user who
/// types `-D resx=320` at a file with a fixed width gets a warning, not a
/// full-size render with no word.
#[test]
fn a_define_the_file_never_reads_is_a_warning() {
    let xml = format!(
        "<scene version=\"3.0.0\">\n<default name=\"res\" value=\"8\"/><default name=\"spp\" value=\"1\"/>\
         <default name=\"power\" value=\"1\"/>\n{SENSOR}\n<shape type=\"cube\"/>\n</scene>"
    );
    let scene = load("defines", &xml, &[("res", "4"), ("resx", "320")], false)
        .unwrap_or_else(|e| panic!("{e}"));
    let w = scene.warnings.join("\n");
    assert!(
        w.contains("-D resx: the file never reads `$resx`: ignored") && !w.contains("-D res:"),
        "{w}"
    );
}

/// An image file of 0 bytes (a snapshot that lacks its large files) is an
/// error that says so, at the element that names it.
#[test]
fn an_empty_image_file_is_named_as_empty() {
    let xml = format!(
        "<scene version=\"3.0.0\">\n<default name=\"res\" value=\"8\"/><default name=\"spp\" value=\"1\"/>\
         <default name=\"power\" value=\"1\"/>\n{SENSOR}\n<emitter type=\"envmap\">\
         <string name=\"filename\" value=\"empty.hdr\"/></emitter>\n</scene>"
    );
    let e = load("empty-image", &xml, &[], false).expect_err("an empty image");
    let e = e.to_string();
    assert!(
        e.contains("scene.xml:10:1: ") && e.contains("empty.hdr: the file is empty (0 bytes)"),
        "{e}"
    );
}
