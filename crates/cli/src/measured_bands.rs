//! `chatter bands --kind geometric` on a model whose `measured_frf` gives its dynamics: Type B
//! offset boundaries (001) around the zero-order lobes straight from the FRFs, with the offsets
//! either stated (`--offset-rpm`, `--offset-mm`) or set by an FRF uncertainty (`--gain-sd`,
//! `--frequency-sd`: the spread of the lobe pocket over an ensemble of perturbed FRFs,
//! [`chatter_uncertainty::measured`]).

use crate::bands::{BandRequest, band_series, geometric_csv};
use crate::output::{emit, write_atomic};
use crate::plot::line_chart_svg;
use anyhow::{Context, Result, bail};
use chatter_frf::MeasuredModel;
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use chatter_uncertainty::geometric::{OffsetBoundaries, TypeBOffsets, type_b_offsets};
use chatter_uncertainty::measured::{FrfUncertainty, frf_ensemble, measured_type_b_bands};
use std::path::Path;

/// FRF draws of the ensemble when `--samples` is not given.
const SAMPLES: usize = 40;
/// Coverage factor k of the ensemble offsets (o = k sd; about 95 % of a normal spread).
const COVERAGE_FACTOR: f64 = 2.0;

/// The relative standard deviations of the FRF uncertainty asked for, if any.
pub fn frf_uncertainty(req: &BandRequest) -> Option<(f64, f64)> {
    match req.frf_sd {
        (None, None) => None,
        (g, f) => Some((g.unwrap_or(0.0), f.unwrap_or(0.0))),
    }
}

/// Geometric bands of the measured-FRF model at `model_path` (zero-order lobes of the FRFs).
pub fn bands(req: &BandRequest, model_path: &Path) -> Result<()> {
    let model = MeasuredModel::from_path(model_path).context("reading the measured FRFs")?;
    let speeds = match req.speeds {
        Some(s) => crate::validate::speeds(s)?,
        None => crate::measured::default_speeds(&model),
    };
    let (curve, bands) = match frf_uncertainty(req) {
        None => {
            let lobes = measured_limiting_depths(
                &model.operation,
                model.cutting,
                &model.receptance,
                &speeds,
                &ZeroOrderOptions::default(),
            )?;
            let curve = chatter_jobs::bands::finite_curve(&lobes);
            let offsets = TypeBOffsets::new(
                req.offsets.0.unwrap_or(crate::bands::OFFSET_RPM),
                req.offsets.1.unwrap_or(crate::bands::OFFSET_MM),
            )?;
            (curve.clone(), type_b_offsets(&curve, offsets)?)
        }
        Some((gain_sd, frequency_sd)) => {
            let uncertainty = FrfUncertainty::new(gain_sd, frequency_sd)
                .map_err(|e| anyhow::anyhow!("--gain-sd / --frequency-sd: {e}"))?;
            let count = req.samples.unwrap_or(SAMPLES);
            let members =
                frf_ensemble(&model.receptance, uncertainty, count, req.seed.unwrap_or(0))?;
            let b = measured_type_b_bands(
                &model.operation,
                model.cutting,
                &model.receptance,
                &members,
                &speeds,
                COVERAGE_FACTOR,
            )?;
            eprintln!(
                "offsets from the FRF uncertainty (gain sd {gain_sd}, frequency sd \
                 {frequency_sd}, {count} draws, k = {COVERAGE_FACTOR}): {:.1} rpm, {:.4} mm \
                 around the pocket at {:.0} rpm, {:.4} mm",
                b.offsets.offset_rpm(),
                b.offsets.offset_mm(),
                b.pocket.0,
                b.pocket.1
            );
            (chatter_jobs::bands::finite_curve(&b.lobes), b.bands)
        }
    };
    emit(req.out, &geometric_csv(&bands))?;
    if let Some(path) = req.plot {
        write_atomic(path, plot(curve, &bands)?.as_bytes())?;
    }
    Ok(())
}

fn plot(curve: Vec<(f64, f64)>, bands: &OffsetBoundaries) -> Result<String> {
    let series = band_series(
        curve,
        bands.lower.clone(),
        bands.upper.clone(),
        ["lobes from the FRF", "lower offset", "upper offset"],
    );
    line_chart_svg(
        "Type B offset boundaries on measured FRFs",
        "spindle speed (rpm)",
        "depth (mm)",
        &series,
        None,
    )
}

/// Refuse what the measured-FRF bands cannot do.
pub fn check(req: &BandRequest) -> Result<()> {
    if req.report.is_some() || req.observations.is_some() {
        bail!(
            "--report and --observations are not available for a model with measured_frf; \
             use --out and --plot"
        );
    }
    Ok(())
}
