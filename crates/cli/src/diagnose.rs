//! `chatter diagnose`: the sim-to-real gap between a model and shop-floor observations.
//!
//! An observations file with `signals` (a shop's recordings) is diagnosed from them:
//! `chatter_jobs::diagnose::diagnose_recordings` judges each record by chatter detection and
//! identifies the stable ones by OMA (the library calls of `chatter detect` and `chatter oma`,
//! their default settings), and the diagnosis runs on those cuts and poles with the file's own.
//! Each record's verdict, chatter frequency, identified pole, evidence, or the reason it gave no
//! cut or pole, is the `records` table of the report JSON, of `diagnosis.json` and of the
//! `--report` page.

use crate::output::Folder;
use crate::plot::{Markers, Series, line_chart_svg};
use crate::{inputs, progress::Bar};
use anyhow::{Context, Result, bail};
use chatter_gap::{Diagnosis, EffectClass, Validation};
use chatter_jobs::diagnose::{
    DiagnoseRequest as JobRequest, RecordedDiagnosis, diagnose_recordings,
};
use chatter_jobs::inference_data::{Draws, InferenceData};
use chatter_jobs::recordings::{RecordRow, RecordsRequest};
use chatter_progress::Observer;
use plotters::style::{BLUE, RED};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Held-out validation schemes of the CLI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ValidationArg {
    /// Random folds.
    Kfold,
    /// Leave one speed band out.
    SpeedBands,
    /// No validation.
    Off,
}

/// What `chatter diagnose` was asked.
pub struct DiagnoseRequest<'a> {
    pub model: &'a Path,
    pub observations: &'a Path,
    pub seed: u64,
    pub samples: usize,
    pub validation: ValidationArg,
    pub folds: usize,
    pub out: Option<&'a Path>,
    /// HTML report page.
    pub report: Option<&'a Path>,
    /// Every class's InferenceData netCDF under `out`.
    pub netcdf: bool,
    pub quiet: bool,
}

/// What stdout gets: the diagnosis without the per-observation residuals (those go to
/// `diagnosis.json` under `--out`).
#[derive(serde::Serialize)]
struct Report<'a> {
    verdict: &'static str,
    best_class: EffectClass,
    classes: &'a [chatter_gap::diagnose::ClassReport],
    regions: &'a [chatter_gap::regions::Region],
    #[serde(skip_serializing_if = "Option::is_none")]
    shrink: Option<&'a chatter_gap::shrink::Shrink>,
    #[serde(skip_serializing_if = "Option::is_none")]
    validation: Option<&'a chatter_gap::shrink::ValidationReport>,
    predictive_check: &'a chatter_gap::PredictiveCheck,
    nominal_log_evidence: f64,
    alternative_log_evidence: f64,
    nominal_check: &'a chatter_gap::PredictiveCheck,
    /// Largest shift of any prediction by the best class, in noise standard deviations.
    practical_shift_std: f64,
    notes: &'a [String],
    /// One row per signal record (absent without `signals`).
    #[serde(skip_serializing_if = "<[RecordRow]>::is_empty")]
    records: &'a [RecordRow],
}

/// Progress over the classes and the validation folds.
struct Progress {
    bar: Bar,
    done: AtomicUsize,
}

impl Observer for Progress {
    fn class_done(&self, _class: &str, _log_evidence: f64) {
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.bar.set(k);
    }
    fn steps_done(&self, _done: usize, _total: usize) {
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.bar.set(k);
    }
}

/// Files of a result: name and content.
pub type Files = Vec<(String, Vec<u8>)>;

/// What `--out` of `chatter diagnose` may hold.
pub const FILES: [&str; 6] = [
    "diagnosis.json",
    "inference_data",
    "diagnosed_model.json",
    "diagnosed_effects.json",
    "lobes.svg",
    "residuals.svg",
];

/// `chatter diagnose`: the report JSON on stdout, the files in `--out`.
pub fn run(r: &DiagnoseRequest, folds_given: bool) -> Result<()> {
    let folder = r
        .out
        .map(|dir| Folder::new("--out", dir, &FILES))
        .transpose()?;
    crate::output::check_optional_file("--report", r.report)?;
    if folds_given && r.validation == ValidationArg::Off {
        bail!("--folds is not used with --validation off; it is for kfold and speed-bands");
    }
    let model = inputs::model(r.model)?;
    let observations = inputs::observations(r.observations)?;
    let (recorded, json, files) = report_of(&model, &observations, r)?;
    if let Some(path) = r.report {
        crate::report::jobs::diagnose(&model, &observations, &recorded, &files)?.write(path)?;
    }
    if let Some(mut folder) = folder {
        for (name, bytes) in files {
            folder.add(name, bytes);
        }
        folder.commit()?;
    }
    let mut stdout = std::io::stdout().lock();
    writeln!(stdout, "{json}").context("writing to stdout")
}

