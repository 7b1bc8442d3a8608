//! What each screen computes, over the library crates the CLI calls: the modal fit of a tap test
//! (`chatter fit-frf`: [`chatter_frf::fit_modes`]), the lobes with their Type B bands and the
//! recommended cut (`chatter bands --kind geometric`, `chatter recommend`:
//! [`type_b_offsets`], [`chatter_stability::recommend::highest_mrr_cut`]),
//! chatter detection of a recording (`chatter detect`: [`chatter_jobs::detect::detect_record`])
//! and learning (`chatter update`, `chatter diagnose`: [`chatter_jobs::update`],
//! [`chatter_jobs::diagnose`]). Results are JSON for the page, curves thinned to what a
//! screen shows.

use crate::error::{Result, ServeError};
use chatter_dynamics::model_file::ModeFile;
use chatter_dynamics::{ModalModel, ModelFile, Observations, Operation, SignalRecord, limits};
use chatter_frf::{FitOptions, fit_modes, read_frf};
use chatter_progress::{Observer, Silent};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::boundary::LobePoint;
use chatter_stability::recommend::{RecommendOptions, highest_mrr_cut};
use chatter_stability::speed_grid::lobe_speeds_rpm;
use chatter_stability::{DominantMultiplier, Method, PreparedSolver};
use chatter_uncertainty::geometric::{TypeBOffsets, type_b_offsets};
use serde_json::{Value, json};
use std::path::Path;

/// Points of a curve sent to the page.
const CURVE_POINTS: usize = 600;

/// Every `step`-th point so at most [`CURVE_POINTS`] remain (the last kept).
fn thin<T: Copy>(points: &[T]) -> Vec<T> {
    let step = points.len().div_ceil(CURVE_POINTS).max(1);
    let mut out: Vec<T> = points.iter().step_by(step).copied().collect();
    if let Some(&last) = points.last()
        && !(points.len() - 1).is_multiple_of(step)
    {
        out.push(last);
    }
    out
}

/// A model's errors and a job's errors as the page's message.
fn job_error(e: impl std::fmt::Display) -> ServeError {
    ServeError::Job(e.to_string())
}

/// A message of a reader with the staged file's path replaced by the user's file name.
fn named(e: impl std::fmt::Display, staged: &Path, shown: &str) -> String {
    e.to_string().replace(&staged.display().to_string(), shown)
}

/// The coordinates a tap test is taken as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TapDirections {
    /// x only.
    X,
    /// y only.
    Y,
    /// x, and y taken alike (a symmetric tool).
    Both,
}

impl TapDirections {
    /// From the form's `x`, `y` or `xy`.
    pub fn parse(text: &str) -> Result<Self> {
        match text {
            "x" => Ok(Self::X),
            "y" => Ok(Self::Y),
            "xy" | "" => Ok(Self::Both),
            other => Err(ServeError::bad(
                "direction",
                format!("`{other}`: expected x, y or xy (a symmetric tool)"),
            )),
        }
    }

    fn names(self) -> &'static [&'static str] {
        match self {
            Self::X => &["x"],
            Self::Y => &["y"],
            Self::Both => &["x", "y"],
        }
    }
}

/// A modal fit of a tap test as asked on the page.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// Lowest frequency fitted (Hz); default the FRF's lowest positive frequency.
    pub fmin_hz: Option<f64>,
    /// Highest frequency fitted (Hz); default the FRF's highest.
    pub fmax_hz: Option<f64>,
    /// Number of modes; default from the stabilization diagram.
    pub modes: Option<usize>,
    /// Coordinates the measured direct FRF stands for.
    pub directions: TapDirections,
}

