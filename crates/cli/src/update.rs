//! `chatter update`: Bayesian model updating (000, 002, 004) over model classes, writing the
//! posterior samples, a summary, the updated model and evidence / corner plots.

use crate::output::Folder;
use crate::progress::Bar;
use anyhow::{Context, Result, anyhow, bail};
use chatter_bayes::tmcmc::SamplerObserver;
use chatter_updating::classes::{ClassObserver, Sampler, SamplerOptions};
use chatter_updating::parameters::parse_model_parameters;
use chatter_updating::update::{PriorOverrides, UpdateJob, UpdateResult, UpdateSettings};
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
    /// theta_k_N, kt_n_per_mm2, kn_n_per_mm2, c_n_per_m); default: the most sensitive mode's.
    #[arg(long)]
    parameters: Option<String>,
    /// Priors file: {"NAME": {"kind": "uniform"|"normal"|"truncated_normal"|"log_normal", ...}};
    /// unnamed parameters keep the papers' priors.
    #[arg(long)]
    priors: Option<PathBuf>,
    /// Model classes alpha, comma-separated; default 2^-5.5..2^2 (turning), 0.001..1 (milling).
    #[arg(long)]
    classes: Option<String>,
    /// Samples per class.
    #[arg(long, default_value_t = 5000)]
    samples: usize,
    /// Seed.
    #[arg(long)]
    seed: u64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

/// Progress: one step per model class.
struct ClassProgress(Bar);

impl SamplerObserver for ClassProgress {
    fn stage(&self, index: usize, beta: f64, acceptance: f64) {
        self.0.detail(&format!(
            "stage {index}, beta {beta:.3}, acceptance {acceptance:.2}"
        ));
    }
    fn chain_progress(&self, chain: usize, done: usize, total: usize) {
        self.0
            .detail(&format!("chain {chain}: {done}/{total} samples"));
    }
}

impl ClassObserver for ClassProgress {
    fn class_started(&self, index: usize, _total: usize, _alpha: f64) {
        self.0.set(index);
    }
}

/// What `--out` of `chatter update` may hold.
pub const FILES: [&str; 5] = [
    "posterior.csv",
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
    let folder = Folder::new("--out", &args.out, &FILES)?;
    crate::validate::count(
        "--samples",
        args.samples,
        10,
        1_000_000,
        "samples per class",
    )?;
    let model = crate::inputs::model(&args.model)?;
    let observations = crate::inputs::observations(&args.observations)?;
    crate::validate::observations_match(&model, &observations, &args.observations, &args.model)?;
    let priors: PriorOverrides = match &args.priors {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading the priors file {}", path.display()))?;
            serde_json::from_str(&text)
                .with_context(|| format!("{}: invalid priors file", path.display()))?
        }
        None => PriorOverrides::new(),
    };
    let settings = UpdateSettings {
        parameters: args
            .parameters
            .as_deref()
            .map(parse_model_parameters)
            .transpose()?,
        priors,
        classes: args.classes.as_deref().map(parse_classes).transpose()?,
    };
    let job = UpdateJob::new(&model, &observations, &settings)?;
    if args.classes.is_some() && job.alphas().is_empty() {
        bail!(
            "--classes is not used with these observations: {} has no poles, and the cut \
             likelihood (004) has no model classes",
            args.observations.display()
        );
    }
    crate::validate::observation_work_size(&model, &observations, &args.observations)?;
    let options = SamplerOptions {
        sampler: match args.sampler {
            SamplerArg::Itmcmc => Sampler::Itmcmc,
            SamplerArg::Tmcmc => Sampler::Tmcmc,
            SamplerArg::Amcmc => Sampler::Amcmc,
        },
        samples: args.samples,
        seed: args.seed,
    };
    let progress = ClassProgress(Bar::new(
        job.alphas().len().max(1) as u64,
        "model classes",
        quiet,
    ));
    let result = job.run(&options, &progress)?;
    progress.0.finish();
    for c in &result.classes {
        if let Some(n) = c.numerical_failures.filter(|&n| n > 0) {
            let class = c.alpha.map_or(String::new(), |a| format!(" alpha {a}"));
            eprintln!(
                "warning: model class{class}: {n} likelihood evaluations failed numerically \
                 (rejected and counted; see `numerical_failures` in summary.json)"
            );
        }
    }
    write_outputs(folder, &result, &model)
}

fn write_outputs(
    mut out: Folder,
    r: &UpdateResult,
    nominal: &chatter_dynamics::ModalModel,
) -> Result<()> {
    // posterior.csv: one row per sample, the parameters then the sample weight
    let mut csv = r.parameter_names.join(",") + ",weight\n";
    for (s, w) in r.samples.samples().iter().zip(r.samples.weights()) {
        let row: Vec<String> = s.iter().map(|v| format!("{v:e}")).collect();
        csv += &format!("{},{w:e}\n", row.join(","));
    }
    out.add("posterior.csv", csv);
    let n = r.posterior_covariance.nrows();
    let covariance: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| r.posterior_covariance[(i, j)]).collect())
        .collect();
    let summary = serde_json::json!({
        "parameter_names": r.parameter_names,
        "posterior_mean": r.posterior_mean,
        "posterior_covariance": covariance,
        "classes": r.classes,
        "selected_alpha": r.selected_alpha,
    });
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
    out.add("evidence.svg", evidence_plot(r)?);
    out.add("corner.svg", corner_plot(r)?);
    out.commit().map(drop)
}

fn plot_err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("plot: {e}")
}

fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let span = (hi - lo).abs().max(1e-12 * lo.abs().max(1e-300));
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// Log-evidence against log2(alpha) (000 Fig. 4a).
fn evidence_plot(r: &UpdateResult) -> Result<String> {
    let pts: Vec<(f64, f64)> = r
        .classes
        .iter()
        .filter_map(|c| c.alpha.map(|a| (a.log2(), c.log_evidence)))
        .filter(|p| p.1.is_finite())
        .collect();
    let (x0, x1) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.0), a.1.max(p.0))
    });
    let (y0, y1) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        if pts.is_empty() {
            root.titled("no model classes (cut likelihood)", ("sans-serif", 20))
                .map_err(plot_err)?;
        } else {
            let (x0, x1) = padded(x0, x1);
            let (y0, y1) = padded(y0, y1);
            let mut chart = ChartBuilder::on(&root)
                .caption("Model evidence per class", ("sans-serif", 20))
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("log2(alpha)")
                .y_desc("ln p(D | M)")
                .draw()
                .map_err(plot_err)?;
            chart
                .draw_series(LineSeries::new(pts.clone(), BLUE.stroke_width(2)))
                .map_err(plot_err)?;
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, BLUE.filled())))
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}

/// Histograms on the diagonal, pairwise scatter below it (000 Fig. 5).
fn corner_plot(r: &UpdateResult) -> Result<String> {
    let d = r.parameter_names.len();
    let samples = r.samples.samples();
    let ranges: Vec<(f64, f64)> = (0..d)
        .map(|k| {
            let (lo, hi) = samples
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, s| {
                    (a.0.min(s[k]), a.1.max(s[k]))
                });
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
                let top = counts.iter().copied().fold(0.0, f64::max).max(1e-300);
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
            } else {
                let (y0, y1) = ranges[i];
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
