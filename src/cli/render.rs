//! `tracelab render`: one image from the command line, with a progress bar
//! and a summary of what it cost; `--debug-sample` replays one path.

use super::choices::*;
use super::shared::{override_resolution, progress_bar};
use super::solver::{render_solver, render_until};
use super::technique::TechniqueFlags;
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tracelab::film::{EXTREME_LUMINANCE, FinalImage, FlaggedPixel};
use tracelab::filter::{FilterSampling, PixelFilter};
use tracelab::image::check_writable;
use tracelab::integrator::{CameraIntegrator, Integrator, SplattingIntegrator};
use tracelab::math::OffsetMode;
use tracelab::render::{Adaptive, RenderSettings, RenderStats, Session};
use tracelab::replay::replay_sample;
use tracelab::sampling::{Domains, SamplerKind};
use tracelab::scene::light::LightSampling;
use tracelab::scene::{Limits, LoadOptions, Scene};
use tracelab::{Error, Result};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file: tracelab TOML, Mitsuba XML, glTF, or a bare OBJ or PLY mesh.
    scene: PathBuf,
    #[command(flatten)]
    pub(crate) technique: TechniqueFlags,
    /// Mitsuba XML: set a parameter `$name` (as Mitsuba's -D).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
    /// Make every warning about the scene file an error.
    #[arg(long)]
    strict: bool,
    /// Samples per pixel.
    #[arg(long, conflicts_with_all = ["time", "rays_per_pixel"])]
    spp: Option<u32>,
    /// Render for this many seconds instead of a sample count (a solver:
    /// solve, then add samples to the image of the solution until then).
    #[arg(long, conflicts_with = "rays_per_pixel")]
    time: Option<f64>,
    /// Render until this many rays per pixel (all kinds) are cast: equal-cost comparisons.
    #[arg(long)]
    rays_per_pixel: Option<f64>,
    /// Sampler (default: the scene file's, else independent).
    #[arg(long, value_enum)]
    sampler: Option<SamplerArg>,
    /// Domains the sampler applies to, the rest independent: any of
    /// pixel,lens,time,light,bsdf (default all).
    #[arg(long, value_parser = parse_domains)]
    domains: Option<Domains>,
    /// How area lights are sampled (default: the scene's, i.e. triangles by
    /// area and spheres by solid angle unless its [lights] table says otherwise).
    #[arg(long, value_enum)]
    light_sampling: Option<LightSamplingArg>,
    /// How rays leave surfaces: `robust` (by the hit's rounding-error bound)
    /// or `fixed:EPS` (the classic epsilon along the normal, to see its artifacts).
    #[arg(long, value_parser = OffsetMode::parse, default_value = "robust")]
    offset: OffsetMode,
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
    /// Adaptive sampling for the least RMSE per time: after N samples in
    /// every pixel, each pass spends its samples (spp x pixels) where the
    /// per-pixel noise is; --spp is then the mean over pixels.
    #[arg(long, value_name = "N", conflicts_with = "adaptive")]
    distribute: Option<u32>,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0)]
    exposure: f32,
    /// Largest accepted image side.
    #[arg(long, default_value_t = Limits::default().max_resolution)]
    max_resolution: u32,
    /// Largest accepted triangle count.
    #[arg(long, default_value_t = Limits::default().max_triangles)]
    max_triangles: usize,
    /// Largest accepted --spp (a typo guard; raise it to render more).
    #[arg(long, default_value_t = 1 << 24)]
    max_spp: u32,
    /// Largest number of rays one MC ray tracing sample may branch into
    /// (M glossy rays per hit to depth D cast about M^(D-1) rays).
    #[arg(long, default_value_t = 1_000_000)]
    max_branch_rays: u64,
    /// Scale down samples whose largest component exceeds this value
    /// (removes fireflies; biased, and the summary says how often it acted).
    #[arg(long)]
    clamp: Option<f32>,
    /// How camera samples meet a tent or Gaussian pixel filter: `splat`
    /// (Mitsuba's film: each sample, uniform in its pixel, adds to every
    /// pixel the filter covers, weighted) or `importance` (pbrt-v4: the
    /// sample's position drawn from the filter, counted in one pixel).
    /// Adaptive sampling and deterministic techniques always use `importance`.
    #[arg(long, value_parser = parse_filter_sampling, default_value = "splat")]
    filter_sampling: FilterSampling,
    /// Replay one sample of the render instead, `X,Y,S` (pixel and sample
    /// index), printing its path's vertices, pdfs and weights.
    #[arg(long, value_parser = parse_debug_sample)]
    debug_sample: Option<(u32, u32, u32)>,
    /// Bidirectional path tracing: write every strategy's image, weighted
    /// and unweighted, and two PNG sheets of the (s, t) pyramid into this
    /// folder instead of one image (one thread, --spp samples).
    #[arg(long)]
    strategies: Option<PathBuf>,
    /// Output file: .exr (linear float32) or .png (tone-mapped sRGB).
    #[arg(long, short, required_unless_present_any = ["debug_sample", "strategies"])]
    out: Option<PathBuf>,
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

