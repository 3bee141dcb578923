//! `tracelab lab <experiment>`: runs one Monte Carlo lab experiment with a
//! progress bar, prints its text, tables and checks, and writes CSV and
//! plots. Exits non-zero when a check does not hold.

use super::choices::SamplerArg;
use super::shared::progress_bar;
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::time::Duration;
use tracelab::lab::{Experiment, LabRunner};
use tracelab::plot::{PlotFormat, write_figure};
use tracelab::{Error, Result};

#[derive(Args, Debug)]
pub struct LabArgs {
    /// The experiment.
    #[arg(value_enum)]
    experiment: ExperimentArg,
    /// Write every table here (CSV, one header row per table).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the figures here (.svg or .png); with several, the first gets
    /// this name and the others `NAME-<figure>.ext` beside it.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Seed of every random number.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Largest sample count (default: the experiment's).
    #[arg(long)]
    n: Option<u32>,
    /// Independent runs the error statistics average over (default: the experiment's).
    #[arg(long)]
    runs: Option<u32>,
    /// Sampler of the scatter plot and the periodogram (pi, point-sets).
    #[arg(long, value_enum, default_value = "independent")]
    sampler: SamplerArg,
}

/// An experiment, by its name in [`Experiment::name`].
#[derive(Clone, Copy, Debug)]
pub(super) struct ExperimentArg(pub(super) Experiment);

impl ValueEnum for ExperimentArg {
    fn value_variants<'a>() -> &'a [Self] {
        const VARIANTS: [ExperimentArg; Experiment::ALL.len()] = {
            let mut all = [ExperimentArg(Experiment::Pi); Experiment::ALL.len()];
            let mut i = 0;
            while i < all.len() {
                all[i] = ExperimentArg(Experiment::ALL[i]);
                i += 1;
            }
            all
        };
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.label()))
    }
}

pub fn lab(args: &LabArgs) -> Result<()> {
    // Refuse a bad output name before the work, not after it.
    if let Some(plot) = &args.plot {
        PlotFormat::of(plot)?;
    }
    let experiment = args.experiment.0;
    let mut settings = experiment.default_settings();
    settings.seed = args.seed;
    settings.sampler = args.sampler.kind();
    settings.n = args.n.unwrap_or(settings.n);
    settings.runs = args.runs.unwrap_or(settings.runs);
    experiment.check(&settings).map_err(Error::new)?;
    println!("{}\n", experiment.label());
    println!("{}\n", wrap(experiment.text(), 88));
    let mut runner = LabRunner::start(settings);
    let bar = progress_bar(1, "units");
    while runner.is_running() {
        let (done, planned) = runner.progress().counts();
        bar.set_length(planned.max(1));
        bar.set_position(done);
        std::thread::sleep(Duration::from_millis(100));
    }
    bar.finish_and_clear();
    let report = runner
        .report()
        .filter(|_| !runner.was_cancelled())
        .ok_or_else(|| Error::new("the experiment stopped before it finished"))?;
    print!("{}", report.to_text());
    eprintln!("({:.1} s)", runner.seconds());
    if let Some(csv) = &args.csv {
        report.write_csv(csv)?;
        eprintln!("wrote {}", csv.display());
    }
    if let Some(plot) = &args.plot {
        for (i, figure) in report.figures.iter().enumerate() {
            let path = if i == 0 {
                plot.clone()
            } else {
                sibling(plot, &figure.slug(), i)
            };
            write_figure(&path, figure)?;
            eprintln!("wrote {}", path.display());
        }
    }
    let failed = report.checks.iter().filter(|c| !c.holds).count();
    if failed > 0 {
        return Err(Error::new(format!(
            "{failed} of {} checks did not hold (statistical checks fail by chance at their \
             stated rate; another --seed tells chance from a real fault)",
            report.checks.len()
        )));
    }
    Ok(())
}

/// `dir/stem-<slug>.ext` for figure `index` beside `plot`.
fn sibling(plot: &Path, slug: &str, index: usize) -> PathBuf {
    let stem = plot
        .file_stem()
        .map_or("plot".into(), |s| s.to_string_lossy());
    let ext = plot
        .extension()
        .map_or("svg".into(), |s| s.to_string_lossy());
    let slug = if slug.is_empty() {
        index.to_string()
    } else {
        format!("{index}-{slug}")
    };
    plot.with_file_name(format!("{stem}-{slug}.{ext}"))
}

/// `text` broken into lines of at most `width` characters.
fn wrap(text: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = 0;
    for word in text.split_whitespace() {
        let len = word.chars().count();
        if line > 0 && line + 1 + len > width {
            out.push('\n');
            line = 0;
        } else if line > 0 {
            out.push(' ');
            line += 1;
        }
        out.push_str(word);
        line += len;
    }
    out
}
