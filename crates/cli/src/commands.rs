//! One function per subcommand: parse inputs, call the libraries, write results.

use crate::inputs;
use crate::output::{self, Folder, emit, write_atomic};
use crate::plot::{Markers, Series, line_chart, line_chart_svg};
use crate::progress::{Bar, Working};
use crate::validate;
use anyhow::{Context, Result, bail};
use chatter_dynamics::{ModalModel, Observations};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, LobePoint};
pub use chatter_stability::prepared::Method;
use plotters::style::BLUE;
use std::fmt::Write as _;
use std::path::Path;

/// `chatter check`.
pub fn check(model: &Path, observations: Option<&Path>) -> Result<()> {
    let m = inputs::model(model)?;
    let mut line = format!(
        "{}: {} model with {} modes",
        model.display(),
        match m.operation() {
            chatter_dynamics::Operation::Milling(_) => "milling",
            chatter_dynamics::Operation::Turning(_) => "turning",
        },
        m.mode_count()
    );
    if let Some(o) = observations {
        let obs = inputs::observations(o)?;
        validate::observations_match(&m, &obs, o, model)?;
        let _ = write!(
            line,
            "; {}: {} cuts, {} poles, {} signals",
            o.display(),
            obs.cuts.len(),
            obs.poles.len(),
            obs.signals.len()
        );
    }
    println!("{line}");
    Ok(())
}

/// `chatter frf`.
pub fn frf(
    model_path: &Path,
    range_hz: Option<(f64, f64)>,
    points: usize,
    coordinates: (Option<String>, Option<String>),
    out: Option<&Path>,
    plot: Option<&Path>,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let op = model.operation();
    let index = |name: Option<String>| -> Result<usize> {
        match name {
            None => Ok(0),
            Some(n) => op.coordinate_index(&n).with_context(|| {
                let names: Vec<_> = op.coordinates().iter().map(|c| c.name()).collect();
                format!("coordinate `{n}` is not one of {names:?}")
            }),
        }
    };
    let (i, j) = (index(coordinates.0)?, index(coordinates.1)?);
    let f_max = model
        .modes()
        .iter()
        .map(|m| m.frequency_hz())
        .fold(0.0, f64::max);
    let (f0, f1) = range_hz.unwrap_or((0.0, 2.0 * f_max));
    if !(f0 >= 0.0 && f1 > f0 && points >= 2) {
        bail!(
            "frequency range {f0}..{f1} Hz with {points} points: expected 0 <= min < max and >= 2 points"
        );
    }
    let csv = frf_csv(&model, f0, f1, points, i, j);
    emit(out, &csv)?;
    if let Some(p) = plot {
        let mag: Vec<(f64, f64)> = (0..points)
            .map(|k| {
                let f = f0 + (f1 - f0) * k as f64 / (points - 1) as f64;
                (f, model.receptance(f, i, j).norm() * 1e6)
            })
            .collect();
        let series = [Series {
            label: format!(
                "|G_{}{}|",
                op.coordinates()[i].name(),
                op.coordinates()[j].name()
            ),
            points: mag,
            color: BLUE,
            dashed: false,
        }];
        line_chart(
            p,
            "Receptance",
            "frequency (Hz)",
            "|G| (um/N)",
            &series,
            None,
        )?;
    }
    Ok(())
}

fn frf_csv(model: &ModalModel, f0: f64, f1: f64, points: usize, i: usize, j: usize) -> String {
    let mut csv = String::from("frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n\n");
    for k in 0..points {
        let f = f0 + (f1 - f0) * k as f64 / (points - 1) as f64;
        let g = model.receptance(f, i, j);
        let _ = writeln!(csv, "{f},{:e},{:e},{:e}", g.re, g.im, g.norm());
    }
    csv
}

/// Limiting depths with the chosen method.
pub fn compute_lobes(
    model: &ModalModel,
    method: Method,
    speeds: &[f64],
    quiet: bool,
) -> Result<Vec<LobePoint>> {
    if let Some(d) = method.discretization() {
        validate::work_size(model, d, speeds, "--speeds")?;
    }
    // zero-order lobes are instant: no bar
    let bar = Bar::new(speeds.len() as u64, "lobes", quiet || method == Method::Zoa);
    bar.announce(&format!("{} speeds, {}", speeds.len(), method.name()));
    let lobes =
        chatter_jobs::bands::lobes(model, method, speeds, &bar).map_err(crate::job_error)?;
    bar.finish();
    Ok(lobes)
}

