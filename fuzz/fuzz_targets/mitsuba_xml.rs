//! Mitsuba scene files: any bytes, written as `scene.xml` beside veach-bidir's
//! meshes (`models/`), must give a scene or an error, never a panic; what
//! loads is built and rendered.
#![no_main]

mod common;
mod scratch;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = scratch::dir(|dir| {
        let models = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/veach-bidir/models");
        let _ = std::os::unix::fs::symlink(models, dir.join("models"));
    });
    let path = dir.join("scene.xml");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    common::load_and_render(&path);
});
