//! Scene files: any text must give a scene or an error, never a panic.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Placed in scenes/ so that `file = "cornell_box.obj"` finds a real mesh.
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/fuzz.toml"));
    if let Ok(input) = tracelab::scene::load::parse_scene(path, text, &common::limits()) {
        common::build_and_render(input);
    }
});
