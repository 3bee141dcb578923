//! `tracelab bench`: error against a reference at 1, 2, 4, ... spp for
//! several configurations, as a table, CSV and log-log plots (SVG or PNG).

use super::render::render_spp;
use super::shared::override_resolution;
use clap::Args;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tracelab::convergence::{
    BenchConfig, Checkpoint, ErrorOver, StopAt, log_log_slope, mean_variance, measure, time_to_rmse,
};
use tracelab::image::{Image, check_writable};
use tracelab::plot::{PlotFormat, Series, SeriesStyle, log_log_plot};
use tracelab::render::{RenderSettings, Session};
use tracelab::scene::{Limits, Scene};
use tracelab::{Error, Result};

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene file (TOML, Mitsuba XML, glTF, or a bare OBJ or PLY).
    scene: PathBuf,
    /// Reference image (EXR); without it tracelab renders one (path tracing,
    /// Sobol, --reference-spp) and caches it under target/.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Per-pixel variance of the reference's mean (EXR): its mean is taken
    /// out of every MSE, so slopes are not flattened by the reference's noise.
    #[arg(long, requires = "reference")]
    reference_variance: Option<PathBuf>,
    /// Samples per pixel of a rendered reference.
    #[arg(long, default_value_t = 8192)]
    reference_spp: u32,
    /// Configuration of a rendered reference (match the depth of the
    /// configurations measured).
    #[arg(long, default_value = "path:sobol")]
    reference_config: String,
    /// A configuration `integrator:sampler[:key=value...]`, e.g. `path:sobol`,
    /// `path:stratified:max-depth=1`, `mcrt:independent:shadow-rays=5:glossy-rays=5:max-depth=3`,
    /// `light:independent`; keys: max-depth, rr-depth, rr=off, seen-emitters=sampled,
    /// shadow-rays, glossy-rays, strategy=bsdf|light|mis, light-sampling=area|solid-angle,
    /// domains=pixel+light, light-paths, light-path-bounces (BDPT), distribute=N (adaptive
    /// sampling by noise after N spp). Repeatable.
    #[arg(long = "config", required = true)]
    configs: Vec<String>,
    /// Largest sample count measured (powers of two from 1).
    #[arg(long, default_value_t = 256)]
    max_spp: u32,
    /// Stop doubling once a checkpoint's RMSE is at most this.
    #[arg(long)]
    until_rmse: Option<f64>,
    /// Stop doubling once a checkpoint took this many seconds.
    #[arg(long)]
    seconds: Option<f64>,
    /// RMSE levels for the time-to-error table (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "0.01,0.005")]
    targets: Vec<f64>,
    /// Fit the log-log slope from this many samples per pixel on.
    #[arg(long, default_value_t = 4)]
    slope_from: u32,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// RMSE without the worst 0.1% of pixels, for the slopes, the
    /// time-to-error table and the plots: a few fireflies (a rare path
    /// through glass) then do not decide the figure.
    #[arg(long)]
    trim: bool,
    /// CSV of every checkpoint.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Log-log plot of RMSE against samples per pixel (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Log-log plot of RMSE against render time (.svg or .png).
    #[arg(long)]
    plot_time: Option<PathBuf>,
    /// Log-log plot of RMSE against rays per pixel, an equal-cost comparison (.svg or .png).
    #[arg(long)]
    plot_rays: Option<PathBuf>,
    /// Title of the plots.
    #[arg(long, default_value = "RMSE against the reference")]
    title: String,
}

