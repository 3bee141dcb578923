//! Command-line interface (clap): argument definitions and the commands
//! (`view` and `compare` here; `render`, `bench` and `stress` in their own files).

mod bench;
mod choices;
mod lab;
mod radiosity;
mod render;
mod shared;
mod solver;
mod strategies;
mod stress;
mod technique;

use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use tracelab::image::Image;
use tracelab::integrator::IntegratorKind;
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
    Render(render::RenderArgs),
    /// Open the live window (the default when no command is given).
    #[cfg(feature = "viewer")]
    View(ViewArgs),
    /// Measure error against a reference at 1, 2, 4, ... spp for several
    /// configurations; print a table, write CSV and log-log plots (SVG or PNG).
    Bench(bench::BenchArgs),
    /// The numerical stress suite: scaled, far-away and awkward scenes against
    /// their references; exits non-zero when a case fails.
    Stress(stress::StressArgs),
    /// The Monte Carlo lab: pi by darts, coin flips, stratified sampling,
    /// importance sampling, point sets, warps, and radiosity's cluster form
    /// factors; prints a table and checks, writes CSV and plots.
    Lab(lab::LabArgs),
    /// Radiosity step by step against a reference: elements, links, rays,
    /// seconds, residual and RMSE per row; CSV and a plot.
    Radiosity(radiosity::RadiosityArgs),
    /// Compare two images: RMSE, relative MSE and mean relative error (as tev computes them), and the RMSE without the worst 0.1% of pixels.
    Compare {
        /// The image to measure.
        image: PathBuf,
        /// The reference.
        reference: PathBuf,
    },
}

/// A technique, by the name it is registered under
/// ([`tracelab::integrator::IntegratorKind`]).
#[derive(Clone, Copy, Debug)]
struct IntegratorArg(IntegratorKind);

impl ValueEnum for IntegratorArg {
    fn value_variants<'a>() -> &'a [Self] {
        static VARIANTS: std::sync::LazyLock<Vec<IntegratorArg>> = std::sync::LazyLock::new(|| {
            IntegratorKind::ALL
                .iter()
                .map(|&k| IntegratorArg(k))
                .collect()
        });
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.summary()))
    }
}

#[cfg(feature = "viewer")]
#[derive(clap::Args, Debug)]
struct ViewArgs {
    /// Scene file (TOML, Mitsuba XML, glTF, or a bare OBJ or PLY); default: the last one, or the Cornell box.
    scene: Option<PathBuf>,
    /// The technique and its settings, as `render` takes them; without
    /// `--integrator` the viewer's saved technique and settings are kept.
    #[command(flatten)]
    technique: technique::TechniqueFlags,
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
    /// Start a side-by-side comparison at equal time, B rendered by this technique.
    #[arg(long, value_enum, conflicts_with = "compare")]
    compare_with: Option<IntegratorArg>,
    /// Start with adaptive sampling by noise on (after 4 spp everywhere).
    #[arg(long)]
    distribute: bool,
    /// What the image area shows first.
    #[arg(long, value_enum)]
    show: Option<ShowArg>,
    /// Render threads (default: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Ignore the settings saved by the last session.
    #[arg(long)]
    fresh: bool,
    /// Folder for exports (default: ./exports).
    #[arg(long)]
    export_dir: Option<PathBuf>,
    /// Open the Monte Carlo lab tab on this experiment.
    #[arg(long, value_enum)]
    lab: Option<lab::ExperimentArg>,
    /// Open BDPT's live strategy images (with --integrator bdpt).
    #[arg(long)]
    strategy_grid: bool,
    /// Mitsuba XML: set a parameter `$name` (as Mitsuba's -D).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = render::parse_define)]
    define: Vec<(String, String)>,
    /// Make every warning about the scene file an error.
    #[arg(long)]
    strict: bool,
}

impl Cli {
    /// True when the command opens the viewer's window rather than
    /// printing to the terminal.
    pub fn opens_window(&self) -> bool {
        #[cfg(feature = "viewer")]
        return matches!(self.command, None | Some(Command::View(_)));
        #[cfg(not(feature = "viewer"))]
        false
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => render::render(&args),
        Some(Command::Compare { image, reference }) => compare(&image, &reference),
        Some(Command::Bench(args)) => bench::bench(&args),
        Some(Command::Stress(args)) => stress::stress(&args),
        Some(Command::Lab(args)) => lab::lab(&args),
        Some(Command::Radiosity(args)) => radiosity::radiosity(&args),
        #[cfg(feature = "viewer")]
        Some(Command::View(args)) => view(args),
        #[cfg(feature = "viewer")]
        // The viewer with every flag at its default.
        None => run(<Cli as clap::Parser>::parse_from(["tracelab", "view"])),
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
        tracelab::image::check_writable(shot)?;
    }
    let launch_kind = args.technique.integrator.map(integrator_kind);
    let technique = match launch_kind {
        Some(_) => Some(args.technique.options(&Default::default())?),
        None if args.technique.any_given() => {
            return Err(Error::new(
                "the viewer takes a technique's settings with --integrator (else it keeps its saved ones)",
            ));
        }
        None => None,
    };
    tracelab::viewer::run(tracelab::viewer::Launch {
        scene: args.scene,
        integrator: launch_kind,
        target_spp: args.spp,
        fresh: args.fresh || args.screenshot.is_some(),
        screenshot: args.screenshot,
        after_spp: args.after_spp,
        compare: args.compare,
        compare_with: args.compare_with.map(integrator_kind),
        distribute: args.distribute,
        show: args.show.map(|s| match s {
            ShowArg::Image => tracelab::viewer::ViewMode::Image,
            ShowArg::Difference => tracelab::viewer::ViewMode::Difference,
            ShowArg::StdError => tracelab::viewer::ViewMode::StandardError,
            ShowArg::Fireflies => tracelab::viewer::ViewMode::Fireflies,
            ShowArg::Samples => tracelab::viewer::ViewMode::Samples,
        }),
        threads: args.threads,
        lab: args.lab.map(|e| e.0),
        strategy_grid: args.strategy_grid,
        export_dir: args.export_dir,
        technique,
        depth_given: args.technique.depth_given(),
        defines: args.define,
        strict: args.strict,
    })
}

/// The viewer's image modes on the command line.
#[cfg(feature = "viewer")]
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum ShowArg {
    Image,
    Difference,
    StdError,
    Fireflies,
    /// Samples per pixel (where adaptive sampling spends them).
    Samples,
}

fn integrator_kind(arg: IntegratorArg) -> IntegratorKind {
    arg.0
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
    if let Some(k) = a.scale_over(&b).filter(|&k| k > 1) {
        eprintln!(
            "note: {} is {k}x the reference's {}x{}: compared box-downsampled by {k}",
            image.display(),
            b.width,
            b.height
        );
    }
    let (ma, mb) = (a.mean(), b.mean());
    println!(
        "RMSE {:.6} | relative MSE {:.6} | mean relative error {:.6} | RMSE without the worst {}% of pixels {:.6}",
        m.rmse,
        m.relative_mse,
        m.mean_relative_error,
        100.0 * tracelab::image::TRIMMED_SHARE,
        m.trimmed_rmse
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
