//! `chatter bands`: geometric Type B offsets, perturbation credibility bounds and Monte Carlo
//! probability-of-stability maps around the lobes.

use crate::commands::{Method, compute_lobes, markers};
use crate::output::{self, emit, write_atomic};
use crate::plot::{Series, line_chart_svg};
use crate::report::jobs;
use crate::validate;
use crate::{inputs, progress::Bar};
use anyhow::{Result, bail};
use chatter_dynamics::{ModalModel, Observations};
use chatter_jobs::bands as band_jobs;
use chatter_uncertainty::geometric::{OffsetBoundaries, TypeBOffsets, type_b_offsets};
use chatter_uncertainty::montecarlo::FailureKind;
use chatter_uncertainty::parameters::ParameterDistribution;
use chatter_uncertainty::perturbation::BoundRule;
use plotters::style::{BLUE, GREEN, RGBColor};
use std::fmt::Write as _;
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

/// Default Type B speed offset (seed 001).
pub(crate) const OFFSET_RPM: f64 = 100.0;
/// Default Type B depth offset (seed 001).
pub(crate) const OFFSET_MM: f64 = 0.2;
/// Default Monte Carlo samples.
const SAMPLES: usize = 500;
/// Most Monte Carlo samples.
const MAX_SAMPLES: usize = 100_000;