pub fn bench(args: &BenchArgs) -> Result<()> {
    let configs: Vec<BenchConfig> = args
        .configs
        .iter()
        .map(|c| BenchConfig::parse(c))
        .collect::<Result<_>>()?;
    if args.max_spp == 0 || args.max_spp > 1 << 20 {
        return Err(Error::new(format!(
            "--max-spp must be in 1..=1048576, got {}",
            args.max_spp
        )));
    }
    for path in [&args.csv, &args.plot, &args.plot_time, &args.plot_rays]
        .into_iter()
        .flatten()
    {
        check_writable(path)?;
    }
    // A plot's format comes from its extension: a wrong one fails now, not
    // after the renders.
    for path in [&args.plot, &args.plot_time, &args.plot_rays]
        .into_iter()
        .flatten()
    {
        PlotFormat::of(path)?;
    }
    let mut scene = Scene::load(&args.scene)?;
    override_resolution(&mut scene, args.width, args.height, &Limits::default())?;
    let scene = Arc::new(scene);
    let reference = match &args.reference {
        Some(path) => Image::read(path)?,
        None => cached_reference(
            &args.scene,
            &scene,
            &BenchConfig::parse(&args.reference_config)?,
            args.reference_spp,
            args.threads,
        )?,
    };
    let reference_mse = match &args.reference_variance {
        Some(path) => mean_variance(&Image::read(path)?),
        None => 0.0,
    };
    let mut csv = String::from(
        "config,spp,seconds,cpu_seconds,rays_per_pixel,rmse,rmse_without_reference_noise,relative_mse,mean_relative_error,efficiency,trimmed_rmse\n",
    );
    let mut results = Vec::new();
    for config in &configs {
        eprintln!("measuring {} ...", config.label);
        let points = measure(
            &scene,
            config,
            &reference,
            reference_mse,
            args.max_spp,
            StopAt {
                rmse: args.until_rmse,
                seconds: args.seconds,
            },
            if args.trim {
                ErrorOver::Trimmed
            } else {
                ErrorOver::AllPixels
            },
            args.seed,
            args.threads,
        )?;
        println!("{}", config.label);
        println!(
            "  {:>7} {:>9} {:>9} {:>10} {:>10} {:>14} {:>12} {:>12} {:>12}",
            "spp",
            "seconds",
            "CPU s",
            "rays/px",
            "RMSE",
            if args.trim {
                "trimmed-noise"
            } else {
                "RMSE-ref.noise"
            },
            "rel. MSE",
            "mean rel.",
            "1/(MSE t)"
        );
        for p in &points {
            println!(
                "  {:>7} {:>9.3} {:>9} {:>10.1} {:>10.6} {:>14.6} {:>12.6} {:>12.6} {:>12.4e}",
                p.spp,
                p.seconds,
                p.cpu_seconds.map_or("-".into(), |c| format!("{c:.3}")),
                p.rays_per_pixel,
                p.error.rmse,
                p.rmse,
                p.error.relative_mse,
                p.error.mean_relative_error,
                p.efficiency()
            );
            csv += &format!(
                "{},{},{:.6},{},{:.3},{:.8},{:.8},{:.8},{:.8},{:.6e},{:.8}\n",
                config.label,
                p.spp,
                p.seconds,
                p.cpu_seconds.map_or(String::new(), |c| format!("{c:.6}")),
                p.rays_per_pixel,
                p.error.rmse,
                p.rmse,
                p.error.relative_mse,
                p.error.mean_relative_error,
                p.efficiency(),
                p.error.trimmed_rmse
            );
        }
        match log_log_slope(&points, args.slope_from) {
            Some(slope) => println!(
                "  log-log slope of RMSE vs spp (from {} spp): {slope:.3}",
                args.slope_from
            ),
            None => println!("  (too few points for a slope)"),
        }
        results.push((config.label.clone(), points));
    }
    if !args.targets.is_empty() {
        println!(
            "time to reach RMSE (reference noise removed; log-log interpolation between checkpoints)"
        );
        let header: Vec<String> = args.targets.iter().map(|t| format!("{t}")).collect();
        println!("  {:<48} {}", "config", header.join("        "));
        for (name, points) in &results {
            let cells: Vec<String> = args
                .targets
                .iter()
                .map(|&t| match time_to_rmse(points, t) {
                    Some(s) => format!("{s:>8.3} s"),
                    None => format!("{:>10}", "not reached"),
                })
                .collect();
            println!("  {name:<48} {}", cells.join("  "));
        }
    }
    if let Some(path) = &args.csv {
        tracelab::image::write_atomically(path, |tmp| {
            std::fs::write(tmp, &csv).map_err(|e| e.to_string())
        })?;
        eprintln!("wrote {}", path.display());
    }
    let plots: [(&Option<PathBuf>, &str, fn(&Checkpoint) -> f64); 3] = [
        (&args.plot, "samples per pixel", |p| f64::from(p.spp)),
        (&args.plot_time, "seconds", |p| p.seconds),
        (&args.plot_rays, "rays per pixel", |p| p.rays_per_pixel),
    ];
    for (path, x_label, x) in plots {
        if let Some(path) = path {
            let series: Vec<Series> = results
                .iter()
                .enumerate()
                .map(|(i, (name, points))| {
                    let points: Vec<(f64, f64)> = points.iter().map(|p| (x(p), p.rmse)).collect();
                    Series::new(name, SeriesStyle::Line, i, &points)
                })
                .collect();
            let y_label = if args.trim {
                "RMSE without the worst 0.1% of pixels"
            } else {
                "RMSE"
            };
            log_log_plot(path, &args.title, x_label, y_label, &series)?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// A high-sample path-traced reference for `scene`, cached under
/// target/tracelab-references/ by scene file, size and sample count.
fn cached_reference(
    scene_path: &Path,
    scene: &Arc<Scene>,
    config: &BenchConfig,
    spp: u32,
    threads: usize,
) -> Result<Image> {
    let stem = scene_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/tracelab-references");
    let config_name: String = config
        .label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let path = dir.join(format!(
        "{stem}_{}x{}_{config_name}_{spp}spp.exr",
        scene.camera.width, scene.camera.height
    ));
    if path.is_file() {
        eprintln!("using the cached reference {}", path.display());
        return Image::read(&path);
    }
    eprintln!(
        "no --reference: rendering one ({}, {spp} spp) to {}",
        config.label,
        path.display()
    );
    std::fs::create_dir_all(&dir)
        .map_err(|e| Error::at(&dir, None, format!("cannot create the cache: {e}")))?;
    let session = Session::new(
        scene.clone(),
        RenderSettings {
            integrator: config.integrator.build(),
            sampler: config.sampler,
            seed: 0x5eed,
            planned_spp: spp,
            threads,
            adaptive: None,
            domains: config.domains,
            clamp: None,
            filter_sampling: Default::default(),
        },
    )?;
    render_spp(&session, spp);
    let image = session.snapshot().image;
    image.write_exr(&path)?;
    Ok(image)
}
