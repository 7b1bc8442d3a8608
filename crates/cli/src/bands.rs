//! `chatter bands`: the options as a `chatter_jobs::bands::BandsRequest` (geometric Type B
//! offsets, perturbation credibility bounds, Monte Carlo probability-of-stability maps; on a
//! model with `measured_frf`, geometric bands straight from the FRFs), the outcome as CSV, SVG
//! and the report page.

use crate::output::{self, emit, write_atomic};
use crate::plot::{Series, line_chart_svg};
use crate::progress::Bar;
use crate::report::jobs;
use crate::tables::{self, band_series, markers};
use crate::{inputs, validate};
use anyhow::{Result, anyhow, bail};
use chatter_dynamics::{ModalModel, Observations};
use chatter_jobs::JobError;
use chatter_jobs::bands::{self as band_jobs, Bands, BandsOutcome, BandsRequest};
use chatter_jobs::lobes::Dynamics;
use chatter_stability::prepared::Method;
use chatter_uncertainty::geometric::OffsetBoundaries;
use chatter_uncertainty::parameters::ParameterDistribution;
use chatter_uncertainty::perturbation::BoundRule;
use plotters::style::{BLUE, GREEN, RGBColor};
use std::path::Path;

/// Band kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BandKind {
    /// Type B offset boundaries from stated speed and depth offsets (Schmitz 2023).
    Geometric,
    /// Credibility bounds from a parameter covariance by second-order perturbation of the
    /// dominant eigenvalue (Ahmadi 2022).
    Perturbation,
    /// Probability of stability from sampled parameters (Monte Carlo, Schmitz et al. 2022).
    Montecarlo,
}

/// Everything `chatter bands` was asked.
pub struct BandRequest<'a> {
    /// Model file.
    pub model: &'a Path,
    /// Band kind.
    pub kind: BandKind,
    /// Method; default zoa for geometric, fdm otherwise.
    pub method: Option<Method>,
    /// Speeds MIN:MAX:N.
    pub speeds: Option<&'a str>,
    /// Depths MIN:MAX:N (perturbation grid, Monte Carlo map).
    pub depths: Option<&'a str>,
    /// Type B offsets (rpm, mm) when given (default 100 rpm, 0.2 mm).
    pub offsets: (Option<f64>, Option<f64>),
    /// Relative gain and frequency-axis standard deviations of a measured FRF (geometric bands
    /// on a `measured_frf` model: offsets from the FRF ensemble).
    pub frf_sd: (Option<f64>, Option<f64>),
    /// Posterior folder.
    pub posterior: Option<&'a Path>,
    /// Covariance file.
    pub covariance: Option<&'a Path>,
    /// Monte Carlo samples when given (default 500).
    pub samples: Option<usize>,
    /// Seed of the Monte Carlo draws when given (default 0).
    pub seed: Option<u64>,
    /// Perturbation bounds of this central credibility of |mu| (None: the mean modulus +- one
    /// standard deviation of the complex multiplier).
    pub coverage: Option<f64>,
    /// Observed cuts.
    pub observations: Option<&'a Path>,
    /// CSV destination (stdout when absent).
    pub out: Option<&'a Path>,
    /// Probability map CSV (Monte Carlo).
    pub map_out: Option<&'a Path>,
    /// SVG plot.
    pub plot: Option<&'a Path>,
    /// HTML report page.
    pub report: Option<&'a Path>,
    /// No progress bars.
    pub quiet: bool,
}

