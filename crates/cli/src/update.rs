//! `chatter update`: Bayesian model updating (000, 002, 004) over model classes, writing the
//! posterior samples, a summary, the updated model and evidence / corner plots.

use crate::output::Folder;
use crate::progress::Bar;
use anyhow::{Result, anyhow, bail};
use chatter_jobs::inference_data::{Draws, InferenceData};
use chatter_jobs::update::{PreparedUpdate, UpdateRequest};
use chatter_progress::Observer;
use chatter_updating::classes::Sampler;
use chatter_updating::parameters::parse_model_parameters;
use chatter_updating::update::UpdateResult;
use plotters::prelude::*;
use std::path::PathBuf;

/// Posterior samplers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerArg {
    /// Improved transitional MCMC (000).
    Itmcmc,
    /// Transitional MCMC (002).
    Tmcmc,
    /// Rejection sampling + parallel adaptive MCMC (004).
    Amcmc,
}

/// Arguments of `chatter update`.
#[derive(Debug, clap::Args)]
pub struct UpdateArgs {
    /// Model file (JSON).
    #[arg(long)]
    model: PathBuf,
    /// Observations: identified poles (000 turning, 002 milling) or test cuts (004).
    #[arg(long)]
    observations: PathBuf,
    /// Posterior sampler.
    #[arg(long, value_enum, default_value = "itmcmc")]
    sampler: SamplerArg,
    /// Parameters to update, comma-separated (theta_omega_N, theta_zeta_N, theta_phi_N,
    /// theta_k_N, kt_n_per_mm2, kn_n_per_mm2, c_n_per_m, ks_n_per_mm2, beta_deg, fnN_hz,
    /// kN_n_per_m, zetaN); default: the most sensitive mode's.
    #[arg(long)]
    parameters: Option<String>,
    /// Priors file: {"NAME": {"kind": "uniform"|"normal"|"truncated_normal"|"log_normal", ...}}
    /// (unnamed parameters keep the papers' priors), or a correlated normal
    /// {"parameter_names", "mean", "covariance"} (e.g. examples/schmitz2022_rcsa_prior.json; its names are
    /// then the updated parameters unless --parameters is given).
    #[arg(long)]
    priors: Option<PathBuf>,
    /// Stability method of the cut likelihood (cut results only): fdm (default), sdm, or zoa
    /// (the zero-order method 004 used; complex modes and residual terms need it).
    #[arg(long, value_enum)]
    method: Option<chatter_stability::prepared::Method>,
    /// Model classes alpha, comma-separated; default 2^-5.5..2^2 (turning), 0.001..1 (milling).
    #[arg(long)]
    classes: Option<String>,
    /// Samples per class.
    #[arg(long, default_value_t = 5000)]
    samples: usize,
    /// Milling poles (002): `gp` replaces the exact monodromy eigenvalues by the Matérn GP
    /// surrogate of 002 Section 2.2, trained on the exact model over the prior box; `exact`
    /// computes them for every sample. Default: gp for milling poles (the only data it applies to).
    #[arg(long, value_enum)]
    surrogate: Option<SurrogateArg>,
    /// Training points of the GP surrogate (Halton points of the prior box).
    #[arg(long, default_value_t = chatter_updating::surrogate::DEFAULT_TRAINING_POINTS)]
    surrogate_points: usize,
    /// Seed.
    #[arg(long)]
    seed: u64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// One self-contained HTML page: inputs, plots, numbers, verdict, warnings.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write `inference_data.nc`: the selected class's posterior, prior draws and pointwise
    /// log-likelihood as an ArviZ InferenceData netCDF-4 file (`arviz.from_netcdf`); needs an
    /// equally weighted sampler (itmcmc, tmcmc).
    #[arg(long)]
    netcdf: bool,
}

/// Likelihood evaluation of milling poles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SurrogateArg {
    /// Matérn GP surrogate of the dominant multiplier (002 Section 2.2).
    Gp,
    /// The exact monodromy eigenvalue for every sample.
    Exact,
}

/// Progress: one step per model class.
struct ClassProgress(Bar);

impl Observer for ClassProgress {
    fn stage(&self, index: usize, beta: f64, acceptance: f64) {
        self.0.detail(&format!(
            "stage {index}, beta {beta:.3}, acceptance {acceptance:.2}"
        ));
    }
    fn chain_progress(&self, chain: usize, done: usize, total: usize) {
        self.0
            .detail(&format!("chain {chain}: {done}/{total} samples"));
    }

    fn class_started(&self, index: usize, _total: usize, _alpha: f64) {
        self.0.set(index);
    }
}

/// What `--out` of `chatter update` may hold.
pub const FILES: [&str; 7] = [
    "posterior.csv",
    "inference_data.nc",
    "poles.csv",
    "summary.json",
    "updated_model.json",
    "evidence.svg",
    "corner.svg",
];

