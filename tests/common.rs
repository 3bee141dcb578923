//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use tracelab::film::FilmSnapshot;
use tracelab::image::Image;
use tracelab::integrator::Integrator;
use tracelab::render::{Adaptive, RenderSettings, RenderStats, Session};
use tracelab::sampling::SamplerKind;
use tracelab::scene::Scene;

/// Path of a file in the repository.
pub fn repo_path(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// The default Cornell box.
pub fn cornell_box() -> Scene {
    Scene::load(&repo_path("scenes/cornell_box.toml")).expect("default scene loads")
}

/// A scene from TOML text, written to a fresh directory named after `name`
/// and numbered per call: tests run in parallel, and two loading under the
/// same name would empty each other's directory.
pub fn load_scene_text(name: &str, text: &str) -> Scene {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, Ordering::Relaxed);
    let dir = temp_dir(&format!("{name}-{call}"));
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A reference image from tests/data.
pub fn reference(name: &str) -> Image {
    Image::read(&repo_path(&format!("tests/data/{name}"))).expect("reference image loads")
}

/// Renders `spp` samples per pixel in passes of `pass` samples.
pub fn render_with(
    scene: Scene,
    integrator: Integrator,
    sampler: SamplerKind,
    spp: u32,
    seed: u64,
    threads: usize,
    pass: u32,
) -> (FilmSnapshot, RenderStats) {
    render_adaptive(integrator, sampler, None, scene, spp, seed, threads, pass)
}

/// [`render_with`] with adaptive sampling.
#[allow(clippy::too_many_arguments)]
pub fn render_adaptive(
    integrator: Integrator,
    sampler: SamplerKind,
    adaptive: Option<Adaptive>,
    scene: Scene,
    spp: u32,
    seed: u64,
    threads: usize,
    pass: u32,
) -> (FilmSnapshot, RenderStats) {
    let settings = RenderSettings {
        integrator,
        sampler,
        seed,
        planned_spp: spp,
        threads,
        adaptive,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    let session = Session::new(Arc::new(scene), settings).expect("session starts");
    let mut done = 0;
    while done < spp {
        let k = pass.min(spp - done);
        assert!(session.render_pass(k));
        done += k;
    }
    (session.snapshot(), session.stats())
}

/// Renders with all cores in passes of 8 samples.
pub fn render(
    scene: Scene,
    integrator: Integrator,
    sampler: SamplerKind,
    spp: u32,
    seed: u64,
) -> (FilmSnapshot, RenderStats) {
    render_with(scene, integrator, sampler, spp, seed, 0, 8)
}

/// A fresh empty directory under the system temp dir, removed when the
/// guard is dropped: every run of the tests would otherwise leave its
/// directories behind. A failing test keeps its own, to be looked at.
pub fn temp_dir(name: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("tracelab-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    TempDir(dir)
}

/// See [`temp_dir`]; reads as the directory's path.
pub struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Mean of a per-channel quantity over an image and the standard error of
/// that mean from per-pixel standard errors: summed as independent, times
/// the film's correlation (samples splatted through a filter count in
/// several pixels; `FilmSnapshot::correlation`).
pub fn mean_and_standard_error(snapshot: &FilmSnapshot) -> ([f64; 3], [f64; 3]) {
    let n = snapshot.image.pixels.len() as f64;
    let mean = snapshot.image.mean();
    let mut var = [0.0f64; 3];
    for se in &snapshot.standard_error.pixels {
        for c in 0..3 {
            var[c] += (se[c] as f64).powi(2);
        }
    }
    (mean, var.map(|v| (v * snapshot.correlation).sqrt() / n))
}

/// A unit UV sphere of `nu` x `nv` quads as OBJ text, faces counter-clockwise
/// seen from outside; with `normals`, smooth `vn` normals (the true ones).
pub fn uv_sphere_obj(nu: usize, nv: usize, normals: bool) -> String {
    let mut text = String::new();
    let index = |i: usize, j: usize| 1 + j * (nu + 1) + i;
    for j in 0..=nv {
        for i in 0..=nu {
            let theta = std::f32::consts::PI * j as f32 / nv as f32;
            let phi = std::f32::consts::TAU * i as f32 / nu as f32;
            let n = glam::Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            text += &format!("v {} {} {}\n", n.x, n.y, n.z);
            if normals {
                text += &format!("vn {} {} {}\n", n.x, n.y, n.z);
            }
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            text += &match normals {
                true => format!("f {a}//{a} {d}//{d} {c}//{c}\nf {a}//{a} {c}//{c} {b}//{b}\n"),
                false => format!("f {a} {d} {c}\nf {a} {c} {b}\n"),
            };
        }
    }
    text
}
