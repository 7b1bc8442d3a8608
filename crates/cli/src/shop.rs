//! `chatter sle` and `chatter recommend`: parse, build the request of
//! `chatter_jobs::sle` / `chatter_jobs::recommend`, write.

use crate::output::{check_optional_file, emit};
use crate::plot::{Series, line_chart};
use crate::{inputs, validate};
use anyhow::{Result, bail};
use chatter_jobs::recommend::{
    BandsTable, Basis, Evidence, LowerBand, Recommend, RecommendOutcome,
};
use chatter_jobs::sle::{Sle, SleOutcome, SleRequest as SleJob};
use plotters::style::RGBColor;
use std::path::Path;

/// Options of `chatter sle`.
pub struct SleRequest<'a> {
    pub model: &'a Path,
    pub speeds: &'a str,
    pub depth_mm: f64,
    pub feed_per_tooth_mm: f64,
    pub out: Option<&'a Path>,
    pub plot: Option<&'a Path>,
}

/// The SLE job at `speeds_rpm` for `model` (errors in the options' words).
pub fn sle_outcome(
    model: &chatter_dynamics::ModalModel,
    speeds_rpm: Vec<f64>,
    depth_mm: f64,
    feed_per_tooth_mm: f64,
) -> Result<SleOutcome> {
    let job = Sle::new(
        model,
        SleJob {
            speeds_rpm,
            depth_mm,
            feed_per_tooth_mm: Some(feed_per_tooth_mm),
        },
    )
    .map_err(crate::job_error)?;
    job.run().map_err(crate::job_error)
}

/// `chatter sle`: CSV `speed_rpm,sle_um,peak_to_valley_um,modulus,stable` (|mu| by FDM at the
/// depth, so unstable speeds are marked: their forced response is not what the cut leaves).
pub fn sle(r: &SleRequest) -> Result<()> {
    check_optional_file("--out", r.out)?;
    check_optional_file("--plot", r.plot)?;
    let speeds = validate::speeds(r.speeds)?;
    let model = inputs::model(r.model)?;
    let outcome = sle_outcome(&model, speeds, r.depth_mm, r.feed_per_tooth_mm)?;
    let mut csv = String::from("speed_rpm,sle_um,peak_to_valley_um,modulus,stable\n");
    for row in &outcome.rows {
        csv.push_str(&format!(
            "{},{},{},{},{}\n",
            row.speed_rpm,
            row.sle_um,
            row.peak_to_valley_um,
            row.modulus,
            row.stable()
        ));
    }
    if let Some(p) = r.plot {
        line_chart(
            p,
            &sle_title(&outcome),
            "spindle speed (rpm)",
            "SLE (um)",
            &[sle_series(&outcome)],
            None,
        )?;
    }
    emit(r.out, &csv)
}

/// The title of an SLE plot.
pub fn sle_title(outcome: &SleOutcome) -> String {
    format!(
        "Surface location error at {} mm, {} mm/tooth (stable speeds; > 0 undercut)",
        outcome.depth_mm, outcome.feed_per_tooth_mm
    )
}

/// The SLE (um) over the stable speeds, broken (NaN) at the unstable ones.
pub fn sle_series(outcome: &SleOutcome) -> Series {
    Series {
        label: "SLE".into(),
        points: outcome
            .rows
            .iter()
            .map(|r| (r.speed_rpm, if r.stable() { r.sle_um } else { f64::NAN }))
            .collect(),
        color: RGBColor(31, 119, 180),
        dashed: false,
    }
}

/// Options of `chatter recommend`.
pub struct RecommendRequest<'a> {
    pub model: &'a Path,
    pub posterior: Option<&'a Path>,
    pub bands: Option<&'a Path>,
    pub samples: Option<usize>,
    pub job: chatter_jobs::recommend::RecommendRequest,
    pub speeds: Option<&'a str>,
    pub out: Option<&'a Path>,
}

