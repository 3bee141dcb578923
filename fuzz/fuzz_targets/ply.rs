//! PLY meshes, ASCII or binary: any bytes, loaded as a bare mesh (framed
//! by the default camera and light), must give a scene or an error, never
//! a panic; what loads is built and rendered.
#![no_main]

mod common;
mod scratch;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = scratch::dir(|_| {}).join("mesh.ply");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    common::load_and_render(&path);
});
