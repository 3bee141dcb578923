//! Scaling with mesh size and threads: `cargo bench --bench scaling`. A
//! benchmark, never a test. For UV spheres of 10^3 .. 10^6 triangles: BVH
//! build time, bytes per triangle, closest-hit and any-hit rays/s for
//! incoherent and coherent rays on 1 and 2 threads.
//!
//! `-- --export DIR` also writes each mesh and the ray sets as raw
//! little-endian f32 files, so that `bench/peer/embree.py` can trace the
//! same rays with Embree; `-- --csv FILE` writes the table as CSV.

mod shared;

use rayon::prelude::*;
use shared::{coherent_rays, incoherent_rays, uv_sphere};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tracelab::accel::{AccelChoice, Geometry};
use tracelab::math::Ray;

/// UV-sphere resolutions giving about 10^3, 10^4, 10^5 and 10^6 triangles.
const RESOLUTIONS: [usize; 4] = [22, 71, 224, 708];
const RAYS: usize = 1 << 20;
const REPEATS: usize = 5;

struct Row {
    triangles: usize,
    build_s: f64,
    bytes_per_triangle: f64,
    /// Mrays/s for (query, rays, threads).
    rates: Vec<(&'static str, &'static str, usize, f64)>,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value_of = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map(PathBuf::from)
    };
    let export = value_of("--export");
    let csv = value_of("--csv");
    let incoherent = incoherent_rays(RAYS);
    let coherent = coherent_rays(1024);
    if let Some(dir) = &export {
        std::fs::create_dir_all(dir).expect("create export folder");
        write_rays(&dir.join("rays_incoherent.f32"), &incoherent);
        write_rays(&dir.join("rays_coherent.f32"), &coherent);
    }
    println!(
        "| triangles | build (s) | bytes/triangle | query | rays | 1 thread Mrays/s | 2 threads Mrays/s | 2-thread efficiency |"
    );
    println!("|---:|---:|---:|---|---|---:|---:|---:|");
    let mut rows = Vec::new();
    for n in RESOLUTIONS {
        let triangles = uv_sphere(n);
        if let Some(dir) = &export {
            let floats: Vec<f32> = triangles
                .iter()
                .flat_map(|t| t.vertices.iter().flat_map(|v| v.to_array()))
                .collect();
            write_f32(&dir.join(format!("mesh_{}.f32", triangles.len())), &floats);
        }
        let mut builds = Vec::new();
        let mut geometry = Geometry::default();
        for _ in 0..3 {
            let start = Instant::now();
            geometry = Geometry::build_with(&triangles, vec![], AccelChoice::Bvh);
            builds.push(start.elapsed().as_secs_f64());
        }
        let mut row = Row {
            triangles: triangles.len(),
            build_s: median(&mut builds),
            bytes_per_triangle: geometry.memory_bytes() as f64 / triangles.len() as f64,
            rates: Vec::new(),
        };
        for (query, any) in [("closest", false), ("any", true)] {
            for (kind, rays) in [("incoherent", &incoherent), ("coherent", &coherent)] {
                for threads in [1, 2] {
                    let rate = rays_per_second(&geometry, rays, any, threads);
                    row.rates.push((query, kind, threads, rate / 1e6));
                }
                let one = row.rates[row.rates.len() - 2].3;
                let two = row.rates[row.rates.len() - 1].3;
                println!(
                    "| {} | {:.3} | {:.0} | {query} | {kind} | {one:.2} | {two:.2} | {:.0}% |",
                    row.triangles,
                    row.build_s,
                    row.bytes_per_triangle,
                    100.0 * two / (2.0 * one)
                );
            }
        }
        rows.push(row);
    }
    if let Some(path) = csv {
        let mut out =
            String::from("triangles,build_s,bytes_per_triangle,query,rays,threads,mrays_per_s\n");
        for r in &rows {
            for (query, kind, threads, rate) in &r.rates {
                out += &format!(
                    "{},{:.5},{:.1},{query},{kind},{threads},{rate:.4}\n",
                    r.triangles, r.build_s, r.bytes_per_triangle
                );
            }
        }
        std::fs::write(&path, out).expect("write CSV");
        eprintln!("wrote {}", path.display());
    }
}

/// Median over [`REPEATS`] passes of rays per second on `threads` threads.
fn rays_per_second(geometry: &Geometry, rays: &[Ray], any: bool, threads: usize) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut rates = Vec::new();
    for _ in 0..REPEATS {
        let start = Instant::now();
        let hits: usize = pool.install(|| {
            rays.par_chunks(4096)
                .map(|chunk| {
                    chunk
                        .iter()
                        .filter(|r| {
                            if any {
                                geometry.occluded(r)
                            } else {
                                geometry.intersect(r).is_some()
                            }
                        })
                        .count()
                })
                .sum()
        });
        std::hint::black_box(hits);
        rates.push(rays.len() as f64 / start.elapsed().as_secs_f64());
    }
    median(&mut rates)
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Origins then directions, 6 floats per ray.
fn write_rays(path: &Path, rays: &[Ray]) {
    let floats: Vec<f32> = rays
        .iter()
        .flat_map(|r| {
            r.origin
                .to_array()
                .into_iter()
                .chain(r.direction.to_array())
        })
        .collect();
    write_f32(path, &floats);
}

fn write_f32(path: &Path, floats: &[f32]) {
    let mut file = std::fs::File::create(path).expect("create export file");
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    file.write_all(&bytes).expect("write export file");
}