fn parse_debug_sample(text: &str) -> std::result::Result<(u32, u32, u32), String> {
    let parts: Vec<std::result::Result<u32, _>> =
        text.split(',').map(|p| p.trim().parse::<u32>()).collect();
    match parts.as_slice() {
        [Ok(x), Ok(y), Ok(s)] => Ok((*x, *y, *s)),
        _ => Err(format!(
            "`{text}`: expected X,Y,S (pixel column, row, sample index)"
        )),
    }
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let output = match &args.out {
        Some(out) if args.debug_sample.is_none() => {
            check_writable(out)?;
            Some((out.as_path(), output_format(out)?))
        }
        _ => None,
    };
    if let Some(t) = args.time
        && !(t.is_finite() && t > 0.0)
    {
        return Err(Error::new(format!(
            "--time must be a positive number of seconds, got {t}"
        )));
    }
    if args.spp == Some(0) {
        return Err(Error::new("--spp must be at least 1"));
    }
    if let Some(spp) = args.spp
        && spp > args.max_spp
    {
        return Err(Error::new(format!(
            "--spp {spp} is above the limit of {} samples per pixel (raise it with --max-spp)",
            args.max_spp
        )));
    }
    let limits = Limits {
        max_resolution: args.max_resolution,
        max_triangles: args.max_triangles,
    };
    let load_start = Instant::now();
    let mut scene = Scene::load_with(
        &args.scene,
        &LoadOptions {
            limits,
            defines: args.define.clone(),
            strict: args.strict,
        },
    )?;
    let hints = scene.hints.clone();
    override_resolution(&mut scene, args.width, args.height, &limits)?;
    if let Some(mode) = args.light_sampling {
        scene.set_light_sampling(match mode {
            LightSamplingArg::Area => LightSampling::Area,
            LightSamplingArg::SolidAngle => LightSampling::SolidAngle,
        });
    }
    scene.set_offset(args.offset);
    for w in &scene.warnings {
        // Importer warnings already name their file and line.
        match w.starts_with(&args.scene.display().to_string()) {
            true => eprintln!("warning: {w}"),
            false => eprintln!("warning: {}: {w}", args.scene.display()),
        }
    }
    let load_time = load_start.elapsed();

    let integrator = args.technique.options(&hints)?.build();
    let sampler = match (args.sampler, &hints.sampler) {
        (Some(s), _) => s.kind(),
        (None, Some(name)) => SamplerArg::from_str(name, true)
            .map_err(|e| Error::new(format!("the scene's sampler: {e}")))?
            .kind(),
        (None, None) => SamplerKind::Independent,
    };
    let spp_arg = args.spp.or(hints.spp);
    if let Some(dir) = &args.strategies {
        let Integrator::Splatting(SplattingIntegrator::Bdpt(bdpt)) = integrator else {
            return Err(Error::new("--strategies needs --integrator bdpt"));
        };
        let spp = spp_arg.unwrap_or(16);
        let sampler = tracelab::sampling::Sampler::new(sampler, args.seed, spp)
            .with_domains(args.domains.unwrap_or_default());
        return super::strategies::write(&scene, &bdpt, &sampler, spp, dir);
    }
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
        Some(spp_arg.unwrap_or(64))
    };
    let settings = RenderSettings {
        integrator,
        sampler,
        seed: args.seed,
        planned_spp: target_spp.unwrap_or(0),
        threads: args.threads,
        adaptive: match (args.adaptive, args.distribute) {
            (Some(threshold), _) => Some(Adaptive::Stop {
                threshold,
                min_spp: args.adaptive_min_spp.max(2),
            }),
            (None, Some(warmup)) => Some(Adaptive::Distribute {
                warmup_spp: warmup.max(2),
            }),
            (None, None) => None,
        },
        domains: args.domains.unwrap_or_default(),
        clamp: args.clamp,
        filter_sampling: args.filter_sampling,
    };
    if let Integrator::Camera(CameraIntegrator::Mcrt(m)) = settings.integrator
        && m.rays_per_sample_closed() > args.max_branch_rays
    {
        return Err(Error::new(format!(
            "MC ray tracing with --glossy-rays {} --shadow-rays {} --max-depth {} would cast up to {} rays per sample, above the limit of {} (raise it with --max-branch-rays)",
            m.glossy_rays,
            m.shadow_rays,
            m.max_depth,
            m.rays_per_sample_closed(),
            args.max_branch_rays
        )));
    }
    if let Some(c) = args.clamp
        && !(c.is_finite() && c > 0.0)
    {
        return Err(Error::new(format!(
            "--clamp must be a positive number, got {c}"
        )));
    }
    if let Some((x, y, index)) = args.debug_sample {
        let (value, lines) = replay_sample(&scene, &settings, x, y, index)?;
        for line in lines {
            println!("{line}");
        }
        return if value.is_finite() {
            Ok(())
        } else {
            Err(Error::new("the replayed sample is not finite"))
        };
    }
    let Some((out, format)) = output else {
        return Err(Error::new("--out FILE is required"));
    };
    let solver = matches!(settings.integrator, Integrator::Solver(_));
    let session = Session::new(Arc::new(scene), settings)?;
    let stats = match (target_spp, args.rays_per_pixel) {
        _ if solver => {
            let stats = render_solver(&session)?;
            match args.time {
                // Converged: the rest of the time adds samples to its image.
                Some(t) => render_until(&session, Duration::from_secs_f64(t)),
                None => stats,
            }
        }
        (Some(spp), _) => render_spp(&session, spp),
        (None, Some(rays)) => render_rays(&session, rays),
        (None, None) => render_time(&session, Duration::from_secs_f64(args.time.unwrap_or(1.0))),
    };
    print_summary(&session, &stats, load_time);
    let (width, seed) = (session.scene().camera.width, settings_seed(&session));
    let non_finite = stats.non_finite;
    let FinalImage { image, flagged } = session.into_final();
    match format {
        OutputFormat::Exr => image.into_exr(out)?,
        OutputFormat::Png => image.write_png(out, args.exposure)?,
    }
    print_flagged(&flagged, non_finite, width, &seed);
    eprintln!("wrote {}", out.display());
    Ok(())
}