/// The kind's name as the user types it.
fn kind_name(kind: BandKind) -> String {
    use clap::ValueEnum;
    kind.to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// The options that concern files and outputs (what the job never sees): the distribution's
/// files only for the kinds that use one, the observations only with a plot or a report, the
/// outputs writable.
fn check_outputs(req: &BandRequest) -> Result<()> {
    let context = format!("with --kind {}", kind_name(req.kind));
    for (given, flag) in [
        (req.posterior.is_some(), "--posterior"),
        (req.covariance.is_some(), "--covariance"),
    ] {
        validate::unused(
            given && req.kind == BandKind::Geometric,
            flag,
            &context,
            "--kind perturbation and montecarlo",
        )?;
    }
    validate::unused(
        req.observations.is_some() && req.plot.is_none() && req.report.is_none(),
        "--observations",
        "without --plot or --report",
        "drawing the observed cuts on the plot",
    )?;
    output::check_optional_file("--out", req.out)?;
    output::check_optional_file("--map-out", req.map_out)?;
    output::check_optional_file("--plot", req.plot)?;
    output::check_optional_file("--report", req.report)
}

/// The job's request from the options.
fn request(req: &BandRequest) -> Result<BandsRequest> {
    Ok(BandsRequest {
        kind: match req.kind {
            BandKind::Geometric => band_jobs::BandKind::Geometric,
            BandKind::Perturbation => band_jobs::BandKind::Perturbation,
            BandKind::Montecarlo => band_jobs::BandKind::MonteCarlo,
        },
        method: req.method,
        speeds_rpm: req.speeds.map(validate::speeds).transpose()?,
        depths_mm: req
            .depths
            .map(|spec| validate::grid("--depths", spec, &chatter_jobs::checks::DEPTH_GRID_MM))
            .transpose()?,
        offset_rpm: req.offsets.0,
        offset_mm: req.offsets.1,
        gain_sd: req.frf_sd.0,
        frequency_sd: req.frf_sd.1,
        samples: req.samples,
        seed: req.seed,
        coverage: req.coverage,
        map: req.map_out.is_some(),
    })
}

/// `chatter bands`.
pub fn bands(req: &BandRequest) -> Result<()> {
    check_outputs(req)?;
    let request = request(req)?;
    // the options before the files: a misplaced option is named even when a file is the wrong kind
    request.check().map_err(crate::job_error)?;
    let dynamics = inputs::dynamics(req.model, request.method())?;
    let model = match &dynamics {
        Dynamics::Modal(m) => Some(m),
        Dynamics::Measured(_) => {
            if req.report.is_some() || req.observations.is_some() {
                bail!(
                    "--report and --observations are not available for a model with \
                     measured_frf; use --out and --plot"
                );
            }
            None
        }
    };
    let distribution = match model {
        Some(m) if req.kind != BandKind::Geometric => distribution(req, m)?,
        _ => None,
    };
    let job = Bands::new(&dynamics, distribution.as_ref(), request).map_err(|e| match e {
        JobError::Missing { .. } => anyhow!(
            "--kind {} needs a parameter distribution: --posterior DIR (from `chatter update`) \
             or --covariance FILE ({{\"parameter_names\": [...], \"covariance\": [[...]]}})",
            kind_name(req.kind)
        ),
        e => crate::job_error(e),
    })?;
    let obs = req.observations.map(inputs::observations).transpose()?;
    let speeds = job.speeds_rpm().len();
    let bar = match req.kind {
        BandKind::Geometric => {
            let method = job.request().method();
            // zero-order lobes are instant, and the FRF ensemble reports nothing: no bar
            let bar = Bar::new(
                speeds as u64,
                "lobes",
                req.quiet || method == Method::Zoa || model.is_none(),
            );
            bar.announce(&format!("{speeds} speeds, {}", method.name()));
            bar
        }
        BandKind::Perturbation => Bar::new(speeds as u64, "credibility grid", req.quiet),
        BandKind::Montecarlo => Bar::new(job.samples() as u64, "Monte Carlo samples", req.quiet),
    };
    let outcome = job.run(&bar).map_err(crate::job_error)?;
    bar.finish();
    let Some(model) = model else {
        return measured(req, &outcome);
    };
    write(req, model, obs.as_ref(), &outcome)
}

/// The outputs of bands on a modal model.
fn write(
    req: &BandRequest,
    model: &ModalModel,
    obs: Option<&Observations>,
    outcome: &BandsOutcome,
) -> Result<()> {
    let mut warnings = Vec::new();
    let (csv, title, series, extra, lower_label, why_missing) = match outcome {
        BandsOutcome::Geometric { lobes, bands, .. } => {
            tables::warn_unbounded(lobes, "they are left out of the bands");
            let series = band_series(
                band_jobs::finite_curve(lobes),
                bands.lower.clone(),
                bands.upper.clone(),
                ["mean boundary", "lower offset", "upper offset"],
            );
            let stem = req
                .plot
                .and_then(Path::file_stem)
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "bands".into());
            let extra = if req.plot.is_some() || req.report.is_some() {
                offset_detail_svgs(&stem, bands)?.to_vec()
            } else {
                Vec::new()
            };
            (
                tables::geometric_csv(bands),
                "Type B offset boundaries".to_string(),
                series,
                extra,
                "lower offset boundary",
                jobs::GEOMETRIC_MISSING,
            )
        }
        BandsOutcome::Perturbation { rule, bands } => {
            let (csv, series) = tables::credibility_bands(&bands.bounds, *rule);
            (
                csv,
                format!(
                    "Credibility bounds at the posterior mean: {}",
                    rule_title(*rule)
                ),
                series,
                Vec::new(),
                "lower credibility bound",
                jobs::PERTURBATION_MISSING,
            )
        }
        BandsOutcome::MonteCarlo { bands, map } => {
            if let Some(warning) = band_jobs::failure_warning(bands) {
                eprintln!("warning: {warning}");
                warnings.push(warning);
            }
            if let (Some(path), Some(map)) = (req.map_out, map) {
                write_atomic(path, tables::stability_map_csv(map).as_bytes())?;
            }
            let curve = |f: fn(&chatter_uncertainty::montecarlo::QuantileBand) -> f64| {
                bands
                    .depth
                    .iter()
                    .map(|d| (d.speed_rpm, f(d)))
                    .filter(|p| p.1.is_finite())
                    .collect::<Vec<_>>()
            };
            let series = band_series(
                curve(|d| d.q50),
                curve(|d| d.q05),
                curve(|d| d.q95),
                ["P_s = 0.5", "P_s = 0.95", "P_s = 0.05"],
            );
            (
                tables::montecarlo_csv(bands),
                "Monte Carlo probability of stability".to_string(),
                series,
                Vec::new(),
                "P_s = 0.95 contour",
                jobs::MONTECARLO_MISSING,
            )
        }
    };
    emit(req.out, &csv)?;
    if req.plot.is_none() && req.report.is_none() {
        return Ok(());
    }
    let svg = band_plot(&title, &series, obs)?;
    if let Some(path) = req.plot {
        write_atomic(path, svg.as_bytes())?;
        for (name, svg) in &extra {
            write_atomic(&path.with_file_name(name), svg.as_bytes())?;
        }
    }
    if let Some(path) = req.report {
        let mut figures = vec![(title, svg)];
        figures.extend(extra);
        jobs::bands(&jobs::BandsResult {
            kind: &kind_name(req.kind),
            lower_label,
            why_missing,
            model,
            observations: obs,
            curves: &outcome.curves(),
            csv: &csv,
            figures,
            warnings,
        })?
        .write(path)?;
    }
    Ok(())
}