/// `--classes`: distinct numbers > 0.
fn parse_classes(spec: &str) -> Result<Vec<f64>> {
    let mut alphas: Vec<f64> = Vec::new();
    for s in spec.split(',').map(str::trim) {
        let alpha = s
            .parse::<f64>()
            .ok()
            .filter(|a| a.is_finite() && *a > 0.0)
            .ok_or_else(|| anyhow!("--classes {spec}: `{s}` is not a number > 0"))?;
        if alphas.contains(&alpha) {
            bail!("--classes {spec}: `{s}` is given twice; expected distinct classes");
        }
        alphas.push(alpha);
    }
    Ok(alphas)
}

/// Run `chatter update`.
pub fn run(args: &UpdateArgs, quiet: bool) -> Result<()> {
    let mut folder = Folder::new("--out", &args.out, &FILES)?;
    crate::output::check_optional_file("--report", args.report.as_deref())?;
    let model = crate::inputs::model(&args.model)?;
    let observations = crate::inputs::observations(&args.observations)?;
    crate::validate::observations_match(&model, &observations, &args.observations, &args.model)?;
    let (priors, joint_prior) = crate::inputs::priors(args.priors.as_deref())?;
    let request = UpdateRequest {
        sampler: match args.sampler {
            SamplerArg::Itmcmc => Sampler::Itmcmc,
            SamplerArg::Tmcmc => Sampler::Tmcmc,
            SamplerArg::Amcmc => Sampler::Amcmc,
        },
        samples: args.samples,
        seed: args.seed,
        parameters: args
            .parameters
            .as_deref()
            .map(parse_model_parameters)
            .transpose()?,
        priors,
        joint_prior,
        method: args.method,
        classes: args.classes.as_deref().map(parse_classes).transpose()?,
        surrogate_points: match args.surrogate {
            Some(SurrogateArg::Gp) | None => Some(args.surrogate_points),
            Some(SurrogateArg::Exact) => None,
        },
    };
    if args.netcdf && matches!(args.sampler, SamplerArg::Amcmc) {
        bail!(
            "--netcdf with --sampler amcmc: its samples carry unequal weights, while ArviZ takes \
             every draw as equally weighted; expected --sampler itmcmc or tmcmc"
        );
    }
    let job = PreparedUpdate::new(&model, &observations, request).map_err(crate::job_error)?;
    crate::validate::observation_work_size(&model, &observations, &args.observations)?;
    let progress = ClassProgress(Bar::new(
        job.job().alphas().len().max(1) as u64,
        "model classes",
        quiet,
    ));
    let outcome = job.run(&progress).map_err(crate::job_error)?;
    progress.0.finish();
    let result = outcome.result;
    let warnings = chatter_jobs::update::warnings(&result);
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if let Some(s) = &result.surrogate {
        eprintln!(
            "GP surrogate ({} training points): held-out pole errors rms {:.3} Hz / {:.2e} \
             damping (max {:.3} Hz / {:.2e}); |ln L error| at {} posterior samples mean {:.3}, \
             max {:.3}",
            s.held_out.training_points,
            s.held_out.rms_frequency_error_hz,
            s.held_out.rms_damping_error,
            s.held_out.max_frequency_error_hz,
            s.held_out.max_damping_error,
            s.posterior_points,
            s.mean_abs_ln_likelihood_error,
            s.max_abs_ln_likelihood_error
        );
    }
    if args.netcdf {
        let samples = result.samples.samples();
        let pointwise = job
            .job()
            .pointwise_log_likelihood(result.selected_alpha, samples)?;
        let selected = result
            .classes
            .iter()
            .find(|c| c.alpha == result.selected_alpha);
        let mut attributes = vec![("selected_alpha", result.selected_alpha.unwrap_or(f64::NAN))];
        attributes.extend(selected.map(|c| ("log_evidence", c.log_evidence)));
        let data = InferenceData {
            posterior: Draws {
                names: &result.parameter_names,
                rows: samples,
            },
            prior: Some(Draws {
                names: &result.parameter_names,
                rows: &outcome.prior_draws,
            }),
            log_likelihood: Some(&pointwise),
            attributes,
        };
        folder.add(
            "inference_data.nc",
            data.to_netcdf().map_err(crate::job_error)?,
        );
    }
    let figures = write_outputs(folder, &result, &model, &outcome.prior_draws)?;
    match &args.report {
        Some(path) => {
            crate::report::jobs::update(&model, &observations, &result, &figures)?.write(path)
        }
        None => Ok(()),
    }
}