/// Read the tap test at `path` (shown as `shown`), fit modes and build the setup's model: its
/// process (`operation`, `cutting`) with the fitted real modes along the tap directions, the
/// setup's current modes along other directions kept. Returns the model file's JSON and the
/// fit report (modes, misfits, the overlay of measured and fitted |H| and the stabilization
/// diagram).
pub fn fit_tap_test(
    path: &Path,
    shown: &str,
    process: &ModelFile,
    current: Option<&ModelFile>,
    request: &FitRequest,
) -> Result<(String, Value)> {
    let frf = read_frf(path, None).map_err(|e| ServeError::bad("file", named(e, path, shown)))?;
    let f = frf.frequencies_hz();
    let (lowest, highest) = (
        f.iter().copied().find(|&x| x > 0.0).unwrap_or(f[0]),
        f[f.len() - 1],
    );
    let fmin = request.fmin_hz.unwrap_or(lowest);
    let fmax = request.fmax_hz.unwrap_or(highest);
    for (field, v) in [("fmin_hz", fmin), ("fmax_hz", fmax)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(ServeError::bad(
                field,
                format!("{v}: expected a frequency >= 0 Hz"),
            ));
        }
    }
    if fmax <= fmin {
        return Err(ServeError::bad(
            "fmax_hz",
            format!("{fmax}: expected above fmin_hz {fmin}"),
        ));
    }
    if let Some(n) = request.modes
        && !(1..=50).contains(&n)
    {
        return Err(ServeError::bad("modes", format!("{n}: expected 1 to 50")));
    }
    let options = FitOptions {
        modes: request.modes,
        ..FitOptions::default()
    };
    let fit = fit_modes(&frf, fmin, fmax, &options).map_err(|e| {
        ServeError::bad(
            "file",
            format!("fitting `{shown}`: {}", named(e, path, shown)),
        )
    })?;
    let mut file = process.clone();
    let tapped = request.directions.names();
    file.modes = current.map_or_else(Vec::new, |c| {
        c.modes
            .iter()
            .filter(|m| {
                m.shape.is_none() && m.direction.as_deref().is_some_and(|d| !tapped.contains(&d))
            })
            .cloned()
            .collect()
    });
    let real: Vec<_> = fit.modes.iter().filter_map(|m| m.real_mode(0)).collect();
    if real.is_empty() {
        return Err(ServeError::bad(
            "file",
            format!(
                "`{shown}`: no fitted mode is a real mode with a positive modal mass in {fmin}-{fmax} \
                 Hz; widen the band around the resonance"
            ),
        ));
    }
    for d in tapped {
        file.modes.extend(real.iter().map(|m| ModeFile {
            frequency_hz: m.frequency_hz(),
            damping_ratio: m.damping_ratio(),
            stiffness_n_per_m: Some(m.stiffness_at(0)),
            direction: Some((*d).to_string()),
            shape: None,
            residue_phase_deg: None,
        }));
    }
    file.residuals = None;
    file.measured_frf = None;
    file.validate()
        .map_err(|e| ServeError::bad("file", format!("the model fitted to `{shown}`: {e}")))?;
    let band = frf.band(fmin, fmax).map_err(job_error)?;
    let um = 1e6;
    let overlay: Vec<[f64; 3]> = band
        .frequencies_hz()
        .iter()
        .zip(band.receptance_m_per_n())
        .map(|(&f, g)| [f, g.norm() * um, fit.real_mode_receptance(f).norm() * um])
        .collect();
    let stabilization: Vec<[f64; 3]> = fit
        .stabilization
        .iter()
        .flat_map(|o| {
            o.poles
                .iter()
                .map(move |&(f, _, stable)| [o.order as f64, f, f64::from(u8::from(stable))])
        })
        .collect();
    let report = json!({
        "file": shown,
        "band_hz": [fmin, fmax],
        "directions": tapped,
        "modes": fit.modes.iter().map(|m| json!({
            "frequency_hz": m.pole.frequency_hz,
            "damping_ratio": m.pole.damping_ratio,
            "stiffness_n_per_m": m.stiffness_n_per_m,
            "stability_share": m.stability_share,
        })).collect::<Vec<_>>(),
        "nrmse_real_modes": fit.real_mode_relative_misfit,
        "nrmse_complex_modes_with_residuals": fit.relative_misfit,
        "overlay_um_per_n": thin(&overlay),
        "stabilization": stabilization,
    });
    let text = serde_json::to_string_pretty(&file).map_err(job_error)?;
    Ok((text, report))
}

/// A model file's JSON as uploaded, checked: a valid model with modes of its own (a model whose
/// dynamics are `measured_frf` files refers to files on the user's disk; upload the FRF as a tap
/// test instead).
pub fn check_model(text: &str, shown: &str) -> Result<(ModalModel, ModelFile)> {
    let model = ModalModel::from_json_str(text, Path::new(shown))
        .map_err(|e| ServeError::bad("file", e.to_string()))?;
    let file = ModelFile::from_model(&model);
    if file.modes.is_empty() {
        return Err(ServeError::bad(
            "file",
            format!(
                "`{shown}`: a model with modes is expected; upload a measured FRF as a tap test"
            ),
        ));
    }
    Ok((model, file))
}

