//! Command-line interface (clap): argument definitions and the commands
//! (`view`, `render`, `compare` here; `bench` in `bench.rs`).

mod bench;
mod stress;

use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tracelab::image::{Image, check_writable};
use tracelab::integrator::{
    GlassShadows, IntegratorKind, IntegratorOptions, MisHeuristic, Strategy,
};
use tracelab::math::OffsetMode;
use tracelab::render::{Adaptive, RenderSettings, RenderStats, Session};
use tracelab::sampling::{Domains, SamplerKind};
use tracelab::scene::light::LightSampling;
use tracelab::scene::{Limits, Scene};
use tracelab::{Error, Result};

/// tracelab: Monte Carlo light transport, measured.
#[derive(Parser, Debug)]
#[command(name = "tracelab", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to an EXR (linear float) or PNG (tone-mapped sRGB) file.
    Render(RenderArgs),
    /// Open the live window (the default when no command is given).
    #[cfg(feature = "viewer")]
    View(ViewArgs),
    /// Measure error against a reference at 1, 2, 4, ... spp for several
    /// configurations; print a table, write CSV and log-log plots (SVG).
    Bench(bench::BenchArgs),
    /// The numerical stress suite: scaled, far-away and awkward scenes against
    /// their references; exits non-zero when a case fails.
    Stress(stress::StressArgs),
    /// Compare two images: RMSE, relative MSE and mean relative error (as tev computes them).
    Compare {
        /// The image to measure.
        image: PathBuf,
        /// The reference.
        reference: PathBuf,
    },
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum IntegratorArg {
    /// Whitted ray tracing: point-light direct light, hard shadows, mirror and glass recursion.
    Whitted,
    /// Monte Carlo (distribution) ray tracing: N shadow rays and M branching BSDF rays per hit.
    Mcrt,
    /// Path tracing with next-event estimation, MIS and Russian roulette.
    Path,
    /// Light (particle) tracing: paths from the lights, every vertex connected to the camera.
    Light,
}

