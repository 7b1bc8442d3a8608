//! `chatter plan`: the next test cut as JSON, by value of information (003) or by maximum
//! material removal rate on a probability-of-stability contour (004).

use crate::progress::Bar;
use anyhow::Result;
use chatter_jobs::plan::PlanRequest;

use chatter_updating::parameters::parse_model_parameters;
use chatter_updating::plan::Strategy;
use chatter_updating::sampled::SampledBoundaries;
use std::path::PathBuf;

/// Test-selection strategies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StrategyArg {
    /// Largest expected reduction of a parameter's uncertainty (003).
    Voi,
    /// Largest material removal rate on the P_test contour (004).
    Mrr,
}

/// Arguments of `chatter plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Model file (JSON).
    #[arg(long)]
    model: PathBuf,
    /// Cuts made so far (JSON or cuts CSV); without it the first cut is planned from the prior
    /// on a grid from the model.
    #[arg(long)]
    observations: Option<PathBuf>,
    /// voi (003) or mrr (004).
    #[arg(long, value_enum)]
    strategy: StrategyArg,
    /// Probability of stability of the tested contour (mrr); default 0.5.
    #[arg(long)]
    p_test: Option<f64>,
    /// Sampled parameters, comma-separated; default kt_n_per_mm2,kn_n_per_mm2 (+ c_n_per_m with
    /// process damping).
    #[arg(long)]
    parameters: Option<String>,
    /// Priors file: marginals by name (as for `chatter update`), or one correlated normal
    /// `{"parameter_names", "mean", "covariance"}` such as 004's RCSA prior (its names are then
    /// the sampled parameters unless --parameters is given).
    #[arg(long)]
    priors: Option<PathBuf>,
    /// The parameter whose uncertainty value of information reduces; default c_n_per_m when
    /// sampled, else the first parameter.
    #[arg(long)]
    target: Option<String>,
    /// Sampled stability boundaries.
    #[arg(long, default_value_t = 300)]
    paths: usize,
    /// Candidate speeds MIN:MAX:N (rpm); default the cut speeds +- 25 %.
    #[arg(long)]
    speeds: Option<String>,
    /// Candidate depths MIN:MAX:N (mm); default up to twice the deepest cut.
    #[arg(long)]
    depths: Option<String>,
    /// Feed per tooth (mm) for the material removal rate.
    #[arg(long, default_value_t = 0.1)]
    feed_per_tooth_mm: f64,
    /// Stability method of the sampled boundaries: fdm (default), sdm, or zoa (the
    /// zero-order method 004 used; complex modes need it).
    #[arg(long, value_enum)]
    method: Option<chatter_stability::prepared::Method>,
    /// Seed of the prior samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Width of the cut likelihood in depth (mm): sigma of 003 (voi, default 0.5) or s_S of 004
    /// (mrr, default 0.125).
    #[arg(long)]
    sigma_depth_mm: Option<f64>,
    /// s_fc of 004 (Hz): allowed chatter-frequency disagreement (mrr only; default 50).
    #[arg(long)]
    sigma_chatter_hz: Option<f64>,
    /// Cap on test cuts: `stop` is true once this many cuts were made.
    #[arg(long, default_value_t = chatter_updating::plan::DEFAULT_MAX_TESTS)]
    max_tests: usize,
    /// One self-contained HTML page: inputs, plots, numbers, next test, warnings.
    #[arg(long)]
    report: Option<PathBuf>,
    /// The probability of stability after the cuts as CSV `speed_rpm,depth_mm,p_stable`, on
    /// the sampled speeds and the --depths grid (default: 60 depths up to 1.2 times the
    /// deepest sampled limit).
    #[arg(long)]
    map_out: Option<PathBuf>,
    /// The sampled boundaries as CSV `path,probability,speed_rpm,depth_mm` (one row per path
    /// and speed; depth empty where the path has no boundary below the depth ceiling).
    #[arg(long)]
    boundaries_out: Option<PathBuf>,
}

/// `--map-out`: P_s on the sampled speeds x `depths_mm` (or a default grid).
fn map_csv(b: &SampledBoundaries, depths_mm: Option<&[f64]>) -> String {
    let deepest_mm = b
        .limits_mm
        .iter()
        .flatten()
        .filter(|d| d.is_finite())
        .fold(0.0f64, |a, d| a.max(*d));
    let default: Vec<f64> = (1..=60)
        .map(|i| 1.2 * deepest_mm.max(1e-3) * i as f64 / 60.0)
        .collect();
    let map = b.stability_map(depths_mm.unwrap_or(&default));
    let mut csv = String::from("speed_rpm,depth_mm,p_stable\n");
    for (s, row) in map.speeds_rpm.iter().zip(&map.p_stable) {
        for (d, p) in map.depths_mm.iter().zip(row) {
            csv += &format!("{s},{d},{p}\n");
        }
    }
    csv
}