/// The lobes of the page.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeRequest {
    /// Deepest cut the tool takes (mm), for the recommendation.
    pub max_depth_mm: f64,
    /// Accepted probability of chatter of the recommendation.
    pub risk: f64,
}

/// The lobe diagram of `model` on the default speeds ([`lobe_speeds_rpm`]: lobe numbers 1-12
/// of the dominant mode, 20 per lobe): FDM limiting depths and chatter frequencies (as
/// [`chatter_jobs::bands::lobes`]), 001's Type B offset boundaries (100 rpm, 0.2 mm, the
/// paper's example; [`type_b_offsets`]) and the highest-MRR cut at the request's risk (milling
/// only) read from the same diagram.
pub fn lobes(model: &ModalModel, request: &LobeRequest, observer: &dyn Observer) -> Result<Value> {
    limits::DEPTH_MM
        .check("max_depth_mm", request.max_depth_mm)
        .map_err(|e| ServeError::bad("max_depth_mm", e.to_string()))?;
    let speeds = lobe_speeds_rpm(model);
    let fdm = Method::Fdm
        .prepare(model, &BoundaryOptions::default())
        .map_err(job_error)?;
    let lobes = fdm.lobes(&speeds, observer).map_err(job_error)?;
    let offsets = TypeBOffsets::new(100.0, 0.2).map_err(job_error)?;
    let bands =
        type_b_offsets(&chatter_jobs::bands::finite_curve(&lobes), offsets).map_err(job_error)?;
    let recommendation = match model.operation() {
        Operation::Milling(_) => {
            let mut options = RecommendOptions::new(request.max_depth_mm * 1e-3);
            options.risk = request.risk;
            let computed = Computed {
                solver: fdm.as_ref(),
                speeds_rpm: &speeds,
                lobes: &lobes,
            };
            Some(
                highest_mrr_cut(model, &computed, &speeds, &options)
                    .map_err(|e| ServeError::bad("risk", e.to_string()))?,
            )
        }
        Operation::Turning(_) => None,
    };
    let finite = |v: f64| v.is_finite().then_some(v);
    Ok(json!({
        "method": "fdm",
        "lobes": lobes.iter().map(|p| json!([
            p.speed_rpm, finite(p.depth_mm()), finite(p.chatter_hz)
        ])).collect::<Vec<_>>(),
        "band_offsets": {"speed_rpm": 100.0, "depth_mm": 0.2},
        "upper": thin(&bands.upper),
        "lower": thin(&bands.lower),
        "recommended": recommendation,
        "max_depth_mm": request.max_depth_mm,
        "risk": request.risk,
    }))
}

/// A prepared solver whose lobe diagram on `speeds_rpm` is already computed: the
/// recommendation reads that diagram instead of computing it a second time.
struct Computed<'a> {
    solver: &'a dyn PreparedSolver,
    speeds_rpm: &'a [f64],
    lobes: &'a [LobePoint],
}

impl PreparedSolver for Computed<'_> {
    fn name(&self) -> &'static str {
        self.solver.name()
    }

    fn dominant_multiplier(
        &self,
        speed_rpm: f64,
        depth_m: f64,
    ) -> chatter_stability::Result<DominantMultiplier> {
        self.solver.dominant_multiplier(speed_rpm, depth_m)
    }

    fn chatter_frequency_hz(
        &self,
        speed_rpm: f64,
        depth_m: f64,
    ) -> chatter_stability::Result<(DominantMultiplier, f64)> {
        self.solver.chatter_frequency_hz(speed_rpm, depth_m)
    }

    fn limiting_depth(&self, speed_rpm: f64) -> chatter_stability::Result<LobePoint> {
        match self.speeds_rpm.iter().position(|&s| s == speed_rpm) {
            Some(k) => Ok(self.lobes[k]),
            None => self.solver.limiting_depth(speed_rpm),
        }
    }

    fn lobes(
        &self,
        speeds_rpm: &[f64],
        observer: &dyn Observer,
    ) -> chatter_stability::Result<Vec<LobePoint>> {
        if speeds_rpm == self.speeds_rpm {
            Ok(self.lobes.to_vec())
        } else {
            self.solver.lobes(speeds_rpm, observer)
        }
    }
}

