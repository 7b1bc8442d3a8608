//! `chatter`: stability lobes, multipliers, uncertainty bands and the demo, over the
//! chatter-* crates. Thin by design: parse, call, write.

#![cfg_attr(test, allow(clippy::unwrap_used))]

mod bands;
mod batch;
mod commands;
mod demo;
mod detect;
mod diagnose;
mod inputs;
mod lobe_map;
mod measured;
mod oma;
mod output;
mod papers;
mod plan;
mod plot;
mod progress;
mod rcsa;
mod report;
mod sensitivity;
mod shop;
mod tables;
mod update;
mod validate;

use bands::BandKind;
use chatter_stability::prepared::Method;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
pub use validate::job_error;

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
        /// Speeds MIN:MAX:N (rpm); default lobe numbers ~1 to 12 of the dominant mode, evenly
        /// spaced in lobe number (20 speeds per lobe, 200-2000 speeds) so no lobe is aliased.
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
        /// Resolution of fdm/sdm: steps over the cutting part of one delay (tooth period in
        /// milling, revolution in turning); default automatic (>= 40, 24 per vibration cycle).
        /// At least 1: a discretization with zero steps is refused when the option is parsed.
        #[arg(long)]
        cutting_steps: Option<std::num::NonZeroUsize>,
        /// Map of the dominant multiplier's modulus |mu| over speed x depth: CSV
        /// speed_rpm,depth_mm,modulus (|mu| < 1 stable).
        #[arg(long)]
        map_out: Option<PathBuf>,
        /// SVG heat map of |mu| (blue stable, red chatter) with the lobes.
        #[arg(long)]
        map_plot: Option<PathBuf>,
        /// Depths of the |mu| map MIN:MAX:N (mm); default 80 depths up to 1.5x the deepest limit.
        #[arg(long)]
        depths: Option<String>,
        /// A second panel under the --plot lobes: the surface location error (um) against speed
        /// at --sle-depth-mm, 0.05 mm/tooth (as `chatter sle`).
        #[arg(long)]
        sle: bool,
        /// Depth (mm) of the SLE panel; default half the shallowest limiting depth plotted.
        #[arg(long, requires = "sle")]
        sle_depth_mm: Option<f64>,
    },
    /// Surface location error of stable milling cuts over speeds (Schmitz & Mann 2006): CSV
    /// speed_rpm,sle_um,peak_to_valley_um,modulus,stable (> 0 undercut, < 0 overcut).
    Sle {
        /// Model file (milling, even pitch).
        #[arg(long)]
        model: PathBuf,
        /// Speeds MIN:MAX:N (rpm).
        #[arg(long)]
        speeds: String,
        /// Axial depth of cut (mm).
        #[arg(long)]
        depth_mm: f64,
        /// Feed per tooth (mm); default 0.05.
        #[arg(long, default_value_t = 0.05)]
        feed_per_tooth_mm: f64,
        /// Write the CSV here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// SVG plot of the SLE over the stable speeds.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// The highest-MRR cut stable with probability >= 1 - risk (FDM lobes derated, posterior
    /// samples or bands) within a depth limit and an SLE tolerance, and the Harmonizer's speeds
    /// for a chattering cut, as JSON.
    Recommend {
        /// Model file (milling).
        #[arg(long)]
        model: PathBuf,
        /// Deepest cut the tool or machine takes (mm).
        #[arg(long)]
        max_depth_mm: f64,
        /// Largest surface location error allowed (um).
        #[arg(long)]
        sle_tolerance_um: Option<f64>,
        /// Accepted probability of chatter; default 0.05 (in (0, 0.5] without evidence, (0, 1)
        /// with --posterior or a --bands map).
        #[arg(long)]
        risk: Option<f64>,
        /// Assumed standard deviation of the limiting depth (% of the nominal); default 10;
        /// without --posterior or --bands only.
        #[arg(long)]
        limit_sd_percent: Option<f64>,
        /// Posterior folder of `chatter update` (summary.json, posterior.csv): the depth at each
        /// speed is the risk quantile of the samples' limiting depths.
        #[arg(long)]
        posterior: Option<PathBuf>,
        /// Posterior samples whose boundaries are computed (every k-th); default 200.
        #[arg(long)]
        samples: Option<usize>,
        /// A table of `chatter bands`: its Monte Carlo map (--map-out; any --risk) or its band
        /// CSV (--out; the lower curve, with the band's own risk).
        #[arg(long)]
        bands: Option<PathBuf>,
        /// Feed per tooth (mm) of the SLE and MRR; default 0.05.
        #[arg(long, default_value_t = 0.05)]
        feed_per_tooth_mm: f64,
        /// Speeds MIN:MAX:N (rpm) to choose from; default those of `lobes`.
        #[arg(long)]
        speeds: Option<String>,
        /// Speed (rpm) of a cut that chattered.
        #[arg(long)]
        chatter_speed_rpm: Option<f64>,
        /// Its chatter frequency (Hz).
        #[arg(long)]
        chatter_hz: Option<f64>,
        /// Write the JSON here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
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
        /// Spindle-speed variation: amplitude ratio A in [0, 1) of a sinusoidal speed
        /// Omega_0 (1 + A sin(2 pi r f_0 t)); needs --ssv-frequency-ratio. The multiplier is then
        /// over the modulation period.
        #[arg(long)]
        ssv_amplitude_ratio: Option<f64>,
        /// Spindle-speed variation: frequency ratio r (modulation over spindle frequency), such
        /// that the modulation period holds a whole number of tooth periods (N / r an integer).
        #[arg(long)]
        ssv_frequency_ratio: Option<f64>,
    },
    /// Uncertainty bands around the lobes: CSV speed_rpm,depth_mm,lower_mm,upper_mm,...
    Bands {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Band kind: geometric (Type B offsets in speed and depth), perturbation (credibility
        /// bounds from a parameter covariance) or montecarlo (probability of stability).
        #[arg(long, value_enum, default_value = "geometric")]
        kind: BandKind,
        /// Stability method; default zoa for geometric, fdm otherwise.
        #[arg(long, value_enum)]
        method: Option<Method>,
        /// Speeds MIN:MAX:N (rpm); default as `lobes`: lobe numbers ~1 to 12 of the dominant
        /// mode, 20 speeds per lobe (200-2000 speeds) so no lobe is aliased.
        #[arg(long)]
        speeds: Option<String>,
        /// Depths MIN:MAX:N (mm) of the perturbation grid or the probability map; default 0 to
        /// 1.5 times the deepest limit, 100 depths.
        #[arg(long)]
        depths: Option<String>,
        /// Speed offset (rpm), geometric; default 100.
        #[arg(long)]
        offset_rpm: Option<f64>,
        /// Depth offset (mm), geometric; default 0.2.
        #[arg(long)]
        offset_mm: Option<f64>,
        /// Relative standard deviation of a measured FRF's gain (geometric bands on a model with
        /// measured_frf: the offsets become 2 sd of the lobe pocket over FRF draws).
        #[arg(long)]
        gain_sd: Option<f64>,
        /// Relative standard deviation of a measured FRF's frequency axis (as --gain-sd).
        #[arg(long)]
        frequency_sd: Option<f64>,
        /// Posterior folder of `chatter update` (summary.json, posterior.csv).
        #[arg(long)]
        posterior: Option<PathBuf>,
        /// Covariance file: {"parameter_names": [...], "covariance": [[...]], "mean": [...]}.
        #[arg(long)]
        covariance: Option<PathBuf>,
        /// Monte Carlo parameter samples; default 500.
        #[arg(long)]
        samples: Option<usize>,
        /// Seed of the Monte Carlo draws; default 0.
        #[arg(long)]
        seed: Option<u64>,
        /// Perturbation: bounds of this central credibility of |mu| (e.g. 0.95) instead of the
        /// default: the depths where the dominant multiplier's mean modulus plus (lower bound) or
        /// minus (upper bound) one standard deviation of the complex multiplier reaches 1.
        #[arg(long)]
        coverage: Option<f64>,
        /// Observed cuts to draw.
        #[arg(long)]
        observations: Option<PathBuf>,
        /// Write the CSV here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Monte Carlo: write the P_s map (speed_rpm,depth_mm,p_stable) here.
        #[arg(long)]
        map_out: Option<PathBuf>,
        /// SVG plot.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// One self-contained HTML page: inputs, plots, numbers, verdict, warnings.
        #[arg(long)]
        report: Option<PathBuf>,
    },
    /// Simulate a cut in the time domain; writes a signals CSV or a WAV file.
    Simulate {
        /// Model file.
        #[arg(long)]
        model: PathBuf,
        /// Spindle speed (rpm).
        #[arg(long)]
        speed_rpm: f64,
        /// Depth (milling) or width (turning) of cut (mm).
        #[arg(long)]
        depth_mm: f64,
        /// Signal length (s).
        #[arg(long)]
        duration_s: f64,
        /// Output sample rate (Hz).
        #[arg(long)]
        sample_rate_hz: f64,
        /// Seed of the random force.
        #[arg(long)]
        seed: u64,
        /// Output file, .csv or .wav.
        #[arg(long)]
        out: PathBuf,
        /// Output quantity.
        #[arg(long, value_enum, default_value = "acceleration")]
        quantity: QuantityArg,
        /// RMS of the broadband random force per coordinate (N).
        #[arg(long, default_value_t = 1.0)]
        random_force_n: f64,
        /// Amplitude of spindle-harmonic forcing (N).
        #[arg(long, default_value_t = 0.0)]
        harmonic_force_n: f64,
        /// Feed per tooth (milling) or per revolution (turning), mm.
        #[arg(long, default_value_t = 0.05)]
        feed_per_tooth_mm: f64,
    },
    /// Sim-to-real gap diagnosis: where the model and the observations disagree, which
    /// unmodelled effect explains it, how far the gap shrinks on held-out data. JSON to stdout.
    Diagnose {
        /// Nominal model file.
        #[arg(long)]
        model: PathBuf,
        /// Observations file (JSON or cuts CSV).
        #[arg(long)]
        observations: PathBuf,
        /// Seed of the samplers and the folds.
        #[arg(long)]
        seed: u64,
        /// iTMCMC samples per model class.
        #[arg(long, default_value_t = 120)]
        samples: usize,
        /// Held-out validation of the shrinkage.
        #[arg(long, value_enum, default_value = "kfold")]
        validation: diagnose::ValidationArg,
        /// Folds (or speed bands) of the validation; default 3.
        #[arg(long)]
        folds: Option<usize>,
        /// Folder for diagnosis.json (with residuals), lobes.svg and residuals.svg.
        #[arg(long)]
        out: Option<PathBuf>,
        /// One self-contained HTML page: inputs, plots, numbers, verdict, warnings.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Also write `inference_data/CLASS.nc` under --out for every class: its posterior,
        /// prior draws and pointwise log-likelihood (cuts, then poles) as an ArviZ
        /// InferenceData netCDF-4 file (`arviz.from_netcdf`).
        #[arg(long, requires = "out")]
        netcdf: bool,
    },
    /// Sensitivity |d mu / d theta| of the dominant pole at one cut (000 Table 3) as JSON, on
    /// the one-step map of the full discretization (or the period map).
    Sensitivity(sensitivity::SensitivityArgs),
    /// Bayesian model updating: posterior.csv, summary.json, updated_model.json, evidence and
    /// corner plots in --out.
    Update(update::UpdateArgs),
    /// The next test cut as JSON: value of information (003) or maximum MRR at a risk (004).
    Plan(plan::PlanArgs),
    /// Stable or chatter, and the chatter frequency, for every signal record (observations
    /// JSON with one `cuts` entry per record, evidence in its `note`).
    Detect(detect::DetectArgs),
    /// Operational modal analysis of every signal of an observations file: prints observations
    /// JSON whose `poles` hold the identified dominant poles (modified LSCE with the spindle
    /// harmonics; lifting and polyreference for a milling model). Records that chatter
    /// detection calls chatter are refused.
    Oma(oma::OmaArgs),
    /// Modal fit of a measured FRF (LSCF, stabilization, residual terms): model file, JSON
    /// report on stdout, overlay plot.
    FitFrf(measured::FitFrfArgs),
    /// Tool-tip FRF of a tool-holder-spindle assembly by receptance coupling (RCSA).
    Rcsa(rcsa::RcsaArgs),
    /// Diagnose and plan every machine-tool campaign of a fleet manifest in parallel: one table
    /// row per campaign (verdict, boundary shift, next test).
    Batch(batch::BatchArgs),
    /// The shop-floor web application: setups, tap tests, lobes, cut log, learning, export.
    Serve {
        /// Address to listen on; another than 127.0.0.1 exposes the data to the network.
        #[arg(long, default_value = "127.0.0.1")]
        host: String,
        /// Port (0: any free one, printed).
        #[arg(long, default_value_t = 8080)]
        port: u16,
        /// Data folder: the database and the uploaded files (created if needed).
        #[arg(long, default_value = "chatter-data")]
        data: PathBuf,
        /// Add the example setup (seed 001's mill with its cut log) if it is not there.
        #[arg(long)]
        example: bool,
    },
    /// Run the main job on the embedded examples and write the results to a folder.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "demo-output")]
        out: PathBuf,
    },
}

