//! `tracelab render --integrator bdpt --strategies DIR`: Veach's pyramid of
//! strategy images. Every (s, t) as EXR, weighted and unweighted, and two
//! PNG sheets with a row per path length k = s + t - 2 (up to 4 bounces)
//! and a column per s.

use std::path::Path;
use tracelab::image::Image;
use tracelab::integrator::bdpt::Bdpt;
use tracelab::integrator::strategy_images::{StrategyImages, strategy_index};
use tracelab::sampling::Sampler;
use tracelab::scene::Scene;
use tracelab::{Error, Result};

/// Rows of the PNG sheets: paths of 0 to 4 bounces.
const SHEET_BOUNCES: u32 = 4;
/// The strategy images may take this much memory.
const MEMORY_BUDGET: u64 = 4 << 30;

/// Renders the strategy images of `spp` samples per pixel and writes them
/// into `dir`; returns the summed image's mean for the summary.
pub fn write(scene: &Scene, bdpt: &Bdpt, sampler: &Sampler, spp: u32, dir: &Path) -> Result<()> {
    let (width, height) = (scene.camera.width, scene.camera.height);
    let bytes = StrategyImages::memory_estimate(width, height, bdpt.max_depth);
    if bytes > MEMORY_BUDGET {
        return Err(Error::new(format!(
            "--strategies at {width}x{height} and depth {} needs about {} MB (the limit is {} MB): \
             lower the resolution or --max-depth",
            bdpt.max_depth,
            bytes >> 20,
            MEMORY_BUDGET >> 20
        )));
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::at(dir, None, format!("cannot create the folder: {e}")))?;
    eprintln!("strategy images: {spp} spp on one thread, every strategy kept apart");
    let (images, _) = StrategyImages::render(scene, bdpt, sampler, spp);
    let image = |pixels: &Vec<[f32; 3]>| Image {
        width,
        height,
        pixels: pixels.clone(),
    };
    let mut sum = Image::new(width, height);
    for k in 0..=images.max_depth {
        for s in 0..=k + 1 {
            let t = k + 2 - s;
            let i = strategy_index(s, t);
            image(&images.weighted[i]).write_exr(&dir.join(format!("s{s}_t{t}.exr")))?;
            image(&images.unweighted[i])
                .write_exr(&dir.join(format!("s{s}_t{t}_unweighted.exr")))?;
            for (p, w) in sum.pixels.iter_mut().zip(&images.weighted[i]) {
                for c in 0..3 {
                    p[c] += w[c];
                }
            }
        }
    }
    sum.write_exr(&dir.join("sum.exr"))?;
    // One exposure for every tile: the sum's mean luminance at mid-grey,
    // so that the weighted tiles visibly add up to the image.
    let mean = sum.mean();
    let luminance = 0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2];
    let exposure = if luminance > 0.0 {
        (0.18 / luminance).log2() as f32
    } else {
        0.0
    };
    for (name, weighted) in [("weighted", true), ("unweighted", false)] {
        images
            .sheet(weighted, SHEET_BOUNCES + 1)
            .write_png(&dir.join(format!("strategies_{name}.png")), exposure)?;
    }
    println!(
        "wrote {} strategies (weighted and unweighted EXR), sum.exr and two PNG sheets to {}",
        tracelab::integrator::strategy_images::strategy_count(images.max_depth),
        dir.display()
    );
    Ok(())
}