/// A recording as described on the page.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordingRequest {
    /// Spindle speed of the cut (rpm).
    pub speed_rpm: f64,
    /// Depth of the cut (mm).
    pub depth_mm: f64,
    /// Sample rate of a CSV record (Hz); a WAV or MP3 file gives its own.
    pub sample_rate_hz: Option<f64>,
}

/// Judge the recording at `path` (shown as `shown`) by chatter detection: the labelled cut
/// (its note naming the user's file) and the verdict with its evidence and spectrum.
pub fn detect(
    path: &Path,
    shown: &str,
    request: &RecordingRequest,
    model: Option<&ModalModel>,
) -> Result<(chatter_dynamics::Cut, Value)> {
    limits::SPEED_RPM
        .check("speed_rpm", request.speed_rpm)
        .map_err(|e| ServeError::bad("speed_rpm", e.to_string()))?;
    limits::DEPTH_MM
        .check("depth_mm", request.depth_mm)
        .map_err(|e| ServeError::bad("depth_mm", e.to_string()))?;
    if let Some(fs) = request.sample_rate_hz
        && !(fs.is_finite() && fs > 0.0 && fs <= 1e6)
    {
        return Err(ServeError::bad(
            "sample_rate_hz",
            format!("{fs}: expected a sample rate in (0, 1e6] Hz"),
        ));
    }
    let record = SignalRecord {
        file: path.to_path_buf(),
        speed_rpm: request.speed_rpm,
        depth_mm: request.depth_mm,
        sample_rate_hz: request.sample_rate_hz,
        once_per_rev_channel: None,
        quantity: None,
        sequence: None,
        radial_immersion: None,
        note: None,
    };
    let judged = chatter_jobs::detect::detect_record(
        0,
        &record,
        model,
        &chatter_jobs::detect::DetectRequest::default(),
        &Silent,
    )
    .map_err(|e| ServeError::bad("file", named(e, path, shown)))?;
    let mut cut = judged.cut;
    let stored = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    cut.note = cut.note.map(|n| n.replace(&stored, shown));
    let d = &judged.detection;
    let (lo, hi) = d.band_hz;
    let spectrum: Vec<[f64; 2]> = d
        .spectrum
        .frequencies_hz
        .iter()
        .zip(&d.spectrum.values)
        .filter(|(f, v)| **f >= lo && **f <= hi && v.is_finite())
        .map(|(f, v)| [*f, *v])
        .collect();
    let report = json!({
        "file": shown,
        "verdict": if cut.stable { "stable" } else { "chatter" },
        "chatter_hz": d.chatter_hz,
        "evidence": cut.evidence,
        "note": cut.note,
        "band_hz": [lo, hi],
        "harmonics_hz": d.harmonics_hz,
        "spectrum": thin_peaks(&spectrum),
    });
    Ok((cut, report))
}

/// At most [`CURVE_POINTS`] points of a spectrum, each the largest of its run (a thinned
/// spectrum keeps its lines).
fn thin_peaks(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let run = points.len().div_ceil(CURVE_POINTS).max(1);
    points
        .chunks(run)
        .filter_map(|c| c.iter().copied().max_by(|a, b| a[1].total_cmp(&b[1])))
        .collect()
}

/// A learning run as asked on the page.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LearnRequest {
    /// Seed of the samplers and the folds.
    pub seed: u64,
    /// Samples per class of the update.
    pub update_samples: usize,
    /// Samples per class of the diagnosis (40 or more).
    pub diagnose_samples: usize,
}

impl Default for LearnRequest {
    /// Seed 1, 200 update samples per class (a quick posterior on the shop floor; the CLI's
    /// default is 5000), the diagnosis's default 120 samples.
    fn default() -> Self {
        Self {
            seed: 1,
            update_samples: 200,
            diagnose_samples: chatter_jobs::diagnose::DEFAULT_SAMPLES,
        }
    }
}

/// Which step a learning run is in, for the progress line.
pub trait Stages: Observer {
    /// Step `name` starts (its own steps are then counted from 0).
    fn step(&self, name: &str);
}