/// The outputs of geometric bands on measured FRFs (CSV and plot).
fn measured(req: &BandRequest, outcome: &BandsOutcome) -> Result<()> {
    let BandsOutcome::Geometric { lobes, bands, frf } = outcome else {
        bail!("bands on measured FRFs are geometric");
    };
    if let Some(f) = frf {
        eprintln!(
            "offsets from the FRF uncertainty (gain sd {}, frequency sd {}, {} draws, k = {}): \
             {:.1} rpm, {:.4} mm around the pocket at {:.0} rpm, {:.4} mm",
            f.gain_sd,
            f.frequency_sd,
            f.draws,
            f.coverage_factor,
            f.offsets.offset_rpm(),
            f.offsets.offset_mm(),
            f.pocket.0,
            f.pocket.1
        );
    }
    emit(req.out, &tables::geometric_csv(bands))?;
    if let Some(path) = req.plot {
        let series = band_series(
            band_jobs::finite_curve(lobes),
            bands.lower.clone(),
            bands.upper.clone(),
            ["lobes from the FRF", "lower offset", "upper offset"],
        );
        let svg = line_chart_svg(
            "Type B offset boundaries on measured FRFs",
            "spindle speed (rpm)",
            "depth (mm)",
            &series,
            None,
        )?;
        write_atomic(path, svg.as_bytes())?;
    }
    Ok(())
}

