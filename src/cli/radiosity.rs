//! Radiosity on the command line: the flags `render` and `radiosity` share,
//! and `tracelab radiosity SCENE --reference REF.exr`, which prints one row
//! per iteration (elements, links, rays, seconds, unshot or changed power,
//! RMSE against the reference with and without the pixels that see lights)
//! and writes them as CSV and a plot.

use super::shared::override_resolution;
use super::solver::drive_solver;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::sync::Arc;
use tracelab::image::{Image, check_writable};
use tracelab::integrator::radiosity::{Radiosity, RadiosityDisplay};
use tracelab::integrator::{IntegratorKind, IntegratorOptions, Settings};
use tracelab::plot::{Figure, PlotFormat, Series, SeriesStyle, log_log_plot, write_figure};
use tracelab::radiosity::{FormFactorMethod, RadiositySolver};
use tracelab::render::{RenderSettings, Session};
use tracelab::sampling::SamplerKind;
use tracelab::scene::{Limits, Scene};
use tracelab::{Error, Result};

#[derive(ValueEnum, Clone, Copy, Debug)]
enum SolverArg {
    Jacobi,
    GaussSeidel,
    /// Progressive refinement (shooting).
    Progressive,
    /// Hierarchical radiosity (links refined by the BF oracle).
    Hierarchical,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum DisplayArg {
    Flat,
    Smooth,
    Gather,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum FormFactorArg {
    Analytic,
    RayCast,
}

/// The radiosity technique's flags; each left out keeps the setting it
/// applies to ([`Radiosity`]'s defaults on the command line).
#[derive(Args, Debug)]
pub struct RadiosityFlags {
    /// Radiosity: the solver [default: gauss-seidel].
    #[arg(long, value_enum)]
    solver: Option<SolverArg>,
    /// Radiosity, progressive solver: add the ambient term to the display.
    #[arg(long)]
    ambient_term: bool,
    /// Radiosity: sweeps (Jacobi, Gauss-Seidel) or shots (progressive) to
    /// run; 0 runs until the solution stops changing [default: 0].
    #[arg(long)]
    iterations: Option<u32>,
    /// Radiosity: longest element edge (the smallest one, hierarchical),
    /// as a fraction of the scene's diagonal [default: 0.1].
    #[arg(long)]
    patch_size: Option<f32>,
    /// Radiosity, hierarchical: a link may carry at most this share of the
    /// emitted power (smaller: more links, more accuracy, more time)
    /// [default: 1e-4].
    #[arg(long)]
    epsilon: Option<f32>,
    /// Radiosity: samples (point pairs or points) per element pair for form
    /// factors [default: 16 analytic, 256 ray-cast].
    #[arg(long)]
    ff_rays: Option<u32>,
    /// Radiosity: how the solution is shown (`flat`, `smooth`, or `gather`:
    /// direct light sampled, indirect read from the solution) [default: gather].
    #[arg(long, value_enum)]
    display: Option<DisplayArg>,
    /// Radiosity: form factors by the point-to-polygon contour integral
    /// times visibility (`analytic`) or by point pairs (`ray-cast`)
    /// [default: analytic].
    #[arg(long, value_enum)]
    ff_method: Option<FormFactorArg>,
    /// Radiosity, Jacobi, Gauss-Seidel or progressive: rounds of adaptive
    /// subdivision after the first solve (split elements where neighbours
    /// differ) [default: 0].
    #[arg(long)]
    adaptive_rounds: Option<u32>,
    /// Radiosity: adaptive subdivision splits an element whose reflected
    /// radiance differs from a neighbour's by more than this times the mean
    /// [default: 0.5].
    #[arg(long)]
    adaptive_tolerance: Option<f32>,
    /// Radiosity, matrix solvers: adaptive subdivision leaves elements with
    /// an angle under this many degrees whole (their four children would be
    /// as thin; 20 leaves the slivers beside discontinuity lines whole)
    /// [default: 0].
    #[arg(long)]
    adaptive_min_angle: Option<f32>,
    /// Radiosity: draw the elements' edges over the image, coloured by level.
    #[arg(long)]
    wireframe: bool,
    /// Radiosity: split receivers along the umbra and penumbra boundaries
    /// of polygonal lights first (discontinuity meshing; drawn in cyan
    /// with --wireframe).
    #[arg(long)]
    discontinuity_meshing: bool,
    /// Radiosity, matrix solvers, with --discontinuity-meshing: keep the
    /// regular elements of the mesh without lines and split only those a
    /// line crosses (better at fine meshes, worse at coarse ones).
    #[arg(long)]
    lines_on_regular_mesh: bool,
    /// Radiosity, lines on the regular mesh (implied): an element that a
    /// line crosses stays whole where a piece would be smaller than this
    /// fraction of its area (0.035 pays at coarse meshes) [default: 0].
    #[arg(long)]
    min_piece_area: Option<f32>,
    /// Radiosity, matrix solvers: discontinuity meshing that keeps a
    /// penumbra's boundary lines only where the penumbra is narrower than
    /// this many patch sizes (0: contact lines only) [default: every line].
    #[arg(long)]
    max_penumbra: Option<f32>,
}

impl RadiosityFlags {
    /// True when any of these flags was given.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub fn any_given(&self) -> bool {
        self.solver.is_some()
            || self.ambient_term
            || self.iterations.is_some()
            || self.patch_size.is_some()
            || self.epsilon.is_some()
            || self.ff_rays.is_some()
            || self.display.is_some()
            || self.ff_method.is_some()
            || self.adaptive_rounds.is_some()
            || self.adaptive_tolerance.is_some()
            || self.adaptive_min_angle.is_some()
            || self.wireframe
            || self.discontinuity_meshing
            || self.lines_on_regular_mesh
            || self.min_piece_area.is_some()
            || self.max_penumbra.is_some()
    }

    /// `settings` with the flags given applied, checked.
    pub fn apply(&self, settings: &mut Radiosity) -> Result<()> {
        if let Some(solver) = self.solver {
            settings.solver = match solver {
                SolverArg::Jacobi => RadiositySolver::Jacobi,
                SolverArg::GaussSeidel => RadiositySolver::GaussSeidel,
                SolverArg::Progressive => RadiositySolver::Progressive,
                SolverArg::Hierarchical => RadiositySolver::Hierarchical,
            };
        }
        if let Some(method) = self.ff_method {
            settings.form_factors = match method {
                FormFactorArg::Analytic => FormFactorMethod::Analytic,
                FormFactorArg::RayCast => FormFactorMethod::RayCast,
            };
            settings.form_factor_samples = settings.form_factors.default_samples();
        }
        settings.form_factor_samples = self.ff_rays.unwrap_or(settings.form_factor_samples);
        settings.epsilon = self.epsilon.unwrap_or(settings.epsilon);
        settings.patch_size = self.patch_size.unwrap_or(settings.patch_size);
        settings.iterations = self.iterations.unwrap_or(settings.iterations);
        settings.adaptive_rounds = self.adaptive_rounds.unwrap_or(settings.adaptive_rounds);
        settings.adaptive_tolerance = self
            .adaptive_tolerance
            .unwrap_or(settings.adaptive_tolerance);
        settings.adaptive_min_angle = self
            .adaptive_min_angle
            .unwrap_or(settings.adaptive_min_angle);
        settings.ambient |= self.ambient_term;
        settings.wireframe |= self.wireframe;
        let regular = self.lines_on_regular_mesh || self.min_piece_area.is_some();
        settings.discontinuity |=
            self.discontinuity_meshing || regular || self.max_penumbra.is_some();
        settings.lines_on_regular_mesh |= regular;
        settings.min_piece_area = self.min_piece_area.unwrap_or(settings.min_piece_area);
        settings.max_penumbra = self.max_penumbra.or(settings.max_penumbra);
        if let Some(display) = self.display {
            settings.display = match display {
                DisplayArg::Flat => RadiosityDisplay::Flat,
                DisplayArg::Smooth => RadiosityDisplay::Smooth,
                DisplayArg::Gather => RadiosityDisplay::Gather,
            };
        }
        settings.validate().map_err(Error::new)
    }

    /// The default settings with the flags applied, checked.
    pub fn settings(&self) -> Result<Radiosity> {
        let mut settings = Radiosity::default();
        self.apply(&mut settings)?;
        Ok(settings)
    }
}

#[derive(Args, Debug)]
pub struct RadiosityArgs {
    /// Scene file (TOML, Mitsuba XML, glTF, or a bare OBJ or PLY).
    scene: PathBuf,
    /// The image to measure against (EXR, the scene's resolution).
    #[arg(long)]
    reference: PathBuf,
    /// Write the rows here (CSV).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Plot RMSE and residual against steps here (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Render threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Reference pixels brighter than this (any channel) see a light and
    /// are left out of the masked RMSE.
    #[arg(long, default_value_t = 1.0)]
    mask_above: f32,
    /// Hierarchical: solve once per epsilon (comma-separated) to
    /// convergence, printing the converged rows and the slope of links
    /// against elements.
    #[arg(long, value_delimiter = ',')]
    sweep_epsilon: Vec<f32>,
    /// Solve once per patch size (comma-separated): the smallest element
    /// (hierarchical) or the mesh (the other solvers).
    #[arg(long, value_delimiter = ',')]
    sweep_patch_size: Vec<f32>,
    /// Plot the sweeps' links against elements here (log-log, .svg or .png).
    #[arg(long)]
    scaling_plot: Option<PathBuf>,
    #[command(flatten)]
    radiosity: RadiosityFlags,
}

/// RMSE of `image` against `reference` over all pixels, and over those
/// whose reference stays at or below `mask_above`.
fn rmse(image: &Image, reference: &Image, mask_above: f32) -> (f64, f64, usize) {
    let (mut all, mut masked, mut kept) = (0.0f64, 0.0f64, 0usize);
    for (p, r) in image.pixels.iter().zip(&reference.pixels) {
        let e: f64 = (0..3).map(|c| ((p[c] - r[c]) as f64).powi(2)).sum::<f64>() / 3.0;
        all += e;
        if r.iter().all(|&v| v <= mask_above) {
            masked += e;
            kept += 1;
        }
    }
    let n = image.pixels.len().max(1) as f64;
    ((all / n).sqrt(), (masked / kept.max(1) as f64).sqrt(), kept)
}

/// One row of `tracelab radiosity`: steps, elements, links, shadow rays,
/// bytes, solve seconds, residual, RMSE, masked RMSE, display seconds.
type Row = (u64, u64, u64, u64, u64, f64, f64, f64, f64, f64);

/// Solves with `options`, returning a row after each pass and printing it
/// if `echo`.
fn run(
    scene: Arc<Scene>,
    reference: &Image,
    options: IntegratorOptions,
    args: &RadiosityArgs,
    echo: bool,
) -> Result<Vec<Row>> {
    let settings = RenderSettings {
        integrator: options.build(),
        sampler: SamplerKind::Independent,
        seed: 0,
        planned_spp: 0,
        threads: args.threads,
        adaptive: None,
        domains: Default::default(),
        clamp: None,
        filter_sampling: Default::default(),
    };
    let session = Session::new(scene, settings)?;
    if echo {
        print_header("steps");
    }
    let mut rows = Vec::new();
    drive_solver(&session, |stats, progress| {
        let (all, masked, _) = rmse(&session.snapshot().image, reference, args.mask_above);
        // The solver's own time (form factors included), without drawing the image.
        let row = (
            progress.steps,
            progress.elements,
            progress.links,
            stats.rays.shadow,
            progress.memory,
            progress.solve_seconds,
            progress.residual,
            all,
            masked,
            progress.display_seconds,
        );
        if echo {
            print_row(&format!("{}", row.0), &row);
        }
        rows.push(row);
    })?;
    Ok(rows)
}

/// The rows' header, the first column named `first`.
fn print_header(first: &str) {
    println!(
        "{:>10} {:>9} {:>11} {:>9} {:>9} {:>9} {:>10} {:>11} {:>9} {:>13}",
        first,
        "elements",
        "links",
        "rays M",
        "MB",
        "solve s",
        "display s",
        "residual",
        "RMSE",
        "masked RMSE"
    );
}

/// One row, its first column `first`.
fn print_row(first: &str, row: &Row) {
    let &(_, elements, links, rays, bytes, seconds, residual, all, masked, display) = row;
    println!(
        "{:>10} {:>9} {:>11} {:>9.2} {:>9.1} {:>9.3} {:>10.3} {:>11.3e} {:>9.5} {:>13.5}",
        first,
        elements,
        links,
        rays as f64 * 1e-6,
        bytes as f64 * 1e-6,
        seconds,
        display,
        residual,
        all,
        masked
    );
}

pub fn radiosity(args: &RadiosityArgs) -> Result<()> {
    let settings = args.radiosity.settings()?;
    check_sweeps(args)?;
    for path in [&args.csv, &args.plot, &args.scaling_plot]
        .into_iter()
        .flatten()
    {
        check_writable(path)?;
    }
    if let Some(plot) = &args.scaling_plot {
        PlotFormat::of(plot)?;
    }
    if let Some(plot) = &args.plot {
        PlotFormat::of(plot)?;
    }
    let limits = Limits::default();
    let mut scene = Scene::load_with_limits(&args.scene, &limits)?;
    let reference = Image::read(&args.reference)?;
    override_resolution(
        &mut scene,
        Some(reference.width),
        Some(reference.height),
        &limits,
    )?;
    let options = IntegratorOptions {
        radiosity: settings,
        ..IntegratorOptions::of(IntegratorKind::Radiosity)
    };
    let scene = Arc::new(scene);
    if !args.sweep_epsilon.is_empty() || !args.sweep_patch_size.is_empty() {
        return sweep(scene, &reference, options, args);
    }
    let rows = run(scene.clone(), &reference, options, args, true)?;
    // Progressive refinement: the plot shows both ambient settings.
    let other = if options.radiosity.solver == RadiositySolver::Progressive && args.plot.is_some() {
        let mut other = options;
        other.radiosity.ambient = !options.radiosity.ambient;
        println!(
            "and {} the ambient term, for the plot:",
            if other.radiosity.ambient {
                "with"
            } else {
                "without"
            }
        );
        Some(run(scene, &reference, other, args, true)?)
    } else {
        None
    };
    if let Some(path) = &args.csv {
        let mut text = String::from(
            "steps,elements,links,shadow_rays,bytes,solve_seconds,display_seconds,residual,rmse,\
             masked_rmse\n",
        );
        for (steps, elements, links, rays, bytes, seconds, residual, all, masked, display) in &rows
        {
            text.push_str(&format!(
                "{steps},{elements},{links},{rays},{bytes},{seconds},{display},{residual},{all},\
                 {masked}\n"
            ));
        }
        tracelab::image::write_atomically(path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| e.to_string())
        })?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.plot {
        let mut series = vec![
            (
                "masked RMSE".to_string(),
                rows.iter().map(|r| (r.0 as f64, r.8)).collect::<Vec<_>>(),
            ),
            (
                "residual".to_string(),
                rows.iter().map(|r| (r.0 as f64, r.6)).collect(),
            ),
        ];
        if let Some(other_rows) = &other {
            let (this, that) = if options.radiosity.ambient {
                ("with ambient", "without ambient")
            } else {
                ("without ambient", "with ambient")
            };
            series[0].0 = format!("masked RMSE, {this}");
            series[1].0 = format!("unshot power, {this}");
            series.push((
                format!("masked RMSE, {that}"),
                other_rows.iter().map(|r| (r.0 as f64, r.8)).collect(),
            ));
            series.push((
                format!("unshot power, {that}"),
                other_rows.iter().map(|r| (r.0 as f64, r.6)).collect(),
            ));
        }
        let series: Vec<Series> = series
            .iter()
            .enumerate()
            .map(|(i, (name, points))| Series::new(name, SeriesStyle::Line, i, points))
            .collect();
        log_log_plot(
            path,
            "Radiosity: error against steps",
            "steps",
            "RMSE / residual",
            &series,
        )?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Refuses sweeps that mean nothing: values out of range, epsilon without
/// the hierarchy, and plots that do not go with them.
fn check_sweeps(args: &RadiosityArgs) -> Result<()> {
    let sweeping = !args.sweep_epsilon.is_empty() || !args.sweep_patch_size.is_empty();
    if let Some(e) = args
        .sweep_epsilon
        .iter()
        .find(|e| !(**e > 0.0 && e.is_finite()))
    {
        return Err(Error::new(format!(
            "--sweep-epsilon values must be positive, got {e}"
        )));
    }
    if let Some(s) = args
        .sweep_patch_size
        .iter()
        .find(|s| !(**s > 0.0 && **s <= 1.0))
    {
        return Err(Error::new(format!(
            "--sweep-patch-size values must be in (0, 1], got {s}"
        )));
    }
    if !args.sweep_epsilon.is_empty()
        && !matches!(args.radiosity.solver, Some(SolverArg::Hierarchical))
    {
        return Err(Error::new(
            "--sweep-epsilon needs --solver hierarchical (epsilon is its oracle's)",
        ));
    }
    if sweeping && args.plot.is_some() {
        return Err(Error::new(
            "--plot draws one solve's steps; with a sweep, use --scaling-plot",
        ));
    }
    if !sweeping && args.scaling_plot.is_some() {
        return Err(Error::new(
            "--scaling-plot needs --sweep-epsilon or --sweep-patch-size",
        ));
    }
    Ok(())
}

/// Solves once per swept value to convergence; prints the converged rows
/// and, per sweep, the slope of links against elements on log-log (the
/// scaling of hierarchical radiosity: 2 for a full matrix, 1 for
/// Hanrahan's O(n)); writes the rows as CSV and the plot.
fn sweep(
    scene: Arc<Scene>,
    reference: &Image,
    options: IntegratorOptions,
    args: &RadiosityArgs,
) -> Result<()> {
    let sweeps = [
        ("epsilon", &args.sweep_epsilon),
        ("patch size", &args.sweep_patch_size),
    ];
    let mut csv = String::from(
        "sweep,value,steps,elements,links,shadow_rays,bytes,solve_seconds,display_seconds,\
         residual,rmse,masked_rmse\n",
    );
    let mut series = Vec::new();
    for (name, values) in sweeps {
        if values.is_empty() {
            continue;
        }
        println!("{name} sweep (converged):");
        print_header(name);
        let mut points = Vec::new();
        for &value in values {
            let mut run_options = options;
            if name == "epsilon" {
                run_options.radiosity.epsilon = value;
            } else {
                run_options.radiosity.patch_size = value;
            }
            let rows = run(scene.clone(), reference, run_options, args, false)?;
            let Some(last) = rows.last() else { continue };
            let label = if name == "epsilon" {
                format!("{value:e}")
            } else {
                format!("{value}")
            };
            print_row(&label, last);
            let (steps, elements, links, rays, bytes, seconds, residual, all, masked, display) =
                *last;
            csv.push_str(&format!(
                "{name},{value},{steps},{elements},{links},{rays},{bytes},{seconds},{display},\
                 {residual},{all},{masked}\n"
            ));
            points.push((elements as f64, links as f64));
        }
        let slope = tracelab::lab::stats::log_log_slope(&points);
        let label = if slope.is_finite() {
            println!("links grow as elements^{slope:.2} over the {name} sweep");
            format!("{name} sweep (slope {slope:.2})")
        } else {
            format!("{name} sweep")
        };
        series.push(Series::new(
            &label,
            SeriesStyle::Line,
            series.len(),
            &points,
        ));
    }
    if let Some(path) = &args.csv {
        tracelab::image::write_atomically(path, |tmp| {
            std::fs::write(tmp, &csv).map_err(|e| e.to_string())
        })?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.scaling_plot {
        // Guides of slope 1 (Hanrahan's O(n)) and 2 (a full matrix) from
        // the first point.
        let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.clone()).collect();
        if let Some(&(x0, y0)) = all.first() {
            let x1 = all.iter().map(|p| p.0).fold(x0, f64::max);
            for (guide, slope) in [("links ~ elements", 1.0), ("links ~ elements²", 2.0)] {
                series.push(Series::new(
                    guide,
                    SeriesStyle::Guide,
                    7,
                    &[(x0, y0), (x1, y0 * (x1 / x0).powf(slope))],
                ));
            }
        }
        let figure = Figure::log_log(
            "Radiosity: links against elements",
            "elements (leaves)",
            "links",
            series,
        );
        write_figure(path, &figure)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