/// Output quantities of `simulate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum QuantityArg {
    /// m/s^2.
    Acceleration,
    /// m/s.
    Velocity,
    /// m.
    Displacement,
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
            output::check_optional_file("--out", out.as_deref())?;
            output::check_optional_file("--plot", plot.as_deref())?;
            commands::frf(
                &model,
                &chatter_jobs::frf::FrfRequest {
                    fmin_hz,
                    fmax_hz,
                    points,
                    response: from,
                    force: to,
                },
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
            cutting_steps,
            map_out,
            map_plot,
            depths,
            sle,
            sle_depth_mm,
        } => commands::lobes(
            &model,
            method,
            speeds.as_deref(),
            observations.as_deref(),
            out.as_deref(),
            plot.as_deref(),
            &commands::LobeExtras {
                cutting_steps,
                map_out: map_out.as_deref(),
                map_plot: map_plot.as_deref(),
                depths: depths.as_deref(),
                sle: sle.then_some(sle_depth_mm),
            },
            quiet,
        ),
        Command::Sle {
            model,
            speeds,
            depth_mm,
            feed_per_tooth_mm,
            out,
            plot,
        } => shop::sle(&shop::SleRequest {
            model: &model,
            speeds: &speeds,
            depth_mm,
            feed_per_tooth_mm,
            out: out.as_deref(),
            plot: plot.as_deref(),
        }),
        Command::Recommend {
            model,
            max_depth_mm,
            sle_tolerance_um,
            risk,
            limit_sd_percent,
            posterior,
            samples,
            bands,
            feed_per_tooth_mm,
            speeds,
            chatter_speed_rpm,
            chatter_hz,
            out,
        } => shop::recommend(
            shop::RecommendRequest {
                model: &model,
                posterior: posterior.as_deref(),
                bands: bands.as_deref(),
                samples,
                job: chatter_jobs::recommend::RecommendRequest {
                    max_depth_mm,
                    risk,
                    limit_sd_percent,
                    sle_tolerance_um,
                    feed_per_tooth_mm: Some(feed_per_tooth_mm),
                    chatter_speed_rpm,
                    chatter_hz,
                    ..Default::default()
                },
                speeds: speeds.as_deref(),
                out: out.as_deref(),
            },
            quiet,
        ),
        Command::Multiplier {
            model,
            speed_rpm,
            depth_mm,
            method,
            ssv_amplitude_ratio,
            ssv_frequency_ratio,
        } => commands::multiplier(
            &model,
            speed_rpm,
            depth_mm,
            method,
            shop::speed_variation(ssv_amplitude_ratio, ssv_frequency_ratio)?,
            quiet,
        ),
        Command::Bands {
            model,
            kind,
            method,
            speeds,
            depths,
            offset_rpm,
            offset_mm,
            gain_sd,
            frequency_sd,
            posterior,
            covariance,
            samples,
            seed,
            coverage,
            observations,
            out,
            map_out,
            plot,
            report,
        } => bands::bands(&bands::BandRequest {
            model: &model,
            kind,
            method,
            speeds: speeds.as_deref(),
            depths: depths.as_deref(),
            offsets: (offset_rpm, offset_mm),
            frf_sd: (gain_sd, frequency_sd),
            posterior: posterior.as_deref(),
            covariance: covariance.as_deref(),
            samples,
            seed,
            coverage,
            observations: observations.as_deref(),
            out: out.as_deref(),
            map_out: map_out.as_deref(),
            plot: plot.as_deref(),
            report: report.as_deref(),
            quiet,
        }),
        Command::Simulate {
            model,
            speed_rpm,
            depth_mm,
            duration_s,
            sample_rate_hz,
            seed,
            out,
            quantity,
            random_force_n,
            harmonic_force_n,
            feed_per_tooth_mm,
        } => {
            use chatter_dynamics::simulate::Quantity;
            let request = chatter_jobs::simulate::SimulateRequest {
                quantity: match quantity {
                    QuantityArg::Acceleration => Quantity::Acceleration,
                    QuantityArg::Velocity => Quantity::Velocity,
                    QuantityArg::Displacement => Quantity::Displacement,
                },
                random_force_n,
                harmonic_force_n,
                feed_per_tooth_mm,
                ..chatter_jobs::simulate::SimulateRequest::new(
                    speed_rpm,
                    depth_mm,
                    duration_s,
                    sample_rate_hz,
                    seed,
                )
            };
            let s = request.check().map_err(job_error)?;
            output::check_file("--out", &out)?;
            commands::simulate(&model, &s, &out, quiet)
        }
        Command::Diagnose {
            model,
            observations,
            seed,
            samples,
            validation,
            folds,
            out,
            report,
            netcdf,
        } => diagnose::run(
            &diagnose::DiagnoseRequest {
                model: &model,
                observations: &observations,
                seed,
                samples,
                validation,
                folds: folds.unwrap_or(3),
                out: out.as_deref(),
                report: report.as_deref(),
                netcdf,
                quiet,
            },
            folds.is_some(),
        ),
        Command::Sensitivity(args) => sensitivity::run(&args),
        Command::Update(args) => update::run(&args, quiet),
        Command::Plan(args) => plan::run(&args, quiet),
        Command::Detect(args) => detect::run(&args),
        Command::Oma(args) => oma::run(&args),
        Command::FitFrf(args) => measured::fit_frf(&args),
        Command::Rcsa(args) => rcsa::rcsa(&args),
        Command::Batch(args) => batch::run(&args, quiet),
        Command::Demo { out } => demo::demo(&out, quiet),
        Command::Serve {
            host,
            port,
            data,
            example,
        } => {
            let options = chatter_serve::ServeOptions::new(&host, port, data, example)?;
            if let Some(w) = chatter_serve::exposure_warning(options.host) {
                eprintln!("warning: {w}");
            }
            Ok(chatter_serve::serve(&options, |a| {
                println!("chatter serve: listening on http://{a}/ (Ctrl-C stops)");
            })?)
        }
    }
}

