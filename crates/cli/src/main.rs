//! `chatter`: stability lobes, multipliers, uncertainty bands and the demo, over the
//! chatter-* crates. Thin by design: parse, call, write.

mod commands;
mod inputs;
mod output;
mod plot;
mod progress;

use clap::{Parser, Subcommand};
use commands::Method;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "chatter",
    version,
    about = "Machining chatter: stability lobes, uncertainty, model updating"
)]
struct Cli {
    /// No progress bars on stderr.
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a model (and observations) file and print a summary.
    Check {
        /// Model file (JSON).
        #[arg(long)]
        model: PathBuf,
        /// Observations file (JSON or cuts CSV).
        #[arg(long)]
        observations: Option<PathBuf>,
    },
    /// Receptance FRF as CSV (frequency_hz, real, imaginary, magnitude in m/N).
    Frf {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Lowest frequency (Hz); default 0.
        #[arg(long)]
        fmin_hz: Option<f64>,
        /// Highest frequency (Hz); default twice the highest natural frequency.
        #[arg(long)]
        fmax_hz: Option<f64>,
        /// Number of frequencies.
        #[arg(long, default_value_t = 1000)]
        points: usize,
        /// Response coordinate (x, y, feed, cutting); default the first.
        #[arg(long)]
        from: Option<String>,
        /// Force coordinate; default the first.
        #[arg(long)]
        to: Option<String>,
        /// Write the CSV here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// SVG magnitude plot.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Limiting depth per spindle speed: CSV speed_rpm,depth_mm,chatter_hz.
    Lobes {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Stability method.
        #[arg(long, value_enum, default_value = "fdm")]
        method: Method,
        /// Speeds MIN:MAX:N (rpm); default around the dominant mode's lobes.
        #[arg(long)]
        speeds: Option<String>,
        /// Observed cuts to draw (o stable, x chatter).
        #[arg(long)]
        observations: Option<PathBuf>,
        /// Write the CSV here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// SVG lobe plot.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Dominant Floquet multiplier at one cut, as JSON.
    Multiplier {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Spindle speed (rpm).
        #[arg(long)]
        speed_rpm: f64,
        /// Depth (milling) or width (turning) of cut (mm).
        #[arg(long)]
        depth_mm: f64,
        /// fdm or sdm.
        #[arg(long, value_enum, default_value = "fdm")]
        method: Method,
    },
    /// Uncertainty bands around the lobes: CSV speed_rpm,depth_mm,lower_mm,upper_mm,...
    Bands {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Band kind (geometric: Type B offsets of seed 001).
        #[arg(long, value_enum, default_value = "geometric")]
        kind: BandKind,
        /// Stability method of the mean boundary.
        #[arg(long, value_enum, default_value = "zoa")]
        method: Method,
        /// Speeds MIN:MAX:N (rpm).
        #[arg(long)]
        speeds: Option<String>,
        /// Speed offset (rpm).
        #[arg(long, default_value_t = 100.0)]
        offset_rpm: f64,
        /// Depth offset (mm).
        #[arg(long, default_value_t = 0.2)]
        offset_mm: f64,
        /// Observed cuts to draw.
        #[arg(long)]
        observations: Option<PathBuf>,
        /// Write the CSV here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// SVG plot.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Run the main job on the embedded examples and write the results to a folder.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "demo-output")]
        out: PathBuf,
    },
}

/// Band kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum BandKind {
    /// Geometric Type B offsets (seed 001).
    Geometric,
}

fn run(cli: Cli) -> anyhow::Result<()> {
    let quiet = cli.quiet;
    match cli.command {
        Command::Check {
            model,
            observations,
        } => commands::check(&model, observations.as_deref()),
        Command::Frf {
            model,
            fmin_hz,
            fmax_hz,
            points,
            from,
            to,
            out,
            plot,
        } => {
            let range = match (fmin_hz, fmax_hz) {
                (None, None) => None,
                (a, Some(b)) => Some((a.unwrap_or(0.0), b)),
                (Some(a), None) => anyhow::bail!("--fmin-hz {a} needs --fmax-hz"),
            };
            commands::frf(
                &model,
                range,
                points,
                (from, to),
                out.as_deref(),
                plot.as_deref(),
            )
        }
        Command::Lobes {
            model,
            method,
            speeds,
            observations,
            out,
            plot,
        } => commands::lobes(
            &model,
            method,
            speeds.as_deref(),
            observations.as_deref(),
            out.as_deref(),
            plot.as_deref(),
            quiet,
        ),
        Command::Multiplier {
            model,
            speed_rpm,
            depth_mm,
            method,
        } => commands::multiplier(&model, speed_rpm, depth_mm, method),
        Command::Bands {
            model,
            kind: BandKind::Geometric,
            method,
            speeds,
            offset_rpm,
            offset_mm,
            observations,
            out,
            plot,
        } => commands::bands_geometric(
            &model,
            method,
            speeds.as_deref(),
            offset_rpm,
            offset_mm,
            observations.as_deref(),
            out.as_deref(),
            plot.as_deref(),
            quiet,
        ),
        Command::Demo { out } => commands::demo(&out, quiet),
    }
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