/// `chatter recommend`: JSON with the highest-MRR cut stable with probability >= 1 - P (the
/// nominal lobes derated, posterior samples or a bands table) and, given a chattering speed
/// and frequency, the Harmonizer's speeds, each with its reasons.
pub fn recommend(r: RecommendRequest, quiet: bool) -> Result<()> {
    check_optional_file("--out", r.out)?;
    let mut job = r.job;
    job.samples = r.samples;
    if let Some(spec) = r.speeds {
        job.speeds_rpm = Some(validate::speeds(spec)?);
    }
    let model = inputs::model(r.model)?;
    let evidence = match (r.posterior, r.bands) {
        (Some(_), Some(_)) => bail!(
            "give either --posterior DIR or --bands FILE, not both: the stable depth comes from \
             one of them"
        ),
        (Some(dir), None) => {
            validate::posterior_matches(&model, dir)?;
            Evidence::posterior(dir).map_err(|e| anyhow::anyhow!("--posterior: {e}"))?
        }
        (None, Some(file)) => {
            Evidence::Bands(BandsTable::read(file).map_err(|e| anyhow::anyhow!("--bands: {e}"))?)
        }
        (None, None) => Evidence::Nominal,
    };
    let posterior = matches!(evidence, Evidence::Posterior(_));
    let job = Recommend::new(&model, evidence, job).map_err(crate::job_error)?;
    let outcome = if posterior {
        let samples = job_samples(r.samples);
        let bar = crate::progress::Bar::new(samples as u64, "posterior samples", quiet);
        job.run(&bar)
    } else {
        job.run(&chatter_progress::Silent)
    }
    .map_err(crate::job_error)?;
    let json = recommend_json(r.model, &outcome);
    emit(r.out, &(serde_json::to_string_pretty(&json)? + "\n"))
}

/// The posterior samples a recommendation computes.
fn job_samples(samples: Option<usize>) -> usize {
    samples.unwrap_or(chatter_jobs::recommend::POSTERIOR_SAMPLES)
}

/// The JSON of a recommendation.
fn recommend_json(model: &Path, o: &RecommendOutcome) -> serde_json::Value {
    let (basis, extra) = match &o.basis {
        Basis::Derated { limit_sd_percent } => (
            "derated nominal fdm lobes",
            serde_json::json!({ "limit_sd_percent": limit_sd_percent }),
        ),
        Basis::Posterior { samples, failures } => (
            "posterior samples",
            serde_json::json!({ "samples": samples, "failures": failures }),
        ),
        Basis::StabilityMap => ("Monte Carlo probability map", serde_json::json!({})),
        Basis::LowerBand(LowerBand::TypeB) => ("Type B lower boundary", serde_json::json!({})),
        Basis::LowerBand(LowerBand::Credibility) => {
            ("lower credibility bound", serde_json::json!({}))
        }
        Basis::LowerBand(LowerBand::MonteCarloQ05) => {
            ("Monte Carlo 5 % quantile", serde_json::json!({}))
        }
    };
    let harmonizer = o.harmonizer.as_ref().map(|h| {
        serde_json::json!({
            "chatter_speed_rpm": h.chatter_speed_rpm,
            "chatter_hz": h.chatter_hz,
            "speeds": h.speeds,
        })
    });
    serde_json::json!({
        "model": model.display().to_string(),
        "method": "fdm",
        "basis": basis,
        "evidence": extra,
        "risk": o.risk,
        "limit_sd_percent": match o.basis {
            Basis::Derated { limit_sd_percent } => Some(limit_sd_percent),
            _ => None,
        },
        "probability_of_stability": o.probability_of_stability,
        "feed_per_tooth_mm": o.feed_per_tooth_mm,
        "cut": o.cut,
        "harmonizer": harmonizer,
    })
}

/// `--ssv-amplitude-ratio` and `--ssv-frequency-ratio`: both or neither.
pub fn speed_variation(
    amplitude: Option<f64>,
    frequency: Option<f64>,
) -> Result<Option<chatter_stability::ssv::SpeedVariation>> {
    match (amplitude, frequency) {
        (None, None) => Ok(None),
        (Some(a), Some(r)) => chatter_stability::ssv::SpeedVariation::new(a, r)
            .map(Some)
            .map_err(|e| {
                anyhow::anyhow!(
                    "--ssv-amplitude-ratio {} --ssv-frequency-ratio {}: {e}",
                    validate::as_typed("--ssv-amplitude-ratio", a),
                    validate::as_typed("--ssv-frequency-ratio", r)
                )
            }),
        (Some(_), None) => bail!("--ssv-amplitude-ratio needs --ssv-frequency-ratio"),
        (None, Some(_)) => bail!("--ssv-frequency-ratio needs --ssv-amplitude-ratio"),
    }
}