/// The command line with negative numbers accepted as option values (`--depth-mm -1` reaches
/// the range check instead of being taken for a flag) and the `MIN:MAX:N` and list options
/// taking values that start with a hyphen.
fn command() -> clap::Command {
    use clap::CommandFactory;
    const HYPHEN_VALUES: [&str; 5] = [
        "speeds",
        "depths",
        "classes",
        "harmonics_hz",
        "interference_hz",
    ];
    Cli::command().mut_subcommands(|sub| {
        let mut sub = sub.allow_negative_numbers(true);
        for id in HYPHEN_VALUES {
            if sub.get_arguments().any(|a| a.get_id() == id) {
                sub = sub.mut_arg(id, |a| a.allow_hyphen_values(true));
            }
        }
        sub
    })
}

/// The error and its causes on one line, each cause once: a cause whose text its parent
/// already quotes (an OS error inside a file error) is not repeated.
fn message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}

fn main() {
    use clap::FromArgMatches;
    let cli = command();
    let matches = cli.clone().get_matches();
    if let Some((name, sub)) = matches.subcommand() {
        validate::remember_typed(sub);
        if let Some(command) = cli.find_subcommand(name) {
            report::remember_invocation(command, sub);
        }
    }
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Err(e) = run(cli) {
        eprintln!("error: {}", message(&e));
        std::process::exit(1);
    }
}