/// The band plot (depth against speed, with the observed cuts).
fn band_plot(title: &str, series: &[Series], obs: Option<&Observations>) -> Result<String> {
    line_chart_svg(
        title,
        "spindle speed (rpm)",
        "depth (mm)",
        series,
        markers(obs).as_ref(),
    )
}

/// The parameter distribution of `--posterior` or `--covariance` (None when neither is given:
/// the job says which kinds need one).
fn distribution(req: &BandRequest, model: &ModalModel) -> Result<Option<ParameterDistribution>> {
    Ok(match (req.posterior, req.covariance) {
        (Some(dir), None) => {
            validate::posterior_matches(model, dir)?;
            Some(ParameterDistribution::from_posterior_dir(dir)?)
        }
        (None, Some(file)) => Some(ParameterDistribution::from_covariance_file(file)?),
        (Some(_), Some(_)) => bail!("give either --posterior DIR or --covariance FILE, not both"),
        (None, None) => None,
    })
}

/// 001 Figs. 6-10: Eq. 2's angle theta and Eq. 1's offset distance d along the mean boundary,
/// and the raw Eq. 10-11 roots of every point (unmodified, cusp gaps and loops included) beside
/// the mean boundary, as SVG texts named after the band plot `stem`: `STEM-theta.svg`,
/// `STEM-distance.svg` and `STEM-roots.svg` (`bands --plot F.svg` writes them beside the plot).
pub fn offset_detail_svgs(stem: &str, bands: &OffsetBoundaries) -> Result<[(String, String); 3]> {
    let points = |f: fn(&chatter_uncertainty::geometric::PointOffset) -> (f64, f64)| {
        bands.points.iter().map(f).collect::<Vec<_>>()
    };
    let series = |label: &str, f: fn(&chatter_uncertainty::geometric::PointOffset) -> f64| {
        [Series {
            label: label.into(),
            points: bands.points.iter().map(|p| (p.speed_rpm, f(p))).collect(),
            color: BLUE,
            dashed: false,
        }]
    };
    let dots = |label: &str, points: Vec<(f64, f64)>, color: RGBColor| Series {
        label: label.into(),
        points,
        color,
        dashed: true,
    };
    Ok([
        (
            format!("{stem}-theta.svg"),
            line_chart_svg(
                "Angle theta of the mean boundary against spindle speed (Schmitz 2023 Eq. 2)",
                "spindle speed (rpm)",
                "theta (deg)",
                &series("theta", |p| p.theta_deg),
                None,
            )?,
        ),
        (
            format!("{stem}-distance.svg"),
            line_chart_svg(
                "Offset distance d against spindle speed (Schmitz 2023 Eq. 1)",
                "spindle speed (rpm)",
                "d (rpm / um units)",
                &series("d", |p| p.distance),
                None,
            )?,
        ),
        (
            format!("{stem}-roots.svg"),
            line_chart_svg(
                "Offset points of every boundary point: the two roots of Schmitz 2023 Eq. 10-11",
                "spindle speed (rpm)",
                "axial depth (mm)",
                &[
                    Series {
                        label: "mean boundary".into(),
                        points: points(|p| (p.speed_rpm, p.depth_mm)),
                        color: BLUE,
                        dashed: false,
                    },
                    dots("upper root", points(|p| p.upper), GREEN),
                    dots("lower root", points(|p| p.lower), RGBColor(200, 0, 0)),
                ],
                None,
            )?,
        ),
    ])
}

/// Plot title of a bound rule.
pub fn rule_title(rule: BoundRule) -> String {
    match rule {
        BoundRule::ComplexSd => {
            "bounds where the dominant multiplier's mean modulus +- one standard deviation \
             reaches 1"
                .into()
        }
        BoundRule::Coverage(c) => format!("{:.0} % credibility of |mu|", 100.0 * c),
    }
}