/// The diagnosis (with the table of the signal records it was made from), its report JSON and,
/// with `out` or `report`, the files `diagnosis.json`, `diagnosed_model.json` (and
/// `diagnosed_effects.json`), `lobes.svg` and `residuals.svg` (name and content; the caller
/// writes them), of a model and observations already read (`r.model` and `r.observations` name
/// them in messages).
pub fn report_of(
    model: &chatter_dynamics::ModalModel,
    observations: &chatter_dynamics::Observations,
    r: &DiagnoseRequest,
) -> Result<(RecordedDiagnosis, String, Files)> {
    crate::validate::observations_match(model, observations, r.observations, r.model)?;
    // the records' speeds too: their cuts and poles are evaluated like the file's own
    let speeds: Vec<f64> = observations
        .speeds_rpm()
        .into_iter()
        .chain(observations.signals.iter().map(|s| s.speed_rpm))
        .collect();
    crate::validate::work_size(
        model,
        chatter_stability::monodromy::Discretization::full(),
        &speeds,
        &format!("{} (observed speeds)", r.observations.display()),
    )?;
    let validation = match r.validation {
        ValidationArg::Kfold => Validation::KFold { folds: r.folds },
        ValidationArg::SpeedBands => Validation::SpeedBands { bands: r.folds },
        ValidationArg::Off => Validation::Off,
    };
    let request = JobRequest {
        seed: r.seed,
        samples: r.samples,
        validation,
        pointwise: r.netcdf,
    };
    // before the work; with records, the folds are checked by the job against the cuts and
    // poles made from them
    let early = if observations.signals.is_empty() {
        request
    } else {
        JobRequest {
            validation: Validation::Off,
            ..request
        }
    };
    chatter_jobs::diagnose::check(observations, &early).map_err(crate::job_error)?;
    let folds = if validation == Validation::Off {
        0
    } else {
        r.folds
    };
    let progress = Progress {
        bar: Bar::new(
            // the listed classes, the open alternative `speed_band`, the folds
            (EffectClass::ALL.len() + 1 + folds) as u64,
            "diagnosing",
            r.quiet,
        ),
        done: AtomicUsize::new(0),
    };
    if !observations.signals.is_empty() {
        progress.bar.announce(&format!(
            "chatter detection and OMA of {} signal records first",
            observations.signals.len()
        ));
    }
    let recorded = diagnose_recordings(
        model,
        observations,
        &request,
        &RecordsRequest::default(),
        &progress,
    )
    .map_err(crate::job_error)
    .with_context(|| {
        format!(
            "diagnosing {} against {}",
            r.observations.display(),
            r.model.display()
        )
    })?;
    progress.bar.finish();
    let d = &recorded.diagnosis;
    let report = Report {
        verdict: d.verdict.name(),
        best_class: d.best_class,
        classes: &d.classes,
        regions: &d.regions,
        shrink: d.shrink.as_ref(),
        validation: d.validation.as_ref(),
        predictive_check: &d.predictive_check,
        nominal_log_evidence: d.nominal_log_evidence,
        alternative_log_evidence: d.alternative_log_evidence,
        nominal_check: &d.nominal_check,
        practical_shift_std: d.practical_shift,
        notes: &d.notes,
        records: &recorded.records,
    };
    let mut files: Files = Vec::new();
    if r.out.is_some() || r.report.is_some() {
        let diagnosis = &recorded.diagnosis;
        let full = serde_json::to_string_pretty(&recorded)?;
        files.push(("diagnosis.json".into(), full.into_bytes()));
        files.push((
            "diagnosed_model.json".into(),
            diagnosis.diagnosed_model().to_json_string().into_bytes(),
        ));
        let (softening_per_rpm2, drift_rate) = diagnosis.diagnosed_effects();
        if softening_per_rpm2 != 0.0 || drift_rate != 0.0 {
            let effects = serde_json::json!({
                "note": "effects of the diagnosed machine that a model file does not hold yet",
                "natural_frequency_softening_per_rpm2": softening_per_rpm2,
                "cutting_coefficient_drift_over_campaign": drift_rate,
            });
            files.push((
                "diagnosed_effects.json".into(),
                serde_json::to_string_pretty(&effects)?.into_bytes(),
            ));
        }
        files.push(("lobes.svg".into(), lobe_plot(diagnosis)?.into_bytes()));
        files.push((
            "residuals.svg".into(),
            residual_map(diagnosis)?.into_bytes(),
        ));
        if r.netcdf {
            for c in &diagnosis.classes {
                let p = &c.posterior;
                let data = InferenceData {
                    posterior: Draws {
                        names: &p.parameter_names,
                        rows: &p.samples,
                    },
                    prior: Some(Draws {
                        names: &p.parameter_names,
                        rows: &p.prior_draws,
                    }),
                    log_likelihood: Some(&p.log_likelihood),
                    attributes: vec![
                        ("log_evidence", c.log_evidence),
                        ("probability", c.probability),
                    ],
                };
                files.push((
                    format!("inference_data/{}.nc", c.name),
                    data.to_netcdf().map_err(crate::job_error)?,
                ));
            }
        }
    }
    let json = serde_json::to_string_pretty(&report)?;
    Ok((recorded, json, files))
}