/// Write the result into its folder; returns the plots written (name, SVG) for the report page.
fn write_outputs(
    mut out: Folder,
    r: &UpdateResult,
    nominal: &chatter_dynamics::ModalModel,
    prior: &[Vec<f64>],
) -> Result<[(&'static str, String); 2]> {
    // posterior.csv: one row per sample, the parameters then the sample weight
    let mut csv = r.parameter_names.join(",") + ",weight\n";
    for (s, w) in r.samples.samples().iter().zip(r.samples.weights()) {
        let row: Vec<String> = s.iter().map(|v| format!("{v:e}")).collect();
        csv += &format!("{},{w:e}\n", row.join(","));
    }
    out.add("posterior.csv", csv);
    if !r.pole_table.is_empty() {
        let mut t = String::from(
            "speed_rpm,depth_mm,identified_hz,identified_damping,nominal_hz,nominal_damping,\
             updated_hz,updated_damping\n",
        );
        for p in &r.pole_table {
            t += &format!(
                "{},{},{},{},{},{},{},{}\n",
                p.speed_rpm,
                p.depth_mm,
                p.identified_hz,
                p.identified_damping,
                p.nominal_hz,
                p.nominal_damping,
                p.updated_hz,
                p.updated_damping
            );
        }
        out.add("poles.csv", t);
    }
    let summary = chatter_updating::update::PosteriorSummary::of(r);
    out.add(
        "summary.json",
        serde_json::to_string_pretty(&summary)? + "\n",
    );
    let name = format!(
        "{} (updated: posterior mean)",
        nominal.name().unwrap_or("model")
    );
    let updated = r.updated_model.with_name(Some(name));
    out.add("updated_model.json", updated.to_json_string() + "\n");
    let figures = [
        ("evidence.svg", evidence_plot(r)?),
        ("corner.svg", corner_plot(r, prior)?),
    ];
    for (name, svg) in &figures {
        out.add(*name, svg.clone());
    }
    out.commit()?;
    Ok(figures)
}

fn plot_err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("plot: {e}")
}

fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let span = (hi - lo).abs().max(1e-12 * lo.abs().max(1e-300));
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// Model classes against log2(alpha): (a) the log-evidence with the two terms of 000 Eq. 33,
/// data fit E[ln p(D | theta)] and information gain (Fig. 4a); (b) the class probabilities
/// p(M | D) of Eq. 32 (Fig. 4b).
fn evidence_plot(r: &UpdateResult) -> Result<String> {
    let classes: Vec<_> = r
        .classes
        .iter()
        .filter_map(|c| c.alpha.map(|a| (a.log2(), c)))
        .filter(|p| p.1.log_evidence.is_finite())
        .collect();
    let curve = |f: &dyn Fn(&chatter_updating::update::ClassSummary) -> Option<f64>| {
        classes
            .iter()
            .filter_map(|(x, c)| f(c).filter(|v| v.is_finite()).map(|v| (*x, v)))
            .collect::<Vec<_>>()
    };
    let terms = [
        (
            "ln p(D | M) (evidence)",
            curve(&|c| Some(c.log_evidence)),
            BLUE,
        ),
        (
            "E[ln p(D | theta, M)] (data fit)",
            curve(&|c| c.data_fit),
            GREEN,
        ),
        (
            "E[ln posterior / prior] (information gain)",
            curve(&|c| c.information_gain),
            RED,
        ),
    ];
    let probabilities = curve(&|c| Some(c.probability));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 800)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        if classes.is_empty() {
            root.titled("no model classes (cut likelihood)", ("sans-serif", 20))
                .map_err(plot_err)?;
        } else {
            let (top, bottom) = root.split_vertically(480);
            let (x0, x1) = padded(
                classes.iter().map(|c| c.0).fold(f64::INFINITY, f64::min),
                classes
                    .iter()
                    .map(|c| c.0)
                    .fold(f64::NEG_INFINITY, f64::max),
            );
            let ys = terms.iter().flat_map(|t| t.1.iter().map(|p| p.1));
            let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |a, y| {
                (a.0.min(y), a.1.max(y))
            });
            let (y0, y1) = padded(y0, y1);
            let mut chart = ChartBuilder::on(&top)
                .caption(
                    "(a) Model evidence per class and its two terms (Eq. 33)",
                    ("sans-serif", 18),
                )
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("log2(alpha)")
                .y_desc("nats")
                .draw()
                .map_err(plot_err)?;
            for (label, pts, color) in &terms {
                let color = *color;
                chart
                    .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                    .map_err(plot_err)?
                    .label(*label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                    .map_err(plot_err)?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(plot_err)?;
            let width = 0.4 * (x1 - x0) / (classes.len() as f64 + 1.0);
            let mut chart = ChartBuilder::on(&bottom)
                .caption(
                    "(b) Class probabilities p(M | D) (Eq. 32)",
                    ("sans-serif", 18),
                )
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, 0.0..1.05)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("log2(alpha)")
                .y_desc("p(M | D)")
                .draw()
                .map_err(plot_err)?;
            chart
                .draw_series(probabilities.iter().map(|&(x, p)| {
                    Rectangle::new([(x - width, 0.0), (x + width, p)], BLUE.mix(0.6).filled())
                }))
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

/// 000 Fig. 5: on the diagonal the posterior histogram of each parameter with the Gaussian of
/// the posterior mean and standard deviation (the fit of 000 Section 6.4), on the posterior's
/// range; below it pairwise scatter of prior draws (grey) and posterior samples (blue) on the
/// range of both.
fn corner_plot(r: &UpdateResult, prior: &[Vec<f64>]) -> Result<String> {
    let d = r.parameter_names.len();
    let samples = r.samples.samples();
    let span = |rows: &mut dyn Iterator<Item = f64>| {
        rows.fold((f64::INFINITY, f64::NEG_INFINITY), |a, x| {
            (a.0.min(x), a.1.max(x))
        })
    };
    let ranges: Vec<(f64, f64)> = (0..d)
        .map(|k| {
            let (lo, hi) = span(&mut samples.iter().map(|s| s[k]));
            padded(lo, hi)
        })
        .collect();
    let joint: Vec<(f64, f64)> = (0..d)
        .map(|k| {
            let (lo, hi) = span(
                &mut samples
                    .iter()
                    .chain(prior)
                    .map(|s| s[k])
                    .filter(|x| x.is_finite()),
            );
            padded(lo, hi)
        })
        .collect();
    let cell = 220u32;
    let side = cell * d as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (side, side)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let cells = root.split_evenly((d, d));
        for (idx, area) in cells.iter().enumerate() {
            let (i, j) = (idx / d, idx % d);
            if j > i {
                continue;
            }
            let (x0, x1) = ranges[j];
            if i == j {
                let bins = 30usize;
                let width = (x1 - x0) / bins as f64;
                let mut counts = vec![0.0; bins];
                for (s, w) in samples.iter().zip(r.samples.weights()) {
                    let b = (((s[j] - x0) / width) as usize).min(bins - 1);
                    counts[b] += w;
                }
                let (m, sd) = (r.posterior_mean[j], r.posterior_covariance[(j, j)].sqrt());
                let total: f64 = counts.iter().sum();
                let peak = if sd > 0.0 {
                    total * width / (sd * (2.0 * std::f64::consts::PI).sqrt())
                } else {
                    0.0
                };
                let top = counts.iter().copied().fold(peak, f64::max).max(1e-300);
                let mut chart = ChartBuilder::on(area)
                    .caption(&r.parameter_names[j], ("sans-serif", 12))
                    .margin(6)
                    .x_label_area_size(20)
                    .build_cartesian_2d(x0..x1, 0.0..top * 1.05)
                    .map_err(plot_err)?;
                chart
                    .configure_mesh()
                    .disable_y_mesh()
                    .x_labels(3)
                    .y_labels(0)
                    .draw()
                    .map_err(plot_err)?;
                chart
                    .draw_series(counts.iter().enumerate().map(|(b, &c)| {
                        let left = x0 + b as f64 * width;
                        Rectangle::new([(left, 0.0), (left + width, c)], BLUE.mix(0.6).filled())
                    }))
                    .map_err(plot_err)?;
                // the fitted Gaussian, scaled to the histogram's mass per bin
                if sd > 0.0 {
                    let curve = (0..=200).map(|q| {
                        let x = x0 + (x1 - x0) * f64::from(q) / 200.0;
                        let z = (x - m) / sd;
                        let pdf = (-0.5 * z * z).exp() / (sd * (2.0 * std::f64::consts::PI).sqrt());
                        (x, total * width * pdf)
                    });
                    chart
                        .draw_series(LineSeries::new(curve, RED.stroke_width(2)))
                        .map_err(plot_err)?;
                }
            } else {
                let ((x0, x1), (y0, y1)) = (joint[j], joint[i]);
                let mut chart = ChartBuilder::on(area)
                    .margin(6)
                    .x_label_area_size(20)
                    .y_label_area_size(40)
                    .build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(plot_err)?;
                chart
                    .configure_mesh()
                    .x_labels(3)
                    .y_labels(3)
                    .draw()
                    .map_err(plot_err)?;
                chart
                    .draw_series(
                        prior
                            .iter()
                            .filter(|s| s[j].is_finite() && s[i].is_finite())
                            .map(|s| {
                                Circle::new((s[j], s[i]), 1, RGBColor(170, 170, 170).filled())
                            }),
                    )
                    .map_err(plot_err)?;
                let step = (samples.len() / 2000).max(1);
                chart
                    .draw_series(
                        samples
                            .iter()
                            .step_by(step)
                            .map(|s| Circle::new((s[j], s[i]), 1, BLUE.mix(0.4).filled())),
                    )
                    .map_err(plot_err)?;
            }
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}
