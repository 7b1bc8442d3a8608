//! `chatter sle` and `chatter recommend`: parse, call `chatter_dynamics::sle` and
//! `chatter_stability::recommend`, write.

use crate::output::{check_optional_file, emit};
use crate::plot::{Series, line_chart};
use crate::{inputs, validate};
use anyhow::{Result, bail};
use chatter_dynamics::limits::{DEPTH_MM, SPEED_RPM};
use chatter_dynamics::sle::surface_location_error;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;
use chatter_stability::recommend::{RecommendOptions, harmonic_speeds, highest_mrr_cut};
use chatter_stability::speed_grid::default_speeds_rpm;
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

/// `chatter sle`: CSV `speed_rpm,sle_um,peak_to_valley_um,modulus,stable` (|mu| by FDM at the
/// depth, so unstable speeds are marked: their forced response is not what the cut leaves).
pub fn sle(r: &SleRequest) -> Result<()> {
    check_optional_file("--out", r.out)?;
    check_optional_file("--plot", r.plot)?;
    let depth_mm = validate::option("--depth-mm", r.depth_mm, &DEPTH_MM)?;
    let feed_mm = validate::option(
        "--feed-per-tooth-mm",
        r.feed_per_tooth_mm,
        &chatter_jobs::simulate::FEED_MM,
    )?;
    let speeds = validate::speeds(r.speeds)?;
    let model = inputs::model(r.model)?;
    if let Some(d) = Method::Fdm.discretization() {
        validate::work_size(&model, d, &speeds, "--speeds")?;
    }
    let fdm = Method::Fdm.prepare(&model, &BoundaryOptions::default())?;
    let mut csv = String::from("speed_rpm,sle_um,peak_to_valley_um,modulus,stable\n");
    let mut points = Vec::new();
    for &rpm in &speeds {
        let s = surface_location_error(&model, rpm, depth_mm * 1e-3, feed_mm * 1e-3)?;
        let mu = fdm.dominant_multiplier(rpm, depth_mm * 1e-3)?.modulus();
        csv.push_str(&format!(
            "{rpm},{},{},{mu},{}\n",
            s.sle_m * 1e6,
            s.peak_to_valley_m * 1e6,
            mu < 1.0
        ));
        points.push((rpm, if mu < 1.0 { s.sle_m * 1e6 } else { f64::NAN }));
    }
    if let Some(p) = r.plot {
        line_chart(
            p,
            &format!(
                "Surface location error at {depth_mm} mm, {feed_mm} mm/tooth (stable speeds; \
                 > 0 undercut)"
            ),
            "spindle speed (rpm)",
            "SLE (um)",
            &[Series {
                label: "SLE".into(),
                points,
                color: RGBColor(31, 119, 180),
                dashed: false,
            }],
            None,
        )?;
    }
    emit(r.out, &csv)
}

/// Options of `chatter recommend`.
pub struct RecommendRequest<'a> {
    pub model: &'a Path,
    pub max_depth_mm: f64,
    pub sle_tolerance_um: Option<f64>,
    pub risk: Option<f64>,
    pub limit_sd_percent: Option<f64>,
    pub feed_per_tooth_mm: f64,
    pub speeds: Option<&'a str>,
    pub chatter: (Option<f64>, Option<f64>),
    pub out: Option<&'a Path>,
}

/// `chatter recommend`: JSON with the highest-MRR stable cut and, given a chattering speed and
/// frequency, the Harmonizer's speeds, each with its reasons.
pub fn recommend(r: &RecommendRequest) -> Result<()> {
    check_optional_file("--out", r.out)?;
    let max_depth_mm = validate::option("--max-depth-mm", r.max_depth_mm, &DEPTH_MM)?;
    let feed_mm = validate::option(
        "--feed-per-tooth-mm",
        r.feed_per_tooth_mm,
        &chatter_jobs::simulate::FEED_MM,
    )?;
    let mut options = RecommendOptions::new(max_depth_mm * 1e-3);
    options.feed_per_tooth_m = feed_mm * 1e-3;
    if let Some(p) = r.risk {
        if !(p > 0.0 && p <= 0.5) {
            bail!(
                "--risk {}: expected a probability of chatter in (0, 0.5]",
                validate::as_typed("--risk", p)
            );
        }
        options.risk = p;
    }
    if let Some(s) = r.limit_sd_percent {
        if !(s.is_finite() && (0.0..50.0).contains(&s)) {
            bail!(
                "--limit-sd-percent {}: expected a relative standard deviation from 0 to 50 %",
                validate::as_typed("--limit-sd-percent", s)
            );
        }
        options.limit_relative_sd = s / 100.0;
    }
    if let Some(t) = r.sle_tolerance_um {
        if !(t.is_finite() && t > 0.0) {
            bail!(
                "--sle-tolerance-um {}: expected a tolerance > 0 um",
                validate::as_typed("--sle-tolerance-um", t)
            );
        }
        options.sle_tolerance_m = Some(t * 1e-6);
    }
    let chatter = match r.chatter {
        (Some(s), Some(f)) => Some((
            validate::option("--chatter-speed-rpm", s, &SPEED_RPM)?,
            validate::option(
                "--chatter-hz",
                f,
                &chatter_dynamics::limits::OBSERVED_FREQUENCY_HZ,
            )?,
        )),
        (None, None) => None,
        (Some(_), None) => bail!("--chatter-speed-rpm needs --chatter-hz"),
        (None, Some(_)) => bail!("--chatter-hz needs --chatter-speed-rpm"),
    };
    let model = inputs::model(r.model)?;
    let chatter_dynamics::Operation::Milling(milling) = model.operation() else {
        bail!(
            "--model {}: recommend is for milling models",
            r.model.display()
        );
    };
    let speeds = match r.speeds {
        Some(spec) => validate::speeds(spec)?,
        None => default_speeds_rpm(&model),
    };
    if let Some(d) = Method::Fdm.discretization() {
        validate::work_size(&model, d, &speeds, "--speeds")?;
    }
    let fdm = Method::Fdm.prepare(&model, &BoundaryOptions::default())?;
    let cut = highest_mrr_cut(&model, fdm.as_ref(), &speeds, &options)?;
    let harmonizer = match chatter {
        Some((s, f)) => Some(serde_json::json!({
            "chatter_speed_rpm": s,
            "chatter_hz": f,
            "speeds": harmonic_speeds(milling.teeth(), s, f)?,
        })),
        None => None,
    };
    let json = serde_json::json!({
        "model": r.model.display().to_string(),
        "method": "fdm",
        "risk": options.risk,
        "limit_sd_percent": options.limit_relative_sd * 100.0,
        "feed_per_tooth_mm": feed_mm,
        "cut": cut,
        "harmonizer": harmonizer,
    });
    emit(r.out, &(serde_json::to_string_pretty(&json)? + "\n"))
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