/// The kind's name as the user types it.
fn kind_name(kind: BandKind) -> String {
    use clap::ValueEnum;
    kind.to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// Options the kind uses are in range and options it ignores are absent; outputs writable.
fn check_options(req: &BandRequest) -> Result<()> {
    let context = format!("with --kind {}", kind_name(req.kind));
    let geometric = req.kind == BandKind::Geometric;
    let montecarlo = req.kind == BandKind::Montecarlo;
    for (given, flag, used_by) in [
        (req.offsets.0.is_some(), "--offset-rpm", "--kind geometric"),
        (req.offsets.1.is_some(), "--offset-mm", "--kind geometric"),
    ] {
        validate::unused(given && !geometric, flag, &context, used_by)?;
    }
    for (given, flag) in [
        (req.posterior.is_some(), "--posterior"),
        (req.covariance.is_some(), "--covariance"),
    ] {
        validate::unused(
            given && geometric,
            flag,
            &context,
            "--kind perturbation and montecarlo",
        )?;
    }
    let frf_draws = crate::measured_bands::frf_uncertainty(req).is_some();
    for (given, flag) in [
        (req.frf_sd.0.is_some(), "--gain-sd"),
        (req.frf_sd.1.is_some(), "--frequency-sd"),
    ] {
        validate::unused(given && !geometric, flag, &context, "--kind geometric")?;
    }
    if frf_draws && (req.offsets.0.is_some() || req.offsets.1.is_some()) {
        bail!(
            "--offset-rpm/--offset-mm and --gain-sd/--frequency-sd both given: the offsets are \
             either stated or set by the FRF uncertainty; give one of the two"
        );
    }
    for (given, flag) in [
        (req.samples.is_some(), "--samples"),
        (req.seed.is_some(), "--seed"),
    ] {
        validate::unused(
            given && !montecarlo && !frf_draws,
            flag,
            &context,
            "--kind montecarlo and the FRF draws of --gain-sd/--frequency-sd",
        )?;
    }
    validate::unused(
        req.map_out.is_some() && !montecarlo,
        "--map-out",
        &context,
        "--kind montecarlo",
    )?;
    validate::unused(
        req.depths.is_some() && (geometric || (montecarlo && req.map_out.is_none())),
        "--depths",
        &if montecarlo {
            format!("{context} without --map-out")
        } else {
            context.clone()
        },
        "the perturbation grid and the Monte Carlo map (--map-out)",
    )?;
    validate::unused(
        req.observations.is_some() && req.plot.is_none() && req.report.is_none(),
        "--observations",
        "without --plot or --report",
        "drawing the observed cuts on the plot",
    )?;
    if let Some(v) = req.offsets.0 {
        validate::option("--offset-rpm", v, &validate::OFFSET_RPM)?;
    }
    if let Some(v) = req.offsets.1 {
        validate::option("--offset-mm", v, &validate::OFFSET_MM)?;
    }
    if let Some(n) = req.samples {
        validate::count("--samples", n, 2, MAX_SAMPLES, "Monte Carlo samples")?;
    }
    if let Some(spec) = req.depths {
        validate::grid("--depths", spec, &validate::DEPTH_GRID_MM)?;
    }
    output::check_optional_file("--out", req.out)?;
    output::check_optional_file("--map-out", req.map_out)?;
    output::check_optional_file("--plot", req.plot)?;
    output::check_optional_file("--report", req.report)
}

/// `chatter bands`.
pub fn bands(req: &BandRequest) -> Result<()> {
    check_options(req)?;
    let measured = chatter_frf::read_model_file(req.model)
        .map(|f| f.measured_frf.is_some())
        .unwrap_or(false);
    if measured && req.kind == BandKind::Geometric && matches!(req.method, None | Some(Method::Zoa))
    {
        crate::measured_bands::check(req)?;
        return crate::measured_bands::bands(req, req.model);
    }
    if crate::measured_bands::frf_uncertainty(req).is_some() {
        bail!(
            "--gain-sd/--frequency-sd: {} has no measured_frf; the FRF uncertainty applies to \
             zero-order geometric bands of a model with measured_frf",
            req.model.display()
        );
    }
    let speeds = req.speeds.map(validate::speeds).transpose()?;
    let model = inputs::model(req.model)?;
    let obs = req.observations.map(inputs::observations).transpose()?;
    let speeds = match speeds {
        Some(s) => s,
        None => chatter_stability::speed_grid::lobe_speeds_rpm(&model),
    };
    if let Some(offset) = req.offsets.0 {
        let span = speeds.last().unwrap_or(&0.0) - speeds.first().unwrap_or(&0.0);
        if offset > span {
            bail!(
                "--offset-rpm {}: larger than the speed range ({} rpm); expected an offset \
                 within the speeds of the lobes",
                validate::as_typed("--offset-rpm", offset),
                chatter_dynamics::limits::written(span)
            );
        }
    }
    if let Some(d) = req.method.unwrap_or(Method::Fdm).discretization()
        && (req.kind != BandKind::Geometric || req.method.is_some())
    {
        validate::work_size(&model, d, &speeds, "--speeds")?;
    }
    match req.kind {
        BandKind::Geometric => geometric(req, &model, &speeds, obs.as_ref()),
        BandKind::Perturbation => perturbation(req, &model, &speeds, obs.as_ref()),
        BandKind::Montecarlo => montecarlo(req, &model, &speeds, obs.as_ref()),
    }
}

fn geometric(
    req: &BandRequest,
    model: &ModalModel,
    speeds: &[f64],
    obs: Option<&Observations>,
) -> Result<()> {
    let lobes = compute_lobes(model, req.method.unwrap_or(Method::Zoa), speeds, req.quiet)?;
    crate::commands::warn_unbounded(&lobes, "they are left out of the bands");
    let curve = band_jobs::finite_curve(&lobes);
    let offsets = TypeBOffsets::new(
        req.offsets.0.unwrap_or(OFFSET_RPM),
        req.offsets.1.unwrap_or(OFFSET_MM),
    )?;
    let bands = type_b_offsets(&curve, offsets)?;
    let csv = geometric_csv(&bands);
    emit(req.out, &csv)?;
    if req.plot.is_none() && req.report.is_none() {
        return Ok(());
    }
    let series = band_series(
        curve,
        bands.lower.clone(),
        bands.upper.clone(),
        ["mean boundary", "lower offset", "upper offset"],
    );
    let title = "Type B offset boundaries";
    let svg = band_plot(title, &series, obs)?;
    let stem = req
        .plot
        .and_then(Path::file_stem)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bands".into());
    let extra = offset_detail_svgs(&stem, &bands)?;
    if let Some(path) = req.plot {
        for (name, svg) in &extra {
            write_atomic(&path.with_file_name(name), svg.as_bytes())?;
        }
    }
    let mut figures = vec![(title.to_string(), svg)];
    figures.extend(extra);
    let label = ("lower offset boundary", jobs::GEOMETRIC_MISSING);
    finish(req, model, obs, &csv, label, figures, Vec::new())
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

/// Write the band plot (the first figure) to `--plot` and the report page to `--report`.
fn finish(
    req: &BandRequest,
    model: &ModalModel,
    obs: Option<&Observations>,
    csv: &str,
    (lower_label, why_missing): (&str, &str),
    figures: Vec<(String, String)>,
    warnings: Vec<String>,
) -> Result<()> {
    if let (Some(path), Some((_, svg))) = (req.plot, figures.first()) {
        write_atomic(path, svg.as_bytes())?;
    }
    if let Some(path) = req.report {
        jobs::bands(&jobs::BandsResult {
            kind: &kind_name(req.kind),
            lower_label,
            why_missing,
            model,
            observations: obs,
            csv,
            figures,
            warnings,
        })?
        .write(path)?;
    }
    Ok(())
}

/// CSV of Type B offsets (001): per mean-boundary point the lower and upper boundaries at its
/// speed (`lower_mm`, `upper_mm`, from the gap-filled, loop-free polylines), Eq. 2's angle
/// `theta_deg` and Eq. 1's distance `distance` (rpm / um units), and the raw roots of Eq. 10-11
/// (`upper_speed_rpm`, `upper_depth_mm`, `lower_speed_rpm`, `lower_depth_mm`), unmodified.
pub fn geometric_csv(bands: &OffsetBoundaries) -> String {
    let mut csv = String::from(
        "speed_rpm,depth_mm,lower_mm,upper_mm,theta_deg,distance,upper_speed_rpm,\
         upper_depth_mm,lower_speed_rpm,lower_depth_mm\n",
    );
    for p in &bands.points {
        let lo = OffsetBoundaries::depth_at(&bands.lower, p.speed_rpm);
        let up = OffsetBoundaries::depth_at(&bands.upper, p.speed_rpm);
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{}",
            p.speed_rpm,
            p.depth_mm,
            cell(lo),
            cell(up),
            p.theta_deg,
            p.distance,
            p.upper.0,
            p.upper.1,
            p.lower.0,
            p.lower.1
        );
    }
    csv
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

fn cell(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// A mean boundary with a lower and an upper curve, for plotting.
pub fn band_series(
    mean: Vec<(f64, f64)>,
    lower: Vec<(f64, f64)>,
    upper: Vec<(f64, f64)>,
    labels: [&str; 3],
) -> [Series; 3] {
    let line = |label: &str, points: Vec<(f64, f64)>, color: RGBColor| Series {
        label: label.into(),
        points,
        color,
        dashed: false,
    };
    [
        line(labels[0], mean, BLUE),
        line(labels[1], lower, RGBColor(200, 0, 0)),
        line(labels[2], upper, GREEN),
    ]
}

fn distribution(req: &BandRequest, model: &ModalModel) -> Result<ParameterDistribution> {
    Ok(match (req.posterior, req.covariance) {
        (Some(dir), None) => {
            validate::posterior_matches(model, dir)?;
            ParameterDistribution::from_posterior_dir(dir)?
        }
        (None, Some(file)) => ParameterDistribution::from_covariance_file(file)?,
        (Some(_), Some(_)) => bail!("give either --posterior DIR or --covariance FILE, not both"),
        (None, None) => bail!(
            "--kind {} needs a parameter distribution: --posterior DIR (from `chatter update`) \
             or --covariance FILE ({{\"parameter_names\": [...], \"covariance\": [[...]]}})",
            kind_name(req.kind)
        ),
    })
}

/// The method of a band kind that needs a discretization.
fn discretized_method(req: &BandRequest) -> Result<Method> {
    let method = req.method.unwrap_or(Method::Fdm);
    if method.discretization().is_none() {
        bail!("--kind {} needs --method fdm or sdm", kind_name(req.kind));
    }
    Ok(method)
}

/// `--depths` when given.
fn depth_option(req: &BandRequest) -> Result<Option<Vec<f64>>> {
    req.depths
        .map(|spec| validate::grid("--depths", spec, &validate::DEPTH_GRID_MM))
        .transpose()
}

fn perturbation(
    req: &BandRequest,
    model: &ModalModel,
    speeds: &[f64],
    obs: Option<&Observations>,
) -> Result<()> {
    let rule = match req.coverage {
        Some(c) => BoundRule::coverage(c).map_err(|e| anyhow::anyhow!("--coverage: {e}"))?,
        None => BoundRule::ComplexSd,
    };
    let dist = distribution(req, model)?;
    let method = discretized_method(req)?;
    let bar = Bar::new(speeds.len() as u64, "credibility grid", req.quiet);
    let bands =
        band_jobs::perturbation(model, &dist, method, rule, speeds, depth_option(req)?, &bar)
            .map_err(crate::job_error)?;
    bar.finish();
    let (csv, series) = credibility_bands(&bands.bounds, rule);
    emit(req.out, &csv)?;
    if req.plot.is_none() && req.report.is_none() {
        return Ok(());
    }
    let title = format!(
        "Credibility bounds at the posterior mean: {}",
        rule_title(rule)
    );
    let svg = band_plot(&title, &series, obs)?;
    finish(
        req,
        model,
        obs,
        &csv,
        ("lower credibility bound", jobs::PERTURBATION_MISSING),
        vec![(title, svg)],
        Vec::new(),
    )
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

/// Credibility bounds (second-order perturbation of the dominant multiplier, Ahmadi 2022 Eq.
/// 14-18, [`band_jobs::perturbation`]) under `rule` as CSV
/// `speed_rpm,depth_mm,lower_mm,upper_mm` (empty cells where a contour is not reached on the
/// grid) and the plot series, broken (NaN) at those speeds so no line is drawn across a gap.
pub fn credibility_bands(
    bounds: &[chatter_uncertainty::perturbation::CredibilityPoint],
    rule: BoundRule,
) -> (String, [Series; 3]) {
    let mut csv = String::from("speed_rpm,depth_mm,lower_mm,upper_mm\n");
    for b in bounds {
        let _ = writeln!(
            csv,
            "{},{},{},{}",
            b.speed_rpm,
            cell(b.depth_mm),
            cell(b.lower_mm),
            cell(b.upper_mm)
        );
    }
    let pick = |f: fn(&chatter_uncertainty::perturbation::CredibilityPoint) -> Option<f64>| {
        bounds
            .iter()
            .map(|b| (b.speed_rpm, f(b).unwrap_or(f64::NAN)))
            .collect::<Vec<_>>()
    };
    let (mean, lower, upper) = match rule {
        BoundRule::ComplexSd => (
            "limit of the mean multiplier".to_string(),
            "lower: mean + 1 sd reaches 1".to_string(),
            "upper: mean - 1 sd reaches 1".to_string(),
        ),
        BoundRule::Coverage(c) => {
            let p = 100.0 * c;
            (
                "limit of the mean modulus".to_string(),
                format!("lower ({p:.0} %)"),
                format!("upper ({p:.0} %)"),
            )
        }
    };
    let series = band_series(
        pick(|b| b.depth_mm),
        pick(|b| b.lower_mm),
        pick(|b| b.upper_mm),
        [&mean, &lower, &upper],
    );
    (csv, series)
}

fn montecarlo(
    req: &BandRequest,
    model: &ModalModel,
    speeds: &[f64],
    obs: Option<&Observations>,
) -> Result<()> {
    let dist = distribution(req, model)?;
    let method = discretized_method(req)?;
    let samples = req.samples.unwrap_or(SAMPLES);
    let bar = Bar::new(samples as u64, "Monte Carlo samples", req.quiet);
    let mc = band_jobs::montecarlo(
        model,
        &dist,
        method,
        samples,
        req.seed.unwrap_or(0),
        speeds,
        &bar,
    )
    .map_err(crate::job_error)?;
    bar.finish();
    let mut warnings = Vec::new();
    let sampled = &mc.sampled;
    if !sampled.failures.is_empty() {
        // failed samples are left out of P_s and the quantiles, never counted as stable
        let invalid = sampled
            .failures
            .iter()
            .filter(|f| f.kind == FailureKind::InvalidSample)
            .count();
        let worst = sampled.failures_per_speed().into_iter().max().unwrap_or(0);
        let warning = format!(
            "{} sample-speed failures ({} numerical, {invalid} invalid samples), at most \
             {worst} of {} samples at one speed, left out of the map; first: {}",
            sampled.failures.len(),
            sampled.failures.len() - invalid,
            mc.draws,
            sampled.failures[0].message
        );
        eprintln!("warning: {warning}");
        warnings.push(warning);
    }
    let (depth, hz) = (&mc.depth, &mc.chatter_hz);
    let mut csv = String::from(
        "speed_rpm,depth_mm,lower_mm,upper_mm,chatter_hz_q05,chatter_hz_q50,chatter_hz_q95\n",
    );
    for (d, f) in depth.iter().zip(hz) {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{}",
            d.speed_rpm, d.q50, d.q05, d.q95, f.q05, f.q50, f.q95
        );
    }
    emit(req.out, &csv)?;
    if let Some(path) = req.map_out {
        let map = mc.map(depth_option(req)?).map_err(crate::job_error)?;
        let mut text = String::from("speed_rpm,depth_mm,p_stable\n");
        for (s, row) in map.speeds_rpm.iter().zip(&map.p_stable) {
            for (b, p) in map.depths_mm.iter().zip(row) {
                let _ = writeln!(text, "{s},{b},{p}");
            }
        }
        write_atomic(path, text.as_bytes())?;
    }
    if req.plot.is_some() || req.report.is_some() {
        let curve = |f: fn(&chatter_uncertainty::montecarlo::QuantileBand) -> f64| {
            depth
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
        let title = "Monte Carlo probability of stability";
        let svg = band_plot(title, &series, obs)?;
        finish(
            req,
            model,
            obs,
            &csv,
            ("P_s = 0.95 contour", jobs::MONTECARLO_MISSING),
            vec![(title.into(), svg)],
            warnings,
        )?;
    }
    Ok(())
}
