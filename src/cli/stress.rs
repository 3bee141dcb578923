//! `tracelab stress`: the numerical stress suite as a table; exits non-zero
//! when a case fails its tolerance.

use clap::Args;
use std::path::PathBuf;
use tracelab::math::OffsetMode;
use tracelab::stress::{CaseResult, StressSettings, StressSuite, run};
use tracelab::{Error, Result};

#[derive(Args, Debug)]
pub struct StressArgs {
    /// Small images and few samples (seconds instead of a minute).
    #[arg(long)]
    quick: bool,
    /// How rays leave surfaces: `robust` or `fixed:EPS` (to see it fail).
    #[arg(long, value_parser = OffsetMode::parse, default_value = "robust")]
    offset: OffsetMode,
    /// Write every case's image as a PNG into this folder.
    #[arg(long)]
    images: Option<PathBuf>,
    /// Where the Cornell box and caustic scenes are.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes"))]
    scenes: PathBuf,
}

pub fn stress(args: &StressArgs) -> Result<()> {
    let mut settings = if args.quick {
        StressSettings::quick()
    } else {
        StressSettings::full()
    };
    settings.offset = args.offset;
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::new(format!("cannot create folder {}: {e}", dir.display())))?;
    }
    let suite = StressSuite::new(&args.scenes, &settings)?;
    eprintln!(
        "stress suite: {} cases, {}x{}, {} spp, path tracing, offsets {:?}; tolerance = relative RMSE of an independent render of the reference",
        suite.cases.len(),
        settings.width,
        settings.height,
        settings.spp,
        settings.offset
    );
    println!(
        "{:<34} {:>10} {:>10} {:>16} {:>10}  result",
        "case", "rel. RMSE", "tolerance", "self-hits", "non-finite"
    );
    let mut image_error = None;
    let results = run(&suite, &settings, |r: &CaseResult| {
        println!(
            "{:<34} {:>10.4} {:>10.4} {:>16} {:>10}  {}",
            r.name,
            r.relative_rmse,
            r.tolerance,
            format!("{}/{}", r.self_intersections, r.spawned),
            r.non_finite,
            if r.passed() { "ok" } else { "FAIL" }
        );
        if let Some(dir) = &args.images {
            let name: String = r
                .name
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            if let Err(e) = r.image.write_png(&dir.join(format!("{name}.png")), 0.0) {
                image_error.get_or_insert(e);
            }
        }
    })?;
    if let Some(e) = image_error {
        return Err(e);
    }
    let failed = results.iter().filter(|r| !r.passed()).count();
    if failed > 0 {
        return Err(Error::new(format!(
            "{failed} of {} stress cases failed",
            results.len()
        )));
    }
    eprintln!("all {} stress cases passed", results.len());
    Ok(())
}