/// Update the model from the setup's cuts and poles, then diagnose the gap between the model
/// and them; the result with the diagnosis in plain words.
pub fn learn(
    model: &ModalModel,
    observations: &Observations,
    request: &LearnRequest,
    observer: &dyn Stages,
) -> Result<Value> {
    observations
        .validate()
        .and_then(|()| observations.check_against(model))
        .map_err(|e| ServeError::bad("cut log", e.to_string()))?;
    observer.step("update: sampling the posterior");
    let update_request = chatter_jobs::update::UpdateRequest {
        samples: request.update_samples,
        ..chatter_jobs::update::UpdateRequest::new(request.seed)
    };
    let prepared = chatter_jobs::update::PreparedUpdate::new(model, observations, update_request)
        .map_err(job_error)?;
    let updated = prepared.run(observer).map_err(job_error)?;
    let r = &updated.result;
    let sd: Vec<f64> = (0..r.parameter_names.len())
        .map(|i| r.posterior_covariance[(i, i)].max(0.0).sqrt())
        .collect();
    observer.step("diagnosis: fitting the model classes");
    let diagnose_request = chatter_jobs::diagnose::DiagnoseRequest {
        samples: request.diagnose_samples,
        ..chatter_jobs::diagnose::DiagnoseRequest::new(request.seed)
    };
    let diagnosis =
        chatter_jobs::diagnose::diagnose(model, observations, &diagnose_request, observer)
            .map_err(job_error)?;
    Ok(json!({
        "update": {
            "parameters": r.parameter_names.iter().enumerate().map(|(i, n)| json!({
                "name": n, "mean": r.posterior_mean[i], "sd": sd[i],
            })).collect::<Vec<_>>(),
            "warnings": chatter_jobs::update::warnings(r),
            "model": ModelFile::from_model(&r.updated_model),
        },
        "diagnosis": {
            "verdict": diagnosis.verdict.name(),
            "summary": plain_words(&diagnosis),
            "report": diagnosis,
            "model": ModelFile::from_model(diagnosis.diagnosed_model()),
        },
        "observations": {"cuts": observations.cuts.len(), "poles": observations.poles.len()},
    }))
}

/// The diagnosis in sentences: the verdict, where the gap lies, how much better the diagnosed
/// model predicts held-out data.
pub fn plain_words(d: &chatter_gap::Diagnosis) -> Vec<String> {
    use chatter_gap::Verdict;
    let mut out = vec![match d.verdict {
        Verdict::Consistent => {
            "The model agrees with the logged cuts within their noise: nothing to correct.".into()
        }
        Verdict::Class(c) => format!(
            "The model is wrong, and the effect that explains it is {}.",
            c.name().replace('_', " ")
        ),
        Verdict::Unexplained => "The model is wrong, and none of the tried effects explains the \
                                 logged cuts: check the data, or the machine changed."
            .into(),
    }];
    // the three regions where the most observations contradict the model, by share
    let mut regions: Vec<&chatter_gap::regions::Region> =
        d.regions.iter().filter(|r| r.disagreements > 0).collect();
    regions.sort_by(|a, b| {
        let share = |r: &chatter_gap::regions::Region| {
            r.disagreements as f64 / r.observations.max(1) as f64
        };
        share(b).total_cmp(&share(a))
    });
    for r in regions.into_iter().take(3) {
        let range = r
            .range
            .map_or(String::new(), |[a, b]| format!(" ({a:.0} to {b:.0})"));
        let shift = r.boundary_offset_log_depth.map_or(String::new(), |o| {
            format!(
                "; there the real boundary lies {:.0} % {}",
                100.0 * (o.exp() - 1.0).abs(),
                if o > 0.0 { "higher" } else { "lower" }
            )
        });
        out.push(format!(
            "Where: {}{range}, {} of {} observations contradict the model{shift}.",
            r.name, r.disagreements, r.observations
        ));
    }
    if let Some(s) = &d.shrink {
        let m = &s.log_predictive_density_per_observation;
        out.push(format!(
            "On held-out cuts the diagnosed model predicts better: log predictive density per \
             observation {:.2} -> {:.2}.",
            m.before, m.after
        ));
        if let Some(b) = &s.balanced_misclassification {
            out.push(format!(
                "Cuts called wrongly (balanced): {:.0} % -> {:.0} %.",
                100.0 * b.before,
                100.0 * b.after
            ));
        }
    }
    out
}