/// `--boundaries-out`: every path's limiting depth at every sampled speed.
fn boundaries_csv(b: &SampledBoundaries) -> String {
    let mut csv = String::from("path,probability,speed_rpm,depth_mm\n");
    for (i, (p, row)) in b.probabilities.iter().zip(&b.limits_mm).enumerate() {
        for (s, d) in b.speeds_rpm.iter().zip(row) {
            let depth = if d.is_finite() {
                format!("{d}")
            } else {
                String::new()
            };
            csv += &format!("{i},{p},{s},{depth}\n");
        }
    }
    csv
}

/// Run `chatter plan`: print the next cut as JSON on stdout.
pub fn run(args: &PlanArgs, quiet: bool) -> Result<()> {
    use crate::validate;
    crate::output::check_optional_file("--report", args.report.as_deref())?;
    crate::output::check_optional_file("--map-out", args.map_out.as_deref())?;
    crate::output::check_optional_file("--boundaries-out", args.boundaries_out.as_deref())?;
    let voi = args.strategy == StrategyArg::Voi;
    validate::unused(
        voi && args.p_test.is_some(),
        "--p-test",
        "with --strategy voi",
        "--strategy mrr",
    )?;
    validate::unused(
        !voi && args.target.is_some(),
        "--target",
        "with --strategy mrr",
        "--strategy voi",
    )?;
    validate::unused(
        voi && args.sigma_chatter_hz.is_some(),
        "--sigma-chatter-hz",
        "with --strategy voi",
        "--strategy mrr (003's likelihood has no frequency term)",
    )?;
    if let Some(mm) = args.sigma_depth_mm {
        validate::option("--sigma-depth-mm", mm, &validate::SIGMA_DEPTH_MM)?;
    }
    if let Some(hz) = args.sigma_chatter_hz {
        validate::option("--sigma-chatter-hz", hz, &validate::SIGMA_CHATTER_HZ)?;
    }
    if let Some(p) = args.p_test {
        validate::option("--p-test", p, &validate::PROBABILITY)?;
    }
    validate::count("--paths", args.paths, 10, 100_000, "sampled boundaries")?;
    validate::option(
        "--feed-per-tooth-mm",
        args.feed_per_tooth_mm,
        &chatter_jobs::simulate::FEED_MM,
    )?;
    let speeds = args.speeds.as_deref().map(validate::speeds).transpose()?;
    let depths = args
        .depths
        .as_deref()
        .map(|s| validate::grid("--depths", s, &chatter_jobs::checks::DEPTH_GRID_MM))
        .transpose()?;
    let model = crate::inputs::model(&args.model)?;
    let observations = match &args.observations {
        Some(path) => {
            let observations = crate::inputs::observations(path)?;
            validate::observations_match(&model, &observations, path, &args.model)?;
            validate::observation_work_size(&model, &observations, path)?;
            observations
        }
        None => chatter_dynamics::Observations::default(),
    };
    if let Some(s) = &speeds {
        validate::work_size(
            &model,
            chatter_stability::monodromy::Discretization::full(),
            s,
            "--speeds",
        )?;
    }
    let (priors, joint_prior) = crate::inputs::priors(args.priors.as_deref())?;
    let request = PlanRequest {
        strategy: match args.strategy {
            StrategyArg::Voi => Strategy::ValueOfInformation,
            StrategyArg::Mrr => Strategy::MaterialRemovalRate,
        },
        p_test: args.p_test.unwrap_or(0.5),
        parameters: args
            .parameters
            .as_deref()
            .map(parse_model_parameters)
            .transpose()?,
        priors,
        joint_prior,
        target: args.target.as_deref().map(str::parse).transpose()?,
        paths: args.paths,
        speeds_rpm: speeds,
        depths_mm: depths,
        feed_per_tooth_mm: args.feed_per_tooth_mm,
        method: args.method,
        seed: args.seed,
        max_tests: args.max_tests,
        sigma_depth_mm: args.sigma_depth_mm,
        sigma_chatter_hz: args.sigma_chatter_hz,
    };
    let progress = Bar::new(args.paths as u64, "sampled boundaries", quiet);
    let outcome = chatter_jobs::plan::plan(&model, &observations, &request, &progress)
        .map_err(crate::job_error)?;
    progress.finish();
    let warnings = chatter_jobs::plan::warnings(&outcome, &request);
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    let strategy = match args.strategy {
        StrategyArg::Voi => "voi",
        StrategyArg::Mrr => "mrr",
    };
    if let Some(path) = &args.map_out {
        let csv = map_csv(&outcome.boundaries, request.depths_mm.as_deref());
        crate::output::write_atomic(path, csv.as_bytes())?;
    }
    if let Some(path) = &args.boundaries_out {
        crate::output::write_atomic(path, boundaries_csv(&outcome.boundaries).as_bytes())?;
    }
    let mut json = serde_json::to_value(&outcome)?;
    if let Some(map) = json.as_object_mut() {
        map.insert("strategy".into(), strategy.into());
        map.insert("warnings".into(), warnings.clone().into());
    }
    if let Some(path) = &args.report {
        crate::report::jobs::plan(
            &model,
            &observations,
            &outcome,
            &warnings,
            crate::report::jobs::plan_plot(&observations, &outcome),
        )?
        .write(path)?;
    }
    println!("{}", serde_json::to_string_pretty(&json)?);
    Ok(())
}