pub fn markers(obs: Option<&Observations>) -> Option<Markers> {
    obs.map(|o| Markers {
        stable: o
            .cuts
            .iter()
            .filter(|c| c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
        unstable: o
            .cuts
            .iter()
            .filter(|c| !c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
    })
}

/// The lobes as CSV; a speed without a limit below the depth ceiling has empty depth and
/// chatter cells (see [`warn_unbounded`]).
fn lobes_csv(lobes: &[LobePoint]) -> String {
    let mut csv = String::from("speed_rpm,depth_mm,chatter_hz\n");
    for p in lobes {
        if p.depth_m.is_finite() {
            let _ = writeln!(csv, "{},{},{}", p.speed_rpm, p.depth_mm(), p.chatter_hz);
        } else {
            let _ = writeln!(csv, "{},,", p.speed_rpm);
        }
    }
    csv
}

/// A warning on stderr with the number of speeds that have no limit, and what became of them
/// (`fate`, e.g. "their depth_mm and chatter_hz cells are empty").
pub fn warn_unbounded(lobes: &[LobePoint], fate: &str) {
    let unbounded = lobes.iter().filter(|p| !p.depth_m.is_finite()).count();
    if unbounded > 0 {
        eprintln!(
            "warning: {unbounded} of {} speeds have no stability limit below the depth ceiling \
             of {} mm; {fate}",
            lobes.len(),
            BoundaryOptions::default().max_depth_m * 1e3
        );
    }
}

/// Options of `chatter lobes` beyond the lobe CSV and plot ([`crate::lobe_map`]).
pub struct LobeExtras<'a> {
    /// Fixed fdm/sdm cutting steps per delay.
    pub cutting_steps: Option<std::num::NonZeroUsize>,
    /// |mu| map CSV.
    pub map_out: Option<&'a Path>,
    /// |mu| heat map SVG.
    pub map_plot: Option<&'a Path>,
    /// Map depths MIN:MAX:N (mm).
    pub depths: Option<&'a str>,
}

/// Read the model and observations, pick the speeds and compute the limiting depths; with a
/// map requested, also the |mu| map (speeds, depths in m, rows per speed).
fn load_and_compute(
    model_path: &Path,
    method: Method,
    speeds: Option<&str>,
    observations: Option<&Path>,
    extras: &LobeExtras,
    quiet: bool,
) -> Result<(Option<Observations>, Vec<LobePoint>, Option<LobeMap>)> {
    let obs = observations.map(inputs::observations).transpose()?;
    let wants_map = extras.map_out.is_some() || extras.map_plot.is_some();
    validate::unused(
        !wants_map && extras.depths.is_some(),
        "--depths",
        "without --map-out or --map-plot",
        "the |mu| map",
    )?;
    let direct = extras.cutting_steps.is_none() && !wants_map;
    if let Some(lobes) = crate::measured::lobes(model_path, method, speeds)? {
        if !direct {
            bail!(
                "--cutting-steps, --map-out and --map-plot need a modal model (run chatter fit-frf)"
            );
        }
        return Ok((obs, lobes, None));
    }
    let model = inputs::model(model_path)?;
    let speeds = match speeds {
        Some(s) => validate::speeds(s)?,
        None => chatter_stability::speed_grid::lobe_speeds_rpm(&model),
    };
    if direct {
        return Ok((obs, compute_lobes(&model, method, &speeds, quiet)?, None));
    }
    if let Some(d) = method.discretization() {
        let d = extras.cutting_steps.map_or(d, |m| d.with_steps(m));
        validate::work_size(&model, d, &speeds, "--speeds")?;
    }
    let solver = crate::lobe_map::solver(&model, method, extras.cutting_steps)?;
    let bar = Bar::new(speeds.len() as u64, "lobes", quiet);
    let lobes = solver.lobes(&speeds, &bar)?;
    bar.finish();
    let map = if wants_map {
        let depths_m = match extras.depths {
            Some(s) => validate::grid("--depths", s, &validate::DEPTH_GRID_MM)?
                .into_iter()
                .map(|mm| mm * 1e-3)
                .collect(),
            None => crate::lobe_map::default_depths_m(&lobes)?,
        };
        let grid = crate::lobe_map::modulus_map(solver.as_ref(), &speeds, &depths_m, quiet)?;
        Some(LobeMap {
            speeds_rpm: speeds,
            depths_m,
            grid,
        })
    } else {
        None
    };
    Ok((obs, lobes, map))
}

/// A |mu| map of `chatter lobes`.
struct LobeMap {
    speeds_rpm: Vec<f64>,
    depths_m: Vec<f64>,
    grid: Vec<Vec<f64>>,
}

/// `chatter lobes`.
#[allow(clippy::too_many_arguments)]
pub fn lobes(
    model_path: &Path,
    method: Method,
    speeds: Option<&str>,
    observations: Option<&Path>,
    out: Option<&Path>,
    plot: Option<&Path>,
    extras: &LobeExtras,
    quiet: bool,
) -> Result<()> {
    check_outputs(out, plot, observations)?;
    output::check_optional_file("--map-out", extras.map_out)?;
    output::check_optional_file("--map-plot", extras.map_plot)?;
    let (obs, lobes, map) =
        load_and_compute(model_path, method, speeds, observations, extras, quiet)?;
    warn_unbounded(&lobes, "their depth_mm and chatter_hz cells are empty");
    if let Some(m) = &map {
        if let Some(p) = extras.map_out {
            write_atomic(
                p,
                crate::lobe_map::csv(&m.speeds_rpm, &m.depths_m, &m.grid).as_bytes(),
            )?;
        }
        if let Some(p) = extras.map_plot {
            let title = format!(
                "Dominant multiplier |mu| ({}): blue stable, red chatter, black the limit",
                method.name()
            );
            let svg =
                crate::lobe_map::heat_map_svg(&title, &m.speeds_rpm, &m.depths_m, &m.grid, &lobes)?;
            write_atomic(p, svg.as_bytes())?;
        }
    }
    emit(out, &lobes_csv(&lobes))?;
    if let Some(p) = plot {
        let series = [Series {
            label: format!("{method:?} limiting depth").to_lowercase(),
            points: lobes
                .iter()
                .filter(|l| l.depth_m.is_finite())
                .map(|l| (l.speed_rpm, l.depth_mm()))
                .collect(),
            color: BLUE,
            dashed: false,
        }];
        line_chart(
            p,
            &format!(
                "Stability lobes ({}): limiting depth against spindle speed",
                method.name()
            ),
            "spindle speed (rpm)",
            "depth (mm)",
            &series,
            markers(obs.as_ref()).as_ref(),
        )?;
    }
    Ok(())
}

/// `--out` and `--plot` writable, and `--observations` only with `--plot` (they are drawn, not
/// used in the numbers).
pub fn check_outputs(
    out: Option<&Path>,
    plot: Option<&Path>,
    observations: Option<&Path>,
) -> Result<()> {
    output::check_optional_file("--out", out)?;
    output::check_optional_file("--plot", plot)?;
    validate::unused(
        observations.is_some() && plot.is_none(),
        "--observations",
        "without --plot",
        "drawing the observed cuts on the plot",
    )
}

/// `chatter multiplier`.
pub fn multiplier(
    model_path: &Path,
    speed_rpm: f64,
    depth_mm: f64,
    method: Method,
    variation: Option<chatter_stability::ssv::SpeedVariation>,
    quiet: bool,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let Some(solver) = method.discretization() else {
        bail!("--method zoa gives limiting depths, not multipliers; use fdm or sdm");
    };
    if let Some(variation) = variation {
        validate::work_size(&model, solver, &[speed_rpm], "--speed-rpm")?;
        let varied = chatter_stability::ssv::VariedSpeed {
            discretization: solver,
            variation,
        };
        let mu = varied.dominant_multiplier(&model, speed_rpm, depth_mm * 1e-3)?;
        let json = serde_json::json!({
            "speed_rpm": speed_rpm,
            "depth_mm": depth_mm,
            "method": solver.name(),
            "ssv_amplitude_ratio": variation.amplitude_ratio(),
            "ssv_frequency_ratio": variation.frequency_ratio(),
            "period_s": mu.period_s,
            "modulus": mu.modulus(),
            "real": mu.value.re,
            "imag": mu.value.im,
            "stable": mu.modulus() < 1.0,
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(());
    }
    validate::work_size(&model, solver, &[speed_rpm], "--speed-rpm")?;
    let steps = solver.steps_at(&model, speed_rpm);
    let working = Working::start(
        &format!(
            "multiplier: {} at {speed_rpm} rpm, {steps} steps per delay",
            solver.name()
        ),
        quiet,
    );
    let (mu, chatter_hz) = solver.chatter_frequency_hz(&model, speed_rpm, depth_mm * 1e-3)?;
    working.finish();
    let json = serde_json::json!({
        "speed_rpm": speed_rpm,
        "depth_mm": depth_mm,
        "method": solver.name(),
        "modulus": mu.modulus(),
        "real": mu.value.re,
        "imag": mu.value.im,
        "frequency_hz": mu.principal_frequency_hz(),
        "chatter_hz": chatter_hz,
        "kind": mu.kind(),
        "stable": mu.modulus() < 1.0,
    });
    println!("{}", serde_json::to_string_pretty(&json)?);
    Ok(())
}

/// Title of the demo's credibility plot (and its caption in the report page).
pub const CREDIBILITY_TITLE: &str = "Turning tool of Ahmadi (2022) after updating: limit at the \
     posterior mean, bounds where the dominant multiplier's mean modulus +- 1 sd reaches 1";

/// What `--out` of `chatter demo` may hold (the folder of its previous run).
pub const DEMO_FILES: [&str; 17] = [
    "papers.csv",
    "turning_lobes.csv",
    "turning_lobes.svg",
    "eq34_covariance.json",
    "turning_credibility.csv",
    "turning_credibility.svg",
    "milling_bands.csv",
    "milling_bands.svg",
    "milling_bands-theta.svg",
    "milling_bands-distance.svg",
    "milling_bands-roots.svg",
    "milling_frf.csv",
    "shopfloor_model.json",
    "shopfloor_observations.json",
    "diagnosis",
    "summary.json",
    "report.html",
];

/// `chatter demo`: the main job on the embedded examples, results into a folder that appears
/// complete or not at all.
pub fn demo(out_dir: &Path, quiet: bool) -> Result<()> {
    use chatter_dynamics::examples;
    let mut folder = Folder::new("--out", out_dir, &DEMO_FILES)?;
    let mut summary = serde_json::Map::new();
    let stage = |k: usize, what: &str| {
        if !quiet {
            eprintln!("demo {k}/5: {what}");
        }
    };

    // 1. Turning case of seed 000: lobes (FDM and exact ZOA) over the tested speeds with the cuts.
    stage(
        1,
        "turning lobes of the Ahmadi (2022) tool and its test cuts",
    );
    let turning = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    let speeds: Vec<f64> = (0..=120).map(|i| 6800.0 + 7.5 * i as f64).collect();
    let fdm = compute_lobes(&turning, Method::Fdm, &speeds, quiet)?;
    folder.add("turning_lobes.csv", lobes_csv(&fdm));
    folder.add(
        "turning_lobes.svg",
        line_chart_svg(
            "Turning tool of Ahmadi (2022), hammer-test modes: FDM lobes and test cuts",
            "spindle speed (rpm)",
            "width of cut (mm)",
            &[Series {
                label: "FDM limiting width".into(),
                points: fdm.iter().map(|p| (p.speed_rpm, p.depth_mm())).collect(),
                color: BLUE,
                dashed: false,
            }],
            markers(Some(&obs)).as_ref(),
        )?,
    );
    let at = |rpm: f64| {
        fdm.iter()
            .min_by(|a, b| (a.speed_rpm - rpm).abs().total_cmp(&(b.speed_rpm - rpm).abs()))
            .map(|p| serde_json::json!({"speed_rpm": p.speed_rpm, "depth_mm": p.depth_mm(), "chatter_hz": p.chatter_hz}))
    };
    summary.insert(
        "turning_limits".into(),
        serde_json::json!([at(6950.0), at(7150.0), at(7300.0), at(7500.0)]),
    );

    // 2. Credibility bounds of the same case after updating (000 Section 6.4, Fig. 8): the
    //    model at the posterior mean of Eq. 34's distribution with its covariance (written out
    //    as a covariance file that `chatter bands --covariance` reads).
    stage(2, "credibility bounds after updating (Eq. 34)");
    let dist = eq34_distribution(&mut folder)?;
    let updated = dist.mean_model(&turning)?;
    let coarse: Vec<f64> = (0..=36).map(|i| 6800.0 + 25.0 * i as f64).collect();
    let updated_lobes = compute_lobes(&updated, Method::Fdm, &coarse, quiet)?;
    let depths = lobe_covering_depths(&updated_lobes)?;
    let rule = chatter_uncertainty::perturbation::BoundRule::ComplexSd;
    let bands = chatter_jobs::bands::perturbation(
        &turning,
        &dist,
        Method::Fdm,
        rule,
        &coarse,
        Some(depths),
        &chatter_progress::Silent,
    )
    .map_err(crate::job_error)?;
    let (csv, series) = crate::bands::credibility_bands(&bands.bounds, rule);
    folder.add("turning_credibility.csv", csv);
    folder.add(
        "turning_credibility.svg",
        line_chart_svg(
            CREDIBILITY_TITLE,
            "spindle speed (rpm)",
            "width of cut (mm)",
            &series,
            markers(Some(&obs)).as_ref(),
        )?,
    );

    // 3. Milling example of seed 001: zero-order lobes with Type B offsets (100 rpm, 0.2 mm).
    stage(
        3,
        "milling lobes with speed and depth offsets (Schmitz 2023)",
    );
    let milling = examples::schmitz_2023_milling();
    let bands = chatter_uncertainty::geometric::schmitz2023::example_boundaries()?;
    let curve: Vec<(f64, f64)> = bands
        .points
        .iter()
        .map(|p| (p.speed_rpm, p.depth_mm))
        .collect();
    folder.add("milling_bands.csv", crate::bands::geometric_csv(&bands));
    folder.add(
        "milling_bands.svg",
        line_chart_svg(
            "Milling example of Schmitz (2023): zero-order lobes offset by 100 rpm and 0.2 mm",
            "spindle speed (rpm)",
            "axial depth (mm)",
            &crate::bands::band_series(
                curve,
                bands.lower.clone(),
                bands.upper.clone(),
                ["mean boundary", "lower offset", "upper offset"],
            ),
            None,
        )?,
    );
    for (name, svg) in crate::bands::offset_detail_svgs("milling_bands", &bands)? {
        folder.add(name, svg);
    }
    folder.add("milling_frf.csv", frf_csv(&milling, 0.0, 1500.0, 301, 0, 0));

    // 4. The seeds' published numbers beside ours, with tolerances.
    stage(
        4,
        "the papers' numbers beside ours (000 Table 3, 001 Sec. 4, 003 Table 2, 004)",
    );
    let rows = crate::papers::rows(&bands)?;
    folder.add("papers.csv", crate::papers::csv(&rows));
    summary.insert(
        "papers".into(),
        serde_json::json!({
            "rows": rows.len(),
            "within_tolerance": rows.iter().filter(|r| r.within()).count(),
            "outside": rows.iter().filter(|r| !r.within()).map(|r| format!("{}: {}", r.source, r.quantity)).collect::<Vec<_>>(),
        }),
    );

    // 5. Sim-to-real gap: a synthetic shop-floor campaign of a milling machine whose process
    //    damping the nominal model leaves out, diagnosed from the nominal model and the data.
    stage(5, "sim-to-real gap diagnosis of a synthetic campaign");
    let nominal = chatter_gap::nominal_milling()?;
    let mut scenario = chatter_gap::Scenario::new(chatter_gap::HiddenEffect::ParameterError, 101);
    (scenario.effect, _) = chatter_gap::generator::effect_at(
        chatter_gap::EffectClass::ProcessDamping,
        2.0,
        &nominal,
        scenario.speed_range_rpm,
    )?;
    let campaign = chatter_gap::synthesize(&nominal, &scenario)?;
    folder.add(
        "shopfloor_model.json",
        serde_json::to_string_pretty(&chatter_dynamics::ModelFile::from_model(&nominal))?,
    );
    folder.add("shopfloor_observations.json", campaign.to_json_string());
    let (model_path, obs_path) = (
        folder.path_of("shopfloor_model.json"),
        folder.path_of("shopfloor_observations.json"),
    );
    let (recorded, report, files) = crate::diagnose::report_of(
        &nominal,
        &campaign,
        &crate::diagnose::DiagnoseRequest {
            model: &model_path,
            observations: &obs_path,
            seed: 1,
            samples: 120,
            validation: crate::diagnose::ValidationArg::Kfold,
            folds: 3,
            out: Some(&folder.path_of("diagnosis")),
            report: None,
            netcdf: false,
            quiet,
        },
    )?;
    let diagnosis = recorded.diagnosis;
    folder.add("diagnosis/report.json", report);
    for (name, bytes) in files {
        folder.add(Path::new("diagnosis").join(name), bytes);
    }
    summary.insert(
        "diagnosis".into(),
        serde_json::json!({
            "hidden_effect": "process_damping (C = 6e4 N/m), withheld from the model",
            "verdict": diagnosis.verdict.name(),
        }),
    );

    let page = crate::report::jobs::demo(
        &folder,
        &[
            ("turning tool of Ahmadi (2022), hammer-test modes", &turning),
            ("milling example of Schmitz (2023)", &milling),
            ("shop-floor machine: the nominal model diagnosed", &nominal),
        ],
        &diagnosis,
    )?;
    folder.add("report.html", page.html());
    let mut files: Vec<String> = folder
        .paths()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    files.push(folder.path_of("summary.json").display().to_string());
    summary.insert("files".into(), serde_json::json!(files));
    folder.add("summary.json", serde_json::to_string_pretty(&summary)?);
    for p in folder.commit()? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// The posterior of 000 Section 6.4 (`chatter_dynamics::examples::ahmadi_2022_posterior`: the
/// mean and the covariance of Eq. 34 of theta_omega_2, theta_zeta_2, theta_phi_2), written to
/// `eq34_covariance.json` in `out_dir`.
fn eq34_distribution(
    folder: &mut crate::output::Folder,
) -> Result<chatter_uncertainty::parameters::ParameterDistribution> {
    folder.add(
        "eq34_covariance.json",
        chatter_dynamics::examples::AHMADI_2022_POSTERIOR,
    );
    let posterior = chatter_dynamics::examples::ahmadi_2022_posterior();
    Ok(chatter_uncertainty::parameters::ParameterDistribution::new(
        &posterior.parameter_names,
        posterior.mean,
        posterior.covariance,
        None,
        &folder.path_of("eq34_covariance.json"),
    )?)
}

/// Depths (mm) from half the lowest to 1.4 times the highest finite limit of `lobes`, 0.025 mm
/// apart: the credibility contours of every lobe, its top included, lie on the grid.
fn lobe_covering_depths(lobes: &[LobePoint]) -> Result<Vec<f64>> {
    let finite = lobes.iter().map(|p| p.depth_mm()).filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, 0.0f64), |(a, b), d| (a.min(d), b.max(d)));
    if !(lo.is_finite() && hi > 0.0) {
        bail!("no finite limiting depth to cover");
    }
    let (from, to, step) = (0.5 * lo, 1.4 * hi, 0.025);
    let n = ((to - from) / step).ceil() as usize;
    Ok((0..=n).map(|j| from + step * j as f64).collect())
}

/// `chatter simulate`: a simulated cut as signals CSV (header = channel names, first channel the
/// reference) or 32-bit float WAV (channels in the same order: coordinates, then once_per_rev).
pub fn simulate(
    model_path: &Path,
    settings: &chatter_dynamics::simulate::SimulationSettings,
    out: &Path,
    quiet: bool,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let bar = Bar::new(1000, "simulate", quiet);
    bar.announce(&format!(
        "{} s of cutting at {} rpm, {} samples",
        settings.duration_s,
        settings.speed_rpm,
        (settings.duration_s * settings.sample_rate_hz).round()
    ));
    let sim = chatter_dynamics::simulate::simulate_with_observer(&model, settings, &bar)?;
    bar.finish();
    let is_wav = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wav"));
    if is_wav {
        let spec = hound::WavSpec {
            channels: sim.channels.len() as u16,
            sample_rate: sim.sample_rate_hz.round() as u32,
            bits_per_sample: 32,
            sample_format: hound::SampleFormat::Float,
        };
        if (spec.sample_rate as f64 - sim.sample_rate_hz).abs() > 1e-9 {
            bail!(
                "--sample-rate-hz {} is not an integer; WAV needs an integer rate",
                sim.sample_rate_hz
            );
        }
        let mut buffer = std::io::Cursor::new(Vec::new());
        {
            let mut writer =
                hound::WavWriter::new(&mut buffer, spec).context("starting the WAV stream")?;
            let n = sim.channels[0].data.len();
            for k in 0..n {
                for c in &sim.channels {
                    writer
                        .write_sample(c.data[k] as f32)
                        .context("writing WAV samples")?;
                }
            }
            writer.finalize().context("finishing the WAV stream")?;
        }
        write_atomic(out, buffer.get_ref())?;
    } else {
        let mut csv = sim
            .channels
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(",");
        csv.push('\n');
        let n = sim.channels[0].data.len();
        for k in 0..n {
            let row: Vec<String> = sim
                .channels
                .iter()
                .map(|c| format!("{:e}", c.data[k]))
                .collect();
            csv.push_str(&row.join(","));
            csv.push('\n');
        }
        write_atomic(out, csv.as_bytes())?;
    }
    eprintln!(
        "wrote {} ({} samples, lost contact {:.1} %)",
        out.display(),
        sim.channels[0].data.len(),
        100.0 * sim.lost_contact_fraction
    );
    Ok(())
}
