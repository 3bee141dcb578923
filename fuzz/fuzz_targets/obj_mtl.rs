//! OBJ and MTL bytes: split at the first line `#MTL`, written next to a
//! scene file that uses the OBJ; loading and building must give a scene or
//! an error, never a panic.
#![no_main]

mod common;
mod scratch;

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

fn dir() -> &'static PathBuf {
    scratch::dir(|dir| {
        std::fs::write(
            dir.join("scene.toml"),
            "[camera]\neye = [0, 1, 4]\nlook_at = [0, 0, 0]\nfov_y = 40\nwidth = 4\nheight = 4\n\n[[mesh]]\nfile = \"mesh.obj\"\n\n[[point_light]]\nposition = [0, 3, 2]\nintensity = [5, 5, 5]\n",
        )
        .expect("fuzz scene");
    })
}

fuzz_target!(|data: &[u8]| {
    let marker = b"\n#MTL\n";
    let (obj, mtl) = match data.windows(marker.len()).position(|w| w == marker) {
        Some(i) => (&data[..i], &data[i + marker.len()..]),
        None => (data, &[][..]),
    };
    let dir = dir();
    if std::fs::write(dir.join("mesh.obj"), obj).is_err()
        || std::fs::write(dir.join("mesh.mtl"), mtl).is_err()
    {
        return;
    }
    let scene = dir.join("scene.toml");
    if let Ok(input) = tracelab::scene::load::load_scene_file(&scene, &common::limits()) {
        common::build_and_render(input);
    }
});