fn parse_filter_sampling(text: &str) -> std::result::Result<FilterSampling, String> {
    [FilterSampling::Splat, FilterSampling::Importance]
        .into_iter()
        .find(|f| f.name() == text)
        .ok_or_else(|| format!("expected splat or importance, got {text:?}"))
}

fn parse_domains(text: &str) -> std::result::Result<Domains, String> {
    Domains::parse(text, ',')
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

fn settings_seed(session: &Session) -> String {
    format!("--seed {}", session.settings().seed)
}

/// Where the first non-finite or extreme sample is, and how to replay it.
fn print_flagged(flagged: &[FlaggedPixel], non_finite: u64, width: u32, seed: &str) {
    let extreme: u64 = flagged.iter().map(|f| u64::from(f.extreme)).sum();
    let Some(first) = flagged.first() else {
        return;
    };
    let (x, y) = (first.pixel % width, first.pixel / width);
    let sample = first.first_flagged;
    eprintln!(
        "{non_finite} non-finite and {extreme} extreme samples (luminance > {EXTREME_LUMINANCE}); the first in pixel ({x}, {y}) is sample {sample}: replay it with the same options plus {seed} --debug-sample {x},{y},{sample}"
    );
}

/// What the scene holds, by part: "scene memory: 240 MiB (vertices 48, ...)",
/// parts under 0.5 MiB left out; a scene under 1 MiB in KiB, without parts.
fn memory_line(scene: &Scene) -> String {
    let mb = |bytes: usize| bytes as f64 / (1024.0 * 1024.0);
    let mut parts: Vec<(&str, usize)> = scene.geometry.memory_parts().to_vec();
    parts.push(("textures", scene.texture_bytes()));
    let total: usize = parts.iter().map(|(_, bytes)| bytes).sum();
    if total < 1024 * 1024 {
        return format!("scene memory: {} KiB", total.div_ceil(1024));
    }
    let shown: Vec<String> = parts
        .iter()
        .filter(|(_, bytes)| mb(*bytes) >= 0.5)
        .map(|(name, bytes)| format!("{name} {:.0}", mb(*bytes)))
        .collect();
    format!("scene memory: {:.0} MiB ({})", mb(total), shown.join(", "))
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
    eprintln!("{}", memory_line(session.scene()));
    let filter = session.scene().camera.filter;
    if filter != PixelFilter::Box {
        let how = match session.splats_camera_samples() {
            true => "camera samples splatted (--filter-sampling importance to draw them from it)",
            false => "camera samples drawn from it",
        };
        eprintln!(
            "pixel filter: {} (radius {}), {how}",
            filter.name(),
            filter.radius()
        );
    }
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
        Integrator::Camera(CameraIntegrator::Path(_) | CameraIntegrator::Whitted(_))
    ) {
        let whitted = matches!(
            settings.integrator,
            Integrator::Camera(CameraIntegrator::Whitted(_))
        );
        let general = matches!(settings.integrator, Integrator::Camera(e) if e.is_general());
        let scene = session.scene();
        let mut skipped = scene
            .features
            .skipped(whitted, general, scene.geometry.is_plain());
        if !scene.lights.has_choice() {
            skipped.push("light choice (one light)");
        }
        let what = if general {
            "general code (--general)"
        } else {
            "specialised for this scene"
        };
        if skipped.is_empty() {
            eprintln!("{what}: nothing skipped");
        } else {
            eprintln!("{what}: skipped {}", skipped.join(", "));
        }
    }
    for line in session.shortcut_report() {
        eprintln!("{line}");
    }
    match settings.adaptive {
        Some(Adaptive::Stop { threshold, min_spp }) => {
            let planned = stats.samples + stats.skipped;
            eprintln!(
                "adaptive sampling (biased): {:.1}% of {} planned samples skipped (relative error < {threshold}, after {min_spp} spp)",
                100.0 * stats.skipped as f64 / planned.max(1) as f64,
                planned,
            );
        }
        Some(Adaptive::Distribute { warmup_spp }) => {
            let (min, max) = session.sample_count_range();
            eprintln!(
                "adaptive sampling (slightly biased): samples spread by noise after {warmup_spp} spp; per pixel {min} to {max}"
            );
        }
        None => {}
    }
    if let Some(limit) = settings.clamp {
        eprintln!(
            "clamping (biased): {} of {} samples scaled down to a largest component of {limit}",
            stats.clamped, stats.samples
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

/// `-D name=value`.
pub(crate) fn parse_define(s: &str) -> std::result::Result<(String, String), String> {
    match s.split_once('=') {
        Some((n, v)) if !n.is_empty() => Ok((n.to_string(), v.to_string())),
        _ => Err(format!("expected NAME=VALUE, got \"{s}\"")),
    }
}