#[cfg(feature = "viewer")]
#[derive(Args, Debug)]
struct ViewArgs {
    /// Scene file (TOML); default: the last one, or the Cornell box.
    scene: Option<PathBuf>,
    #[arg(long, value_enum)]
    integrator: Option<IntegratorArg>,
    /// Target samples per pixel.
    #[arg(long)]
    spp: Option<u32>,
    /// Save a screenshot of the window here once every view has --after-spp samples, then exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Samples per pixel to wait for before --screenshot.
    #[arg(long, default_value_t = 64, requires = "screenshot")]
    after_spp: u32,
    /// Start a side-by-side comparison (B = A with the Sobol sampler).
    #[arg(long)]
    compare: bool,
    /// Render threads (default: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Ignore the settings saved by the last session.
    #[arg(long)]
    fresh: bool,
    /// Folder for exports (default: ./exports).
    #[arg(long)]
    export_dir: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum StrategyArg {
    /// BSDF sampling only.
    Bsdf,
    /// Light sampling only.
    Light,
    /// Both, combined by MIS.
    Mis,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum LightSamplingArg {
    /// Uniform by area: density d^2 / (cos A) in solid angle.
    Area,
    /// Uniform in solid angle: sphere cones, spherical triangles (Arvo).
    SolidAngle,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum GlassShadowsArg {
    Opaque,
    Tinted,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum SamplerArg {
    /// Independent uniform numbers.
    Independent,
    /// Jittered strata in every dimension and pair, shuffled between dimensions.
    Stratified,
    /// Correlated multi-jittered: jittered and Latin hypercube in every pair.
    Multijitter,
    /// Owen-scrambled Sobol, shuffled per dimension pair.
    Sobol,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum MisArg {
    None,
    Balance,
    Power,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    #[arg(long, value_enum, default_value = "path")]
    integrator: IntegratorArg,
    /// Samples per pixel.
    #[arg(long, conflicts_with_all = ["time", "rays_per_pixel"])]
    spp: Option<u32>,
    /// Render for this many seconds instead of a sample count.
    #[arg(long, conflicts_with = "rays_per_pixel")]
    time: Option<f64>,
    /// Render until this many rays per pixel (all kinds) are cast: equal-cost comparisons.
    #[arg(long)]
    rays_per_pixel: Option<f64>,
    #[arg(long, value_enum, default_value = "independent")]
    sampler: SamplerArg,
    /// Domains the sampler applies to, the rest independent: any of
    /// pixel,lens,time,light,bsdf (default all).
    #[arg(long, value_parser = parse_domains)]
    domains: Option<Domains>,
    /// Maximum bounces (1 = direct lighting); Mitsuba's max_depth is one more.
    #[arg(long, default_value_t = 8)]
    max_depth: u32,
    /// Russian roulette starts after this many bounces.
    #[arg(long, default_value_t = 5)]
    rr_depth: u32,
    /// Turn Russian roulette off.
    #[arg(long)]
    no_rr: bool,
    /// Turn next-event estimation (light sampling) off: the same as --strategy bsdf.
    #[arg(long, conflicts_with = "strategy")]
    no_nee: bool,
    /// Path tracing: sample the BSDF, the lights, or both with MIS.
    #[arg(long, value_enum)]
    strategy: Option<StrategyArg>,
    /// How light and BSDF samples are combined (none = light sampling only).
    #[arg(long, value_enum, default_value = "power")]
    mis: MisArg,
    /// How area lights are sampled (default: the scene's, i.e. triangles by
    /// area and spheres by solid angle unless its [lights] table says otherwise).
    #[arg(long, value_enum)]
    light_sampling: Option<LightSamplingArg>,
    /// How rays leave surfaces: `robust` (by the hit's rounding-error bound)
    /// or `fixed:EPS` (the classic epsilon along the normal, to see its artifacts).
    #[arg(long, value_parser = OffsetMode::parse, default_value = "robust")]
    offset: OffsetMode,
    /// MC ray tracing: light samples (shadow rays) per hit.
    #[arg(long, default_value_t = 1)]
    shadow_rays: u32,
    /// MC ray tracing: BSDF samples (branching rays) per hit.
    #[arg(long, default_value_t = 1)]
    glossy_rays: u32,
    /// Path tracing and Whitted: run the general code, not the code
    /// specialised for the scene's features (to measure what that saves).
    #[arg(long)]
    general: bool,
    /// Whitted: constant ambient radiance times the diffuse albedo.
    #[arg(long, default_value_t = 0.0)]
    ambient: f32,
    /// Whitted: shadow rays through glass are blocked, or tinted by the glass.
    #[arg(long, value_enum, default_value = "opaque")]
    glass_shadows: GlassShadowsArg,
    /// Image width (overrides the scene).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (overrides the scene).
    #[arg(long)]
    height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (default: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Adaptive sampling: stop sampling pixels whose relative standard error
    /// falls below this (e.g. 0.02); biased, and reported as such.
    #[arg(long)]
    adaptive: Option<f32>,
    /// Samples every pixel takes before adaptive sampling may stop it.
    #[arg(long, default_value_t = 16)]
    adaptive_min_spp: u32,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0)]
    exposure: f32,
    /// Largest accepted image side.
    #[arg(long, default_value_t = Limits::default().max_resolution)]
    max_resolution: u32,
    /// Largest accepted triangle count.
    #[arg(long, default_value_t = Limits::default().max_triangles)]
    max_triangles: usize,
    /// Output file: .exr (linear float32) or .png (tone-mapped sRGB).
    #[arg(long, short)]
    out: PathBuf,
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => render(&args),
        Some(Command::Compare { image, reference }) => compare(&image, &reference),
        Some(Command::Bench(args)) => bench::bench(&args),
        Some(Command::Stress(args)) => stress::stress(&args),
        #[cfg(feature = "viewer")]
        Some(Command::View(args)) => view(args),
        #[cfg(feature = "viewer")]
        None => view(ViewArgs {
            scene: None,
            integrator: None,
            spp: None,
            screenshot: None,
            after_spp: 64,
            compare: false,
            threads: 0,
            fresh: false,
            export_dir: None,
        }),
        #[cfg(not(feature = "viewer"))]
        None => {
            eprintln!(
                "tracelab: no command given; rendering the default Cornell box (see `tracelab --help`)."
            );
            let scene = default_scene_path();
            let scene = scene.to_string_lossy().into_owned();
            let argv = [
                "tracelab",
                "render",
                scene.as_str(),
                "--spp",
                "256",
                "--out",
                "cornell_box.png",
            ];
            let cli = Cli::try_parse_from(argv).map_err(|e| Error::new(e.to_string()))?;
            run(cli)
        }
    }
}

#[cfg(feature = "viewer")]
fn view(args: ViewArgs) -> Result<()> {
    if let Some(scene) = &args.scene
        && !scene.is_file()
    {
        return Err(Error::at(scene, None, "no such scene file"));
    }
    if let Some(shot) = &args.screenshot {
        check_writable(shot)?;
    }
    tracelab::viewer::run(tracelab::viewer::Launch {
        scene: args.scene,
        integrator: args.integrator.map(integrator_kind),
        target_spp: args.spp,
        fresh: args.fresh || args.screenshot.is_some(),
        screenshot: args.screenshot,
        after_spp: args.after_spp,
        compare: args.compare,
        threads: args.threads,
        export_dir: args.export_dir,
    })
}

fn integrator_kind(arg: IntegratorArg) -> IntegratorKind {
    match arg {
        IntegratorArg::Whitted => IntegratorKind::Whitted,
        IntegratorArg::Mcrt => IntegratorKind::Mcrt,
        IntegratorArg::Path => IntegratorKind::Path,
        IntegratorArg::Light => IntegratorKind::Light,
    }
}

#[cfg_attr(feature = "viewer", allow(dead_code))]
fn default_scene_path() -> PathBuf {
    let local = PathBuf::from("scenes/cornell_box.toml");
    if local.is_file() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box.toml")
    }
}

enum OutputFormat {
    Exr,
    Png,
}

fn output_format(path: &Path) -> Result<OutputFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("exr") => Ok(OutputFormat::Exr),
        Some("png") => Ok(OutputFormat::Png),
        _ => Err(Error::at(
            path,
            None,
            "output must end in .exr (linear float) or .png (tone-mapped sRGB)",
        )),
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    let format = output_format(&args.out)?;
    check_writable(&args.out)?;
    if let Some(t) = args.time {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::new(format!(
                "--time must be a positive number of seconds, got {t}"
            )));
        }
    }
    if args.spp == Some(0) {
        return Err(Error::new("--spp must be at least 1"));
    }
    let limits = Limits {
        max_resolution: args.max_resolution,
        max_triangles: args.max_triangles,
    };
    let load_start = Instant::now();
    let mut scene = Scene::load_with_limits(&args.scene, &limits)?;
    override_resolution(&mut scene, args.width, args.height, &limits)?;
    if let Some(mode) = args.light_sampling {
        scene.set_light_sampling(match mode {
            LightSamplingArg::Area => LightSampling::Area,
            LightSamplingArg::SolidAngle => LightSampling::SolidAngle,
        });
    }
    scene.set_offset(args.offset);
    for w in &scene.warnings {
        eprintln!("warning: {}: {w}", args.scene.display());
    }
    let load_time = load_start.elapsed();

    let integrator = integrator_options(args)?.build();
    let sampler = match args.sampler {
        SamplerArg::Independent => SamplerKind::Independent,
        SamplerArg::Stratified => SamplerKind::Stratified,
        SamplerArg::Multijitter => SamplerKind::MultiJittered,
        SamplerArg::Sobol => SamplerKind::Sobol,
    };
    if let Some(a) = args.adaptive
        && !(a.is_finite() && a > 0.0)
    {
        return Err(Error::new(format!(
            "--adaptive must be a positive relative error, got {a}"
        )));
    }
    if let Some(r) = args.rays_per_pixel
        && !(r.is_finite() && r > 0.0)
    {
        return Err(Error::new(format!(
            "--rays-per-pixel must be a positive number, got {r}"
        )));
    }
    let target_spp = if integrator.is_deterministic() {
        if args.spp.is_some_and(|s| s > 1) || args.time.is_some() || args.rays_per_pixel.is_some() {
            eprintln!(
                "note: {} is deterministic; rendering 1 sample per pixel",
                integrator.name()
            );
        }
        Some(1)
    } else if args.time.is_some() || args.rays_per_pixel.is_some() {
        None
    } else {
        Some(args.spp.unwrap_or(64))
    };
    let settings = RenderSettings {
        integrator,
        sampler,
        seed: args.seed,
        planned_spp: target_spp.unwrap_or(0),
        threads: args.threads,
        adaptive: args.adaptive.map(|threshold| Adaptive {
            threshold,
            min_spp: args.adaptive_min_spp.max(2),
        }),
        domains: args.domains.unwrap_or_default(),
    };
    let session = Session::new(Arc::new(scene), settings)?;
    let stats = match (target_spp, args.rays_per_pixel) {
        (Some(spp), _) => render_spp(&session, spp),
        (None, Some(rays)) => render_rays(&session, rays),
        (None, None) => render_time(&session, Duration::from_secs_f64(args.time.unwrap_or(1.0))),
    };
    let snapshot = session.snapshot();
    match format {
        OutputFormat::Exr => snapshot.image.write_exr(&args.out)?,
        OutputFormat::Png => snapshot.image.write_png(&args.out, args.exposure)?,
    }
    print_summary(&session, &stats, load_time);
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