/// Lobes of the nominal and the diagnosed model over the observed cuts.
fn lobe_plot(d: &Diagnosis) -> Result<String> {
    let cuts = &d.residuals.nominal.cuts;
    let (lo, hi) = cuts
        .iter()
        .map(|c| c.speed_rpm)
        .fold((f64::INFINITY, 0.0f64), |(a, b), s| (a.min(s), b.max(s)));
    let (lo, hi) = if lo < hi {
        (lo, hi)
    } else {
        (0.8 * hi.max(1.0), 1.2 * hi.max(1.0))
    };
    let speeds: Vec<f64> = (0..200)
        .map(|i| lo + (hi - lo) * i as f64 / 199.0)
        .collect();
    let lobes = d.lobes(&speeds);
    let series = [
        Series {
            label: "nominal".into(),
            points: lobes.iter().map(|l| (l.speed_rpm, l.nominal_mm)).collect(),
            color: BLUE,
            dashed: false,
        },
        Series {
            label: format!("diagnosed ({})", d.best_class),
            points: lobes
                .iter()
                .map(|l| (l.speed_rpm, l.diagnosed_mm))
                .collect(),
            color: RED,
            dashed: false,
        },
    ];
    let markers = Markers {
        stable: cuts
            .iter()
            .filter(|c| c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
        unstable: cuts
            .iter()
            .filter(|c| !c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
    };
    line_chart_svg(
        &format!("verdict: {}", d.verdict.name()),
        "spindle speed (rpm)",
        "limiting depth (mm)",
        &series,
        Some(&markers),
    )
}

/// Every cut at its depth over the nominal limit: circles above 1 and crosses below 1 disagree
/// with the nominal model; the diagnosed limit over the nominal one is drawn as dots.
fn residual_map(d: &Diagnosis) -> Result<String> {
    let nominal = &d.residuals.nominal.cuts;
    let diagnosed = &d.residuals.diagnosed.cuts;
    let ratio = |c: &chatter_gap::regions::CutResidual| (c.speed_rpm, c.depth_mm / c.limit_mm);
    let mut speeds: Vec<f64> = nominal.iter().map(|c| c.speed_rpm).collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    let line = Series {
        label: "nominal limit".into(),
        points: speeds.iter().map(|&s| (s, 1.0)).collect(),
        color: BLUE,
        dashed: false,
    };
    let diagnosed_limit = Series {
        label: "diagnosed limit / nominal limit".into(),
        points: nominal
            .iter()
            .zip(diagnosed)
            .map(|(n, g)| (n.speed_rpm, g.limit_mm / n.limit_mm))
            .collect(),
        color: RED,
        dashed: true,
    };
    let markers = Markers {
        stable: nominal
            .iter()
            .filter(|c| c.stable)
            .map(ratio)
            .filter(|p| p.1.is_finite())
            .collect(),
        unstable: nominal
            .iter()
            .filter(|c| !c.stable)
            .map(ratio)
            .filter(|p| p.1.is_finite())
            .collect(),
    };
    line_chart_svg(
        "cuts relative to the nominal boundary",
        "spindle speed (rpm)",
        "depth / nominal limiting depth",
        &[line, diagnosed_limit],
        Some(&markers),
    )
}
