//! PLY meshes, ASCII or binary: any bytes, loaded as a bare mesh (framed
//! by the default camera and light), must give a scene or an error, never
//! a panic; what loads is built and rendered.
#![no_main]

mod common;
mod scratch;

use libfuzzer_sys::fuzz_target;
use tracelab::scene::LoadOptions;

fuzz_target!(|data: &[u8]| {
    let path = scratch::dir(|_| {}).join("mesh.ply");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let options = LoadOptions {
        limits: common::limits(),
        ..Default::default()
    };
    if let Ok(input) = tracelab::scene::load::load_any(&path, &options) {
        common::build_and_render(input);
    }
});