fn parse_domains(text: &str) -> std::result::Result<Domains, String> {
    Domains::parse(text, ',')
}

/// Applies `--width`/`--height` (either alone keeps the other side).
pub(crate) fn override_resolution(
    scene: &mut Scene,
    width: Option<u32>,
    height: Option<u32>,
    limits: &Limits,
) -> Result<()> {
    if width.is_none() && height.is_none() {
        return Ok(());
    }
    let (w, h) = (
        width.unwrap_or(scene.camera.width),
        height.unwrap_or(scene.camera.height),
    );
    limits
        .check_resolution(w, h)
        .map_err(|e| Error::new(format!("--width/--height: {e}")))?;
    scene.set_resolution(w, h);
    Ok(())
}

fn progress_bar(len: u64, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let template =
        format!("{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit} ({{eta}} left)");
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Renders exactly `spp` samples per pixel in passes small enough for a live progress bar.
pub(crate) fn render_spp(session: &Session, spp: u32) -> RenderStats {
    let bar = progress_bar(spp as u64, "spp");
    let mut done = 0;
    let mut pass = 1;
    while done < spp {
        let k = pass.min(spp - done);
        let start = Instant::now();
        session.render_pass(k);
        done += k;
        bar.set_position(done as u64);
        // Aim for passes of about a quarter second.
        if start.elapsed() < Duration::from_millis(250) {
            pass = (pass * 2).min(64);
        }
    }
    bar.finish_and_clear();
    session.stats()
}

/// Renders one sample per pixel at a time until the rays cast per pixel reach
/// `budget` (the last pass may overshoot by one sample's rays).
fn render_rays(session: &Session, budget: f64) -> RenderStats {
    let pixels = f64::from(session.scene().camera.width) * f64::from(session.scene().camera.height);
    let bar = progress_bar(budget.ceil() as u64, "rays/pixel");
    loop {
        let stats = session.stats();
        let per_pixel = stats.rays.total() as f64 / pixels;
        bar.set_position(per_pixel.min(budget) as u64);
        if per_pixel >= budget {
            break;
        }
        session.render_pass(1);
    }
    bar.finish_and_clear();
    session.stats()
}

/// Estimator options from the command line.
fn integrator_options(args: &RenderArgs) -> Result<IntegratorOptions> {
    let strategy = match (args.strategy, args.no_nee, args.mis) {
        (Some(StrategyArg::Bsdf), ..) | (None, true, _) => Strategy::Bsdf,
        (Some(StrategyArg::Light), ..) | (None, false, MisArg::None) => Strategy::Light,
        (Some(StrategyArg::Mis), _, MisArg::None) => {
            return Err(Error::new("--strategy mis needs --mis balance or power"));
        }
        _ => Strategy::Mis,
    };
    if matches!(args.integrator, IntegratorArg::Mcrt) && args.shadow_rays + args.glossy_rays == 0 {
        return Err(Error::new(
            "--shadow-rays and --glossy-rays cannot both be 0",
        ));
    }
    Ok(IntegratorOptions {
        kind: integrator_kind(args.integrator),
        max_depth: args.max_depth,
        russian_roulette: !args.no_rr,
        rr_depth: args.rr_depth,
        strategy,
        mis: match args.mis {
            MisArg::Balance => MisHeuristic::Balance,
            MisArg::None | MisArg::Power => MisHeuristic::Power,
        },
        shadow_rays: args.shadow_rays,
        glossy_rays: args.glossy_rays,
        ambient: args.ambient,
        glass_shadows: match args.glass_shadows {
            GlassShadowsArg::Opaque => GlassShadows::Opaque,
            GlassShadowsArg::Tinted => GlassShadows::Tinted,
        },
        general: args.general,
    })
}

/// Renders passes until `budget` is spent, sizing passes so as not to overshoot.
fn render_time(session: &Session, budget: Duration) -> RenderStats {
    let bar = progress_bar(budget.as_millis() as u64, "ms");
    let start = Instant::now();
    let mut per_spp = Duration::ZERO;
    loop {
        let elapsed = start.elapsed();
        if elapsed >= budget {
            break;
        }
        let remaining = budget - elapsed;
        let k = if per_spp.is_zero() {
            1
        } else {
            ((remaining.as_secs_f64() / per_spp.as_secs_f64()) as u32).clamp(1, 64)
        };
        let pass_start = Instant::now();
        session.render_pass(k);
        per_spp = pass_start.elapsed() / k;
        bar.set_position(start.elapsed().as_millis().min(budget.as_millis()) as u64);
    }
    bar.finish_and_clear();
    session.stats()
}

fn print_summary(session: &Session, stats: &RenderStats, load_time: Duration) {
    let seconds = stats.render_time.as_secs_f64();
    let rays = stats.rays.total();
    let settings = session.settings();
    eprintln!(
        "{} | {} sampler | {} threads | scene loaded in {:.2} s",
        settings.integrator.describe(),
        settings.sampler.name(),
        session.threads(),
        load_time.as_secs_f64()
    );
    let pixels = f64::from(session.scene().camera.width) * f64::from(session.scene().camera.height);
    let per_pixel = |n: u64| n as f64 / pixels;
    eprintln!(
        "rays per pixel: {:.1} (camera {:.1}, shadow {:.1}, bounce {:.1})",
        per_pixel(rays),
        per_pixel(stats.rays.camera),
        per_pixel(stats.rays.shadow),
        per_pixel(stats.rays.bounce)
    );
    if matches!(
        settings.integrator,
        tracelab::integrator::Integrator::Path(_) | tracelab::integrator::Integrator::Whitted(_)
    ) {
        let skipped = session.scene().features.skipped();
        if settings.integrator.is_general() {
            eprintln!("general code (--general): nothing skipped");
        } else {
            eprintln!("specialised for this scene: skipped {}", skipped.join(", "));
        }
    }
    if let Some(a) = settings.adaptive {
        let planned = stats.samples + stats.skipped;
        eprintln!(
            "adaptive sampling (biased): {:.1}% of {} planned samples skipped (relative error < {}, after {} spp)",
            100.0 * stats.skipped as f64 / planned.max(1) as f64,
            planned,
            a.threshold,
            a.min_spp
        );
    }
    println!(
        "spp {} | {:.3} s | {:.2} M rays (camera {:.2} M, shadow {:.2} M, bounce {:.2} M) | {:.2} Mrays/s | {:.3} M paths/s | non-finite {}",
        stats.spp,
        seconds,
        rays as f64 * 1e-6,
        stats.rays.camera as f64 * 1e-6,
        stats.rays.shadow as f64 * 1e-6,
        stats.rays.bounce as f64 * 1e-6,
        rays as f64 / seconds * 1e-6,
        stats.samples as f64 / seconds * 1e-6,
        stats.non_finite
    );
}

fn compare(image: &Path, reference: &Path) -> Result<()> {
    let a = Image::read(image)?;
    let b = Image::read(reference)?;
    let m = a.compare(&b).map_err(|e| {
        Error::new(format!(
            "{} vs {}: {e}",
            image.display(),
            reference.display()
        ))
    })?;
    let (ma, mb) = (a.mean(), b.mean());
    println!(
        "RMSE {:.6} | relative MSE {:.6} | mean relative error {:.6}",
        m.rmse, m.relative_mse, m.mean_relative_error
    );
    println!(
        "mean RGB {:.6} {:.6} {:.6} vs {:.6} {:.6} {:.6} (ratio {:.4} {:.4} {:.4})",
        ma[0],
        ma[1],
        ma[2],
        mb[0],
        mb[1],
        mb[2],
        ma[0] / mb[0],
        ma[1] / mb[1],
        ma[2] / mb[2]
    );
    Ok(())
}
