//! Python bindings of chatter (`import chatter`): the jobs of the `chatter` program
//! ([`chatter_jobs`]) and the library calls behind its simple commands, with numpy arrays in and
//! out. Units are in every name (`speed_rpm`, `depth_mm`, `frequency_hz`).
//!
//! Long calls run on a worker thread while the calling thread waits without the GIL and checks
//! for Ctrl-C every 50 ms. An interrupt cancels the call inside the libraries (their observer,
//! `chatter_progress::Observer::cancelled`, is polled between speeds, samples and sampler moves)
//! and raises `KeyboardInterrupt` once the worker has returned.

use chatter_dynamics::{ModalModel, ModelFile, Observations};
use chatter_jobs::bands::{BandKind, Bands, BandsOutcome, BandsRequest};
use chatter_jobs::campaign::{self, Campaign, CampaignOptions};
use chatter_jobs::lobes::{Dynamics, Lobes, LobesRequest};
use chatter_jobs::multiplier::{Multiplier, MultiplierRequest};
use chatter_stability::Method;
use chatter_uncertainty::parameters::ParameterDistribution;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Any library error as a Python `ValueError` with its message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The observer of a Python call: silent, and cancelled once the caller was interrupted. It
/// counts the library's polls ([`OBSERVER_POLLS`]) and remembers whether the library was told to
/// stop by one of them.
#[derive(Default)]
struct Interruptible {
    /// Set by the calling thread on Ctrl-C.
    cancel: AtomicBool,
    /// A poll of the library answered "cancelled".
    seen: AtomicBool,
}

impl chatter_progress::Observer for Interruptible {
    fn cancelled(&self) -> bool {
        OBSERVER_POLLS.fetch_add(1, Ordering::Relaxed);
        let cancel = self.cancel.load(Ordering::Relaxed);
        if cancel {
            self.seen.store(true, Ordering::Relaxed);
        }
        cancel
    }
}

/// Worker threads of calls still running (interrupted ones included until they return).
static RUNNING_WORKERS: AtomicUsize = AtomicUsize::new(0);

/// Polls of the cancellation by the libraries of all calls so far: a library that has polled is
/// inside its cancellable loop, what the interruption tests wait for before they interrupt.
static OBSERVER_POLLS: AtomicUsize = AtomicUsize::new(0);

/// Calls whose library stopped on a cancel: their worker returned after a poll had answered
/// "cancelled" (counted when the worker returns).
static CANCELS_SEEN: AtomicUsize = AtomicUsize::new(0);

/// How long an interrupted call waits for its worker to stop before it raises
/// `KeyboardInterrupt`. The libraries poll the cancellation between steps (a speed, a sample, a
/// sampler move), so the worker normally returns within milliseconds; a worker that is slower
/// (a long step on a loaded machine) finishes in the background after this wait, stopping at
/// its next poll.
const CANCEL_WAIT: Duration = Duration::from_secs(5);

/// How often the calling thread checks for Ctrl-C while its worker runs.
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// Run `work` on a worker thread with an observer that can cancel it; wait without the GIL,
/// checking signals every [`SIGNAL_CHECK`]. Signals are checked before the worker's result is
/// taken, also once it has finished, so that a Ctrl-C during the call is always raised by the
/// call (never later, at whatever Python line runs next). On Ctrl-C the observer asks the
/// library to stop, the call waits (up to [`CANCEL_WAIT`]) for the worker to return, and
/// `KeyboardInterrupt` is raised.
fn run_detached<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce(&dyn chatter_progress::Observer) -> T + Send + 'static,
) -> PyResult<T> {
    let observer = Arc::new(Interruptible::default());
    let worker_observer = Arc::clone(&observer);
    RUNNING_WORKERS.fetch_add(1, Ordering::SeqCst);
    let handle = std::thread::spawn(move || {
        let result = work(&*worker_observer);
        if worker_observer.seen.load(Ordering::Relaxed) {
            CANCELS_SEEN.fetch_add(1, Ordering::SeqCst);
        }
        RUNNING_WORKERS.fetch_sub(1, Ordering::SeqCst);
        result
    });
    loop {
        let finished = handle.is_finished();
        if let Err(e) = py.check_signals() {
            observer.cancel.store(true, Ordering::Relaxed);
            py.detach(|| {
                let start = Instant::now();
                while !handle.is_finished() && start.elapsed() < CANCEL_WAIT {
                    std::thread::sleep(Duration::from_millis(5));
                }
            });
            return Err(if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                e
            } else {
                PyKeyboardInterrupt::new_err("interrupted")
            });
        }
        if finished {
            return handle
                .join()
                .map_err(|_| PyRuntimeError::new_err("the chatter worker thread panicked"));
        }
        py.detach(|| std::thread::sleep(SIGNAL_CHECK));
    }
}

/// What the interruption tests observe: `running_workers` (worker threads of calls still
/// running; an interrupted call's until its library returns), `observer_polls` (polls of the
/// cancellation by the libraries so far) and `cancels_seen` (calls whose library stopped on a
/// cancel).
#[pyfunction]
fn _interruption_counters(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("running_workers", RUNNING_WORKERS.load(Ordering::SeqCst))?;
    d.set_item("observer_polls", OBSERVER_POLLS.load(Ordering::SeqCst))?;
    d.set_item("cancels_seen", CANCELS_SEEN.load(Ordering::SeqCst))?;
    Ok(d)
}

/// JSON text of a Python object (a dict) through the `json` module.
fn json_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    obj.py()
        .import("json")?
        .call_method1("dumps", (obj,))?
        .extract()
}

/// A Python object from JSON text.
fn from_json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A Python object from a serializable value.
fn to_py<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    from_json(py, &serde_json::to_string(value).map_err(value_error)?)
}

/// A model from a dict (model-file JSON) or a path.
fn model_of(obj: &Bound<'_, PyAny>) -> PyResult<ModalModel> {
    let m = if obj.is_instance_of::<PyDict>() {
        ModalModel::from_json_str(&json_text(obj)?, Path::new("<model dict>"))
    } else {
        ModalModel::from_path(obj.extract::<PathBuf>()?)
    };
    m.map_err(|e| value_error(format!("reading the model: {e}")))
}

/// Observations from a dict (observations JSON) or a path (JSON or cuts CSV).
fn observations_of(obj: &Bound<'_, PyAny>) -> PyResult<Observations> {
    let o = if obj.is_instance_of::<PyDict>() {
        Observations::from_json_str(&json_text(obj)?, Path::new("<observations dict>"))
    } else {
        Observations::from_path(obj.extract::<PathBuf>()?)
    };
    o.map_err(|e| value_error(format!("reading the observations: {e}")))
}

fn method_of(name: &str) -> PyResult<Method> {
    match name {
        "zoa" => Ok(Method::Zoa),
        "fdm" => Ok(Method::Fdm),
        "sdm" => Ok(Method::Sdm),
        other => Err(value_error(format!(
            "method {other:?}: expected \"zoa\", \"fdm\" or \"sdm\""
        ))),
    }
}

/// An optional array as a request field (`None`: the request's default).
fn vec_of(values: Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Option<Vec<f64>>> {
    Ok(values
        .map(|s| s.as_slice().map(<[f64]>::to_vec))
        .transpose()?)
}

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    v.into_pyarray(py)
}

fn matrix<'py>(
    py: Python<'py>,
    rows: &[Vec<f64>],
    columns: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if rows.is_empty() {
        return Ok(numpy::ndarray::Array2::<f64>::zeros((0, columns)).into_pyarray(py));
    }
    PyArray2::from_vec2(py, rows).map_err(value_error)
}

/// The optional cells of a column as floats with NaN for the missing ones.
fn column(values: impl Iterator<Item = Option<f64>>) -> Vec<f64> {
    values.map(|v| v.unwrap_or(f64::NAN)).collect()
}

/// Read and validate a model; return it as a model-file dict (units in every key).
#[pyfunction]
fn load_model<'py>(py: Python<'py>, model: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let m = model_of(model)?;
    to_py(py, &ModelFile::from_model(&m))
}

/// Read and validate observations; return them as an observations dict.
#[pyfunction]
fn load_observations<'py>(
    py: Python<'py>,
    observations: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    from_json(py, &observations_of(observations)?.to_json_string())
}

/// Validate a model and (optionally) observations; a summary dict.
#[pyfunction]
#[pyo3(signature = (model, observations=None))]
fn validate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    observations: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model_of(model)?;
    let d = PyDict::new(py);
    d.set_item(
        "operation",
        match m.operation() {
            chatter_dynamics::Operation::Milling(_) => "milling",
            chatter_dynamics::Operation::Turning(_) => "turning",
        },
    )?;
    d.set_item("modes", m.mode_count())?;
    if let Some(o) = observations {
        let o = observations_of(o)?;
        d.set_item("cuts", o.cuts.len())?;
        d.set_item("poles", o.poles.len())?;
        d.set_item("signals", o.signals.len())?;
    }
    Ok(d)
}

/// Limiting depth per speed (the `chatter lobes` numbers).
#[pyfunction]
#[pyo3(signature = (model, speeds_rpm=None, method="fdm"))]
fn lobes<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    speeds_rpm: Option<PyReadonlyArray1<'py, f64>>,
    method: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let dynamics = Dynamics::Modal(model_of(model)?);
    let request = LobesRequest {
        method: method_of(method)?,
        speeds_rpm: vec_of(speeds_rpm)?,
        ..LobesRequest::default()
    };
    let points = run_detached(py, move |observer| {
        Lobes::new(&dynamics, request)?.lobes(observer)
    })?
    .map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item(
        "speed_rpm",
        array(py, points.iter().map(|p| p.speed_rpm).collect()),
    )?;
    d.set_item(
        "depth_mm",
        array(py, points.iter().map(|p| p.depth_mm()).collect()),
    )?;
    d.set_item(
        "chatter_hz",
        array(py, points.iter().map(|p| p.chatter_hz).collect()),
    )?;
    Ok(d)
}

/// The dominant Floquet multiplier at one cut (the `chatter multiplier` numbers).
#[pyfunction]
#[pyo3(signature = (model, speed_rpm, depth_mm, method="fdm", ssv_amplitude_ratio=None, ssv_frequency_ratio=None))]
fn multiplier<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    speed_rpm: f64,
    depth_mm: f64,
    method: &str,
    ssv_amplitude_ratio: Option<f64>,
    ssv_frequency_ratio: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model_of(model)?;
    let variation =
        match (ssv_amplitude_ratio, ssv_frequency_ratio) {
            (None, None) => None,
            (Some(a), Some(r)) => Some(chatter_stability::ssv::SpeedVariation::new(a, r).map_err(
                |e| value_error(format!("ssv_amplitude_ratio, ssv_frequency_ratio: {e}")),
            )?),
            _ => {
                return Err(value_error(
                    "ssv_amplitude_ratio and ssv_frequency_ratio go together",
                ));
            }
        };
    let request = MultiplierRequest {
        speed_rpm,
        depth_mm,
        method: method_of(method)?,
        variation,
    };
    let out =
        run_detached(py, move |_| Multiplier::new(&m, request)?.run())?.map_err(value_error)?;
    let mu = &out.multiplier;
    let d = PyDict::new(py);
    d.set_item("speed_rpm", speed_rpm)?;
    d.set_item("depth_mm", depth_mm)?;
    d.set_item("method", out.method)?;
    d.set_item("modulus", mu.modulus())?;
    d.set_item("real", mu.value.re)?;
    d.set_item("imag", mu.value.im)?;
    match (variation, out.chatter_hz) {
        (Some(v), _) => {
            d.set_item("ssv_amplitude_ratio", v.amplitude_ratio())?;
            d.set_item("ssv_frequency_ratio", v.frequency_ratio())?;
            d.set_item("period_s", mu.period_s)?;
        }
        (None, chatter_hz) => {
            d.set_item("frequency_hz", mu.principal_frequency_hz())?;
            d.set_item("chatter_hz", chatter_hz)?;
            d.set_item("kind", to_py(py, &mu.kind())?)?;
        }
    }
    d.set_item("stable", out.stable)?;
    Ok(d)
}

/// d mu / d theta of the dominant pole at one cut (000 Table 3; the `chatter sensitivity` job,
/// `chatter_jobs::sensitivity`), as the dict of the CLI's JSON.
#[pyfunction]
#[pyo3(signature = (model, speed_rpm, depth_mm, parameters=None, steps_per_revolution=None, map="one-step"))]
fn sensitivity<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    speed_rpm: f64,
    depth_mm: f64,
    parameters: Option<Vec<String>>,
    steps_per_revolution: Option<usize>,
    map: &str,
) -> PyResult<Bound<'py, PyAny>> {
    use chatter_jobs::sensitivity::{Sensitivity, SensitivityRequest, transition_map};
    let m = model_of(model)?;
    let defaults = SensitivityRequest::new(speed_rpm, depth_mm);
    let request = SensitivityRequest {
        parameters,
        steps_per_revolution: steps_per_revolution.unwrap_or(defaults.steps_per_revolution),
        map: transition_map(map).map_err(value_error)?,
        ..defaults
    };
    let out =
        run_detached(py, move |_| Sensitivity::new(&m, &request)?.run())?.map_err(value_error)?;
    from_json(py, &out.to_json().to_string())
}

/// The tool-tip FRF of a tool-holder-spindle assembly file by receptance coupling (004 Eq. 1-4;
/// the `chatter rcsa` job, `chatter_jobs::rcsa`): `frequency_hz`, `real`, `imag` (m/N).
#[pyfunction]
fn rcsa<'py>(py: Python<'py>, assembly: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    use chatter_jobs::rcsa::{RcsaRequest, rcsa as couple};
    let out = run_detached(py, move |_| couple(&RcsaRequest::from_path(&assembly)?))?
        .map_err(value_error)?;
    let tip = &out.tool_tip;
    let d = PyDict::new(py);
    d.set_item("frequency_hz", array(py, tip.frequencies_hz().to_vec()))?;
    d.set_item(
        "real",
        array(py, tip.receptance_m_per_n().iter().map(|g| g.re).collect()),
    )?;
    d.set_item(
        "imag",
        array(py, tip.receptance_m_per_n().iter().map(|g| g.im).collect()),
    )?;
    Ok(d)
}

/// A band job's outcome on a modal model, checked and run on a worker thread.
fn run_bands(
    py: Python<'_>,
    model: ModalModel,
    distribution: Option<ParameterDistribution>,
    request: BandsRequest,
) -> PyResult<BandsOutcome> {
    let dynamics = Dynamics::Modal(model);
    run_detached(py, move |observer| {
        Bands::new(&dynamics, distribution.as_ref(), request)?.run(observer)
    })?
    .map_err(value_error)
}

/// Type B offset boundaries (001) around the lobes of `method` (the `chatter bands --kind
/// geometric` numbers; NaN where an offset curve does not cover a speed).
#[pyfunction]
#[pyo3(signature = (model, speeds_rpm=None, offset_rpm=None, offset_mm=None, method="zoa"))]
fn bands_geometric<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    speeds_rpm: Option<PyReadonlyArray1<'py, f64>>,
    offset_rpm: Option<f64>,
    offset_mm: Option<f64>,
    method: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let request = BandsRequest {
        method: Some(method_of(method)?),
        speeds_rpm: vec_of(speeds_rpm)?,
        offset_rpm,
        offset_mm,
        ..BandsRequest::new(BandKind::Geometric)
    };
    let BandsOutcome::Geometric { bands: b, .. } = run_bands(py, model_of(model)?, None, request)?
    else {
        return Err(value_error("geometric bands gave another kind"));
    };
    let depth_at = chatter_uncertainty::geometric::OffsetBoundaries::depth_at;
    let d = PyDict::new(py);
    d.set_item(
        "speed_rpm",
        array(py, b.points.iter().map(|p| p.speed_rpm).collect()),
    )?;
    d.set_item(
        "depth_mm",
        array(py, b.points.iter().map(|p| p.depth_mm).collect()),
    )?;
    d.set_item(
        "lower_mm",
        array(
            py,
            column(b.points.iter().map(|p| depth_at(&b.lower, p.speed_rpm))),
        ),
    )?;
    d.set_item(
        "upper_mm",
        array(
            py,
            column(b.points.iter().map(|p| depth_at(&b.upper, p.speed_rpm))),
        ),
    )?;
    d.set_item(
        "theta_deg",
        array(py, b.points.iter().map(|p| p.theta_deg).collect()),
    )?;
    d.set_item(
        "distance",
        array(py, b.points.iter().map(|p| p.distance).collect()),
    )?;
    Ok(d)
}

/// A parameter distribution: a dict `{"parameter_names", "covariance", "mean"}` (mean
/// optional), an update result (its `parameter_names`, `posterior_mean`,
/// `posterior_covariance`, `samples`), a posterior folder of `chatter update` or a covariance
/// file.
fn distribution_of(obj: &Bound<'_, PyAny>) -> PyResult<ParameterDistribution> {
    if let Ok(d) = obj.cast::<PyDict>() {
        let names: Vec<String> = d
            .get_item("parameter_names")?
            .ok_or_else(|| value_error("distribution: `parameter_names` is missing"))?
            .extract()?;
        let posterior = d.contains("posterior_covariance")?;
        let (mean_key, cov_key) = if posterior {
            ("posterior_mean", "posterior_covariance")
        } else {
            ("mean", "covariance")
        };
        let covariance: Vec<Vec<f64>> = match d.get_item(cov_key)? {
            Some(c) => c
                .call_method0("tolist")
                .or_else(|_| Ok::<_, PyErr>(c))?
                .extract()?,
            None => return Err(value_error(format!("distribution: `{cov_key}` is missing"))),
        };
        let mean: Vec<f64> = match d.get_item(mean_key)? {
            Some(v) => v
                .call_method0("tolist")
                .or_else(|_| Ok::<_, PyErr>(v))?
                .extract()?,
            None => vec![0.0; names.len()],
        };
        let samples: Option<Vec<Vec<f64>>> = match d.get_item("samples")? {
            Some(s) if posterior => Some(s.call_method0("tolist")?.extract()?),
            _ => None,
        };
        return ParameterDistribution::new(&names, mean, covariance, samples, Path::new("<dict>"))
            .map_err(value_error);
    }
    let path: PathBuf = obj.extract()?;
    if path.is_dir() {
        ParameterDistribution::from_posterior_dir(&path)
    } else {
        ParameterDistribution::from_covariance_file(&path)
    }
    .map_err(value_error)
}

/// Second-order credibility bounds (000 Eq. 14-18) at the distribution's mean (the `chatter
/// bands --kind perturbation` numbers; NaN where a contour is not reached on the grid).
#[pyfunction]
#[pyo3(signature = (model, distribution, speeds_rpm=None, depths_mm=None, method="fdm", coverage=None))]
fn bands_perturbation<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    distribution: &Bound<'py, PyAny>,
    speeds_rpm: Option<PyReadonlyArray1<'py, f64>>,
    depths_mm: Option<PyReadonlyArray1<'py, f64>>,
    method: &str,
    coverage: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = BandsRequest {
        method: Some(method_of(method)?),
        speeds_rpm: vec_of(speeds_rpm)?,
        depths_mm: vec_of(depths_mm)?,
        coverage,
        ..BandsRequest::new(BandKind::Perturbation)
    };
    let dist = distribution_of(distribution)?;
    let BandsOutcome::Perturbation { bands: p, .. } =
        run_bands(py, model_of(model)?, Some(dist), request)?
    else {
        return Err(value_error("perturbation bands gave another kind"));
    };
    let d = PyDict::new(py);
    d.set_item(
        "speed_rpm",
        array(py, p.bounds.iter().map(|b| b.speed_rpm).collect()),
    )?;
    d.set_item(
        "depth_mm",
        array(py, column(p.bounds.iter().map(|b| b.depth_mm))),
    )?;
    d.set_item(
        "lower_mm",
        array(py, column(p.bounds.iter().map(|b| b.lower_mm))),
    )?;
    d.set_item(
        "upper_mm",
        array(py, column(p.bounds.iter().map(|b| b.upper_mm))),
    )?;
    d.set_item("depth_grid_mm", array(py, p.depths_mm))?;
    Ok(d)
}

/// Monte Carlo boundaries (004; the `chatter bands --kind montecarlo` numbers): limiting-depth
/// and chatter-frequency quantiles per speed, the per-draw limits and the probability-of-
/// stability map on `map_depths_mm` (default 0 to 1.5 times the deepest 95 % quantile).
#[pyfunction]
#[pyo3(signature = (model, distribution, speeds_rpm=None, samples=None, seed=None, method="fdm", map_depths_mm=None))]
#[allow(clippy::too_many_arguments)]
fn bands_montecarlo<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    distribution: &Bound<'py, PyAny>,
    speeds_rpm: Option<PyReadonlyArray1<'py, f64>>,
    samples: Option<usize>,
    seed: Option<u64>,
    method: &str,
    map_depths_mm: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = BandsRequest {
        method: Some(method_of(method)?),
        speeds_rpm: vec_of(speeds_rpm)?,
        depths_mm: vec_of(map_depths_mm)?,
        samples,
        seed,
        map: true,
        ..BandsRequest::new(BandKind::MonteCarlo)
    };
    let dist = distribution_of(distribution)?;
    let BandsOutcome::MonteCarlo {
        bands: mc,
        map: Some(map),
    } = run_bands(py, model_of(model)?, Some(dist), request)?
    else {
        return Err(value_error("Monte Carlo bands gave no map"));
    };
    let d = PyDict::new(py);
    d.set_item(
        "speed_rpm",
        array(py, mc.depth.iter().map(|q| q.speed_rpm).collect()),
    )?;
    d.set_item(
        "depth_mm",
        array(py, mc.depth.iter().map(|q| q.q50).collect()),
    )?;
    d.set_item(
        "lower_mm",
        array(py, mc.depth.iter().map(|q| q.q05).collect()),
    )?;
    d.set_item(
        "upper_mm",
        array(py, mc.depth.iter().map(|q| q.q95).collect()),
    )?;
    d.set_item(
        "chatter_hz_q05",
        array(py, mc.chatter_hz.iter().map(|q| q.q05).collect()),
    )?;
    d.set_item(
        "chatter_hz_q50",
        array(py, mc.chatter_hz.iter().map(|q| q.q50).collect()),
    )?;
    d.set_item(
        "chatter_hz_q95",
        array(py, mc.chatter_hz.iter().map(|q| q.q95).collect()),
    )?;
    d.set_item(
        "limits_mm",
        matrix(py, &mc.sampled.limits_mm, mc.depth.len())?,
    )?;
    d.set_item("failures", mc.sampled.failures.len())?;
    d.set_item("map_depth_mm", array(py, map.depths_mm))?;
    d.set_item("p_stable", matrix(py, &map.p_stable, 0)?)?;
    Ok(d)
}

/// Time-domain regenerative cut with loss of contact (the `chatter simulate` signals): `data`
/// has one row per channel (the two coordinates, then `once_per_rev`) in m, m/s or m/s^2.
#[pyfunction]
#[pyo3(signature = (model, speed_rpm, depth_mm, duration_s, sample_rate_hz, seed, quantity="acceleration", random_force_n=1.0, harmonic_force_n=0.0, feed_per_tooth_mm=0.05))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    speed_rpm: f64,
    depth_mm: f64,
    duration_s: f64,
    sample_rate_hz: f64,
    seed: u64,
    quantity: &str,
    random_force_n: f64,
    harmonic_force_n: f64,
    feed_per_tooth_mm: f64,
) -> PyResult<Bound<'py, PyDict>> {
    use chatter_dynamics::simulate::Quantity;
    use chatter_jobs::simulate::SimulateRequest;
    let m = model_of(model)?;
    let request = SimulateRequest {
        quantity: match quantity {
            "acceleration" => Quantity::Acceleration,
            "velocity" => Quantity::Velocity,
            "displacement" => Quantity::Displacement,
            other => {
                return Err(value_error(format!(
                    "quantity {other:?}: expected \"acceleration\", \"velocity\" or \"displacement\""
                )));
            }
        },
        random_force_n,
        harmonic_force_n,
        feed_per_tooth_mm,
        ..SimulateRequest::new(speed_rpm, depth_mm, duration_s, sample_rate_hz, seed)
    };
    let s = request.check().map_err(value_error)?;
    let sim = run_detached(py, move |observer| {
        chatter_jobs::simulate::simulate(&m, &s, observer)
    })?
    .map_err(value_error)?;
    let names: Vec<String> = sim.channels.iter().map(|c| c.name.clone()).collect();
    let rows: Vec<Vec<f64>> = sim.channels.into_iter().map(|c| c.data).collect();
    let d = PyDict::new(py);
    d.set_item("names", names)?;
    d.set_item("data", matrix(py, &rows, 0)?)?;
    d.set_item("sample_rate_hz", sim.sample_rate_hz)?;
    d.set_item("lost_contact_fraction", sim.lost_contact_fraction)?;
    Ok(d)
}

fn signals_of(
    data: PyReadonlyArray2<'_, f64>,
    sample_rate_hz: f64,
    names: Option<Vec<String>>,
) -> PyResult<chatter_oma::signals::Signals> {
    let a = data.as_array();
    let rows: Vec<Vec<f64>> = a.outer_iter().map(|r| r.to_vec()).collect();
    let names = names.unwrap_or_else(|| (0..rows.len()).map(|i| format!("ch{i}")).collect());
    chatter_oma::signals::Signals::new(names, sample_rate_hz, rows).map_err(value_error)
}

/// Stable or chatter for one record (`data`: one row per channel, `sample_rate_hz` in Hz,
/// `speed_rpm` the spindle speed): the `chatter detect` criterion.
#[pyfunction]
#[pyo3(signature = (data, sample_rate_hz, speed_rpm, names=None, once_per_rev_channel=None))]
fn detect<'py>(
    py: Python<'py>,
    data: PyReadonlyArray2<'py, f64>,
    sample_rate_hz: f64,
    speed_rpm: f64,
    names: Option<Vec<String>>,
    once_per_rev_channel: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    use chatter_jobs::detect::{DetectRequest, detect_signals, is_stable};
    let signals = signals_of(data, sample_rate_hz, names)?;
    let det = run_detached(py, move |observer| {
        detect_signals(
            &signals,
            speed_rpm,
            once_per_rev_channel,
            None,
            &DetectRequest::default(),
            observer,
        )
    })?
    .map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("stable", is_stable(&det))?;
    d.set_item("chatter_hz", det.chatter_hz)?;
    d.set_item("evidence", to_py(py, &det.evidence)?)?;
    Ok(d)
}

/// Operational modal analysis of one stable record: the dominant pole by LSCE with the spindle
/// harmonics imposed (when `speed_rpm` is given) over repeated random segments.
#[pyfunction]
#[pyo3(signature = (data, sample_rate_hz, speed_rpm=None, names=None, seed=0))]
fn oma<'py>(
    py: Python<'py>,
    data: PyReadonlyArray2<'py, f64>,
    sample_rate_hz: f64,
    speed_rpm: Option<f64>,
    names: Option<Vec<String>>,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let signals = signals_of(data, sample_rate_hz, names)?;
    let mut options = chatter_oma::IdentifyOptions {
        seed,
        ..Default::default()
    };
    if let Some(s) = speed_rpm {
        options.harmonics = chatter_oma::Harmonics::Spindle {
            fundamental_hz: s / 60.0,
        };
    }
    let id = run_detached(py, move |observer| {
        chatter_oma::identify_with_observer(&signals, &options, observer)
    })?
    .map_err(value_error)?;
    let e = &id.estimate;
    let d = PyDict::new(py);
    d.set_item("frequency_hz", e.frequency_hz)?;
    d.set_item("frequency_std_hz", e.frequency_std_hz)?;
    d.set_item("damping_ratio", e.damping_ratio)?;
    d.set_item("damping_std", e.damping_std)?;
    d.set_item("repetitions", e.repetitions)?;
    d.set_item("order", id.order)?;
    Ok(d)
}

/// Operational modal analysis of every signal record of an observations file or dict (the
/// `chatter oma --observations FILE` job, `chatter_jobs::oma`): each record is checked by chatter
/// detection (a chattering record is refused unless `allow_chatter`), then its dominant pole is
/// identified (modified LSCE with the spindle harmonics; lifted polyreference at the tooth period
/// with a milling `model`). Returns ``observations`` (the command's JSON: the input's cuts and
/// one pole per record) and numpy arrays over the records: ``speed_rpm``, ``frequency_hz``,
/// ``damping_ratio``, ``frequency_std_hz``, ``damping_std`` (NaN where not estimated).
/// `harmonics_hz`: None for the spindle lines, [] for none, else the lines to impose (Hz);
/// `interference_hz`: None to search a mains comb, [] for none, else the fundamentals (Hz).
#[pyfunction]
#[pyo3(signature = (observations, model=None, min_order=None, max_order=None, segments=None,
    harmonics_hz=None, decimation=None, interference_hz=None, allow_chatter=false))]
#[allow(clippy::too_many_arguments)]
fn oma_observations<'py>(
    py: Python<'py>,
    observations: &Bound<'py, PyAny>,
    model: Option<&Bound<'py, PyAny>>,
    min_order: Option<usize>,
    max_order: Option<usize>,
    segments: Option<usize>,
    harmonics_hz: Option<Vec<f64>>,
    decimation: Option<usize>,
    interference_hz: Option<Vec<f64>>,
    allow_chatter: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use chatter_oma::interference::Interference;
    let o = observations_of(observations)?;
    let m = model.map(model_of).transpose()?;
    let request = chatter_jobs::oma::OmaRequest {
        min_order,
        max_order,
        segments,
        harmonics: harmonics_hz.map(|h| {
            if h.is_empty() {
                chatter_oma::Harmonics::None
            } else {
                chatter_oma::Harmonics::Known(h)
            }
        }),
        decimation,
        interference: match interference_hz {
            None => Interference::default(),
            Some(f) if f.is_empty() => Interference::Off,
            Some(f) => Interference::Known(f),
        },
        allow_chatter,
    };
    let (result, _) = run_detached(py, move |observer| {
        chatter_jobs::oma::identify_observations(&o, m.as_ref(), &request, observer)
    })?
    .map_err(value_error)?;
    let poles = &result.poles;
    let d = PyDict::new(py);
    d.set_item("observations", from_json(py, &result.to_json_string())?)?;
    d.set_item(
        "speed_rpm",
        array(py, poles.iter().map(|p| p.speed_rpm).collect()),
    )?;
    d.set_item(
        "frequency_hz",
        array(py, poles.iter().map(|p| p.frequency_hz).collect()),
    )?;
    d.set_item(
        "damping_ratio",
        array(py, poles.iter().map(|p| p.damping_ratio).collect()),
    )?;
    d.set_item(
        "frequency_std_hz",
        array(py, column(poles.iter().map(|p| p.frequency_std_hz))),
    )?;
    d.set_item(
        "damping_std",
        array(py, column(poles.iter().map(|p| p.damping_std))),
    )?;
    Ok(d)
}

/// Priors from a dict or a path (the `--priors` file of `chatter update` and `chatter plan`):
/// marginals by name, or one correlated normal `{"parameter_names", "mean", "covariance"}` (004's
/// RCSA prior), read by the same function as the command line's
/// ([`chatter_updating::joint_prior::PriorFile::from_json_str`]).
fn priors_of(
    priors: Option<&Bound<'_, PyAny>>,
) -> PyResult<(
    chatter_updating::update::PriorOverrides,
    Option<chatter_updating::joint_prior::JointNormal>,
)> {
    use chatter_updating::joint_prior::PriorFile;
    let Some(p) = priors else {
        return Ok(Default::default());
    };
    let (text, source) = if p.is_instance_of::<PyDict>() {
        (json_text(p)?, "<priors dict>".to_string())
    } else {
        let path: PathBuf = p.extract()?;
        let text = std::fs::read_to_string(&path)
            .map_err(|e| value_error(format!("priors: reading {}: {e}", path.display())))?;
        (text, path.display().to_string())
    };
    match PriorFile::from_json_str(&text).map_err(|e| {
        value_error(format!(
            "priors: {source}: {e} (expected marginals by name, or \
             {{\"parameter_names\", \"mean\", \"covariance\"}})"
        ))
    })? {
        PriorFile::Marginals(m) => Ok((m, None)),
        PriorFile::Joint(j) => Ok((Default::default(), Some(j))),
    }
}

/// The stability method of a cut likelihood or of sampled boundaries; `None`: the default.
fn optional_method(method: Option<&str>) -> PyResult<Option<Method>> {
    method.map(method_of).transpose()
}

fn parameters_of(
    parameters: Option<Vec<String>>,
) -> PyResult<Option<Vec<chatter_updating::parameters::ModelParameter>>> {
    parameters
        .map(|p| {
            chatter_updating::parameters::parse_model_parameters(&p.join(",")).map_err(value_error)
        })
        .transpose()
}

/// Bayesian updating (the `chatter update` job): posterior samples of the selected class
/// (`samples`, one row per draw, columns `parameter_names`), their `weights`, the
/// classes with `log_evidence` (nats), `prior_draws` and, with `pointwise`, the log-likelihood
/// of every observation at every sample (`log_likelihood`, nats), for ArviZ. `priors` as the
/// `--priors` file (a dict or a path): marginals by name, or one correlated normal
/// `{"parameter_names", "mean", "covariance"}` whose names are then the updated parameters
/// unless `parameters` is given; `method` the stability method of a cut likelihood ("fdm",
/// "sdm" or "zoa"; cut results only).
#[pyfunction]
#[pyo3(signature = (model, observations, seed, sampler="itmcmc", samples=5000, parameters=None, priors=None, classes=None, surrogate="gp", surrogate_points=chatter_updating::surrogate::DEFAULT_TRAINING_POINTS, pointwise=true, method=None))]
#[allow(clippy::too_many_arguments)]
fn update<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    observations: &Bound<'py, PyAny>,
    seed: u64,
    sampler: &str,
    samples: usize,
    parameters: Option<Vec<String>>,
    priors: Option<&Bound<'py, PyAny>>,
    classes: Option<Vec<f64>>,
    surrogate: &str,
    surrogate_points: usize,
    pointwise: bool,
    method: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    use chatter_updating::classes::Sampler;
    let m = model_of(model)?;
    let o = observations_of(observations)?;
    let mut request = chatter_jobs::update::UpdateRequest::new(seed);
    request.sampler = match sampler {
        "itmcmc" => Sampler::Itmcmc,
        "tmcmc" => Sampler::Tmcmc,
        "amcmc" => Sampler::Amcmc,
        other => {
            return Err(value_error(format!(
                "sampler {other:?}: expected \"itmcmc\", \"tmcmc\" or \"amcmc\""
            )));
        }
    };
    request.samples = samples;
    request.parameters = parameters_of(parameters)?;
    (request.priors, request.joint_prior) = priors_of(priors)?;
    request.method = optional_method(method)?;
    request.classes = classes;
    request.surrogate_points = match surrogate {
        "gp" => Some(surrogate_points),
        "exact" => None,
        other => {
            return Err(value_error(format!(
                "surrogate {other:?}: expected \"gp\" or \"exact\""
            )));
        }
    };
    let prepared =
        chatter_jobs::update::PreparedUpdate::new(&m, &o, request).map_err(value_error)?;
    let (outcome, pointwise) = run_detached(py, move |observer| {
        let outcome = prepared.run(observer)?;
        let pointwise = if pointwise {
            let r = &outcome.result;
            Some(
                prepared
                    .job()
                    .pointwise_log_likelihood(r.selected_alpha, r.samples.samples())?,
            )
        } else {
            None
        };
        Ok::<_, chatter_jobs::JobError>((outcome, pointwise))
    })?
    .map_err(value_error)?;
    let r = &outcome.result;
    let dim = r.parameter_names.len();
    let d = PyDict::new(py);
    d.set_item("parameter_names", r.parameter_names.clone())?;
    d.set_item("samples", matrix(py, r.samples.samples(), dim)?)?;
    d.set_item("weights", array(py, r.samples.weights().to_vec()))?;
    d.set_item("posterior_mean", array(py, r.posterior_mean.clone()))?;
    let cov: Vec<Vec<f64>> = (0..dim)
        .map(|i| (0..dim).map(|j| r.posterior_covariance[(i, j)]).collect())
        .collect();
    d.set_item("posterior_covariance", matrix(py, &cov, dim)?)?;
    d.set_item("classes", to_py(py, &r.classes)?)?;
    d.set_item("selected_alpha", r.selected_alpha)?;
    d.set_item("prior_bound_pileups", to_py(py, &r.prior_bound_pileups)?)?;
    d.set_item("warnings", chatter_jobs::update::warnings(r))?;
    d.set_item("surrogate", to_py(py, &r.surrogate)?)?;
    d.set_item("pole_table", to_py(py, &r.pole_table)?)?;
    d.set_item(
        "updated_model",
        to_py(py, &ModelFile::from_model(&r.updated_model))?,
    )?;
    d.set_item("prior_draws", matrix(py, &outcome.prior_draws, dim)?)?;
    if let Some(p) = pointwise {
        let n = p.first().map_or(0, Vec::len);
        d.set_item("log_likelihood", matrix(py, &p, n)?)?;
    }
    Ok(d)
}

/// The next test cut (the `chatter plan` job): `strategy` "voi" (003) or "mrr" (004); speeds
/// in rpm, depths and feed in mm; `priors` as in [`update`]; `method` the stability method of
/// the sampled boundaries ("fdm", the default, "sdm" or "zoa").
#[pyfunction]
#[pyo3(signature = (model, observations, strategy="mrr", p_test=0.5, parameters=None, priors=None, target=None, paths=300, speeds_rpm=None, depths_mm=None, feed_per_tooth_mm=0.1, seed=0, max_tests=chatter_updating::plan::DEFAULT_MAX_TESTS, method=None))]
#[allow(clippy::too_many_arguments)]
fn plan<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    observations: &Bound<'py, PyAny>,
    strategy: &str,
    p_test: f64,
    parameters: Option<Vec<String>>,
    priors: Option<&Bound<'py, PyAny>>,
    target: Option<String>,
    paths: usize,
    speeds_rpm: Option<PyReadonlyArray1<'py, f64>>,
    depths_mm: Option<PyReadonlyArray1<'py, f64>>,
    feed_per_tooth_mm: f64,
    seed: u64,
    max_tests: usize,
    method: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    use chatter_updating::plan::Strategy;
    let m = model_of(model)?;
    let o = observations_of(observations)?;
    let mut request = chatter_jobs::plan::PlanRequest::new(match strategy {
        "voi" => Strategy::ValueOfInformation,
        "mrr" => Strategy::MaterialRemovalRate,
        other => {
            return Err(value_error(format!(
                "strategy {other:?}: expected \"voi\" or \"mrr\""
            )));
        }
    });
    request.p_test = p_test;
    request.parameters = parameters_of(parameters)?;
    (request.priors, request.joint_prior) = priors_of(priors)?;
    request.method = optional_method(method)?;
    request.target = target.map(|t| t.parse().map_err(value_error)).transpose()?;
    request.paths = paths;
    request.speeds_rpm = vec_of(speeds_rpm)?;
    request.depths_mm = vec_of(depths_mm)?;
    request.feed_per_tooth_mm = feed_per_tooth_mm;
    request.seed = seed;
    request.max_tests = max_tests;
    let (outcome, warnings) = run_detached(py, move |observer| {
        chatter_jobs::plan::plan(&m, &o, &request, observer).map(|outcome| {
            let warnings = chatter_jobs::plan::warnings(&outcome, &request);
            (outcome, warnings)
        })
    })?
    .map_err(value_error)?;
    let mut json = serde_json::to_value(&outcome).map_err(value_error)?;
    if let Some(map) = json.as_object_mut() {
        map.insert("strategy".into(), strategy.into());
        map.insert("warnings".into(), warnings.into());
    }
    to_py(py, &json)
}

fn validation_of(validation: &str, folds: usize) -> PyResult<chatter_gap::Validation> {
    use chatter_gap::Validation;
    match validation {
        "kfold" => Ok(Validation::KFold { folds }),
        "speed-bands" | "speed_bands" => Ok(Validation::SpeedBands { bands: folds }),
        "off" => Ok(Validation::Off),
        other => Err(value_error(format!(
            "validation {other:?}: expected \"kfold\", \"speed-bands\" or \"off\""
        ))),
    }
}

/// Sim-to-real gap diagnosis (the `chatter diagnose` job): the full diagnosis as a dict
/// (`verdict`, `classes` with `log_evidence` in nats and fitted parameters, `regions`,
/// `residuals`, ...) plus `diagnosed_model`.
#[pyfunction]
#[pyo3(signature = (model, observations, seed, samples=120, validation="kfold", folds=3, pointwise=true))]
#[allow(clippy::too_many_arguments)]
fn diagnose<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    observations: &Bound<'py, PyAny>,
    seed: u64,
    samples: usize,
    validation: &str,
    folds: usize,
    pointwise: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let m = model_of(model)?;
    let o = observations_of(observations)?;
    let request = chatter_jobs::diagnose::DiagnoseRequest {
        seed,
        samples,
        validation: validation_of(validation, folds)?,
        pointwise,
    };
    let diagnosis = run_detached(py, move |observer| {
        chatter_jobs::diagnose::diagnose(&m, &o, &request, observer)
    })?
    .map_err(value_error)?;
    let out = to_py(py, &diagnosis)?;
    let classes = out.get_item("classes")?;
    for (i, c) in diagnosis.classes.iter().enumerate() {
        let entry = classes.get_item(i)?;
        entry.set_item(
            "posterior_parameter_names",
            c.posterior.parameter_names.clone(),
        )?;
        let width = c.posterior.parameter_names.len();
        entry.set_item(
            "posterior_samples",
            matrix(py, &c.posterior.samples, width)?,
        )?;
        if pointwise {
            entry.set_item("prior_draws", matrix(py, &c.posterior.prior_draws, width)?)?;
            let n = c.posterior.log_likelihood.first().map_or(0, Vec::len);
            entry.set_item(
                "log_likelihood",
                matrix(py, &c.posterior.log_likelihood, n)?,
            )?;
        }
    }
    out.set_item(
        "diagnosed_model",
        to_py(py, &ModelFile::from_model(diagnosis.diagnosed_model()))?,
    )?;
    Ok(out)
}

fn campaign_options(
    samples: usize,
    paths: usize,
    validation: &str,
    folds: usize,
) -> PyResult<CampaignOptions> {
    Ok(CampaignOptions {
        validation: validation_of(validation, folds)?,
        ..CampaignOptions::new(samples, paths).map_err(value_error)?
    })
}

/// The campaigns of a fleet manifest (`name,model,observations,seed`; paths made relative to
/// the current folder) as dicts.
#[pyfunction]
fn read_manifest<'py>(py: Python<'py>, manifest: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    to_py(
        py,
        &campaign::read_manifest(&manifest).map_err(value_error)?,
    )
}

/// One campaign reduced to its row of the batch table: `line` is the table line (bit-equal to
/// the `chatter batch` one), the other keys its cells (`boundary_shift_percent` in %, the next
/// cut's `next_speed_rpm`, `next_depth_mm`), `error` when it failed.
#[pyfunction]
#[pyo3(signature = (name, model, observations, seed, samples=chatter_jobs::diagnose::DEFAULT_SAMPLES, paths=300, validation="off", folds=3))]
#[allow(clippy::too_many_arguments)]
fn run_campaign<'py>(
    py: Python<'py>,
    name: String,
    model: PathBuf,
    observations: PathBuf,
    seed: u64,
    samples: usize,
    paths: usize,
    validation: &str,
    folds: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let options = campaign_options(samples, paths, validation, folds)?;
    let c = Campaign {
        name,
        model,
        observations,
        seed,
    };
    let result = run_detached(py, move |observer| {
        let row = campaign::run_campaign(&c, &options, observer);
        (c, row)
    })?;
    let d = PyDict::new(py);
    match result {
        (_, Ok(row)) => {
            d.set_item("line", row.csv_line())?;
            if let Ok(cells) = to_py(py, &row)?.cast_into::<PyDict>() {
                d.update(cells.as_mapping())?;
            }
        }
        (c, Err(e)) => {
            d.set_item("line", campaign::error_line(&c.name, &e.to_string()))?;
            d.set_item("name", c.name)?;
            d.set_item("error", e.to_string())?;
        }
    }
    Ok(d)
}

/// Every campaign of a manifest in parallel on this machine (rayon), the table text in
/// manifest order (what `chatter batch` writes).
#[pyfunction]
#[pyo3(signature = (manifest, samples=chatter_jobs::diagnose::DEFAULT_SAMPLES, paths=300, validation="off", folds=3))]
fn batch(
    py: Python<'_>,
    manifest: PathBuf,
    samples: usize,
    paths: usize,
    validation: &str,
    folds: usize,
) -> PyResult<String> {
    let options = campaign_options(samples, paths, validation, folds)?;
    let campaigns = campaign::read_manifest(&manifest).map_err(value_error)?;
    run_detached(py, move |observer| {
        campaign::run_batch(&campaigns, &options, observer).map(|b| b.table())
    })?
    .map_err(value_error)
}

/// The batch table of table lines in order (header first).
#[pyfunction]
fn campaign_table(lines: &Bound<'_, PyList>) -> PyResult<String> {
    let lines: Vec<String> = lines.extract()?;
    Ok(campaign::table(&lines))
}

/// A synthetic shop-floor campaign of the gap diagnosis's proving ground (the recipe of
/// `chatter_jobs::synthetic`, the one `chatter demo` uses): the nominal model and observations
/// of a machine with `effect` (an effect class name, or "none") at `magnitude` (1 = the
/// reference size of the class), `cuts` test cuts and poles at `pole_speeds` speeds spread over
/// the range (0: none; None: the default 3000, 6000, 9000 and 12 000 rpm), seeded. Returns
/// `(model, observations)` as dicts.
#[pyfunction]
#[pyo3(signature = (effect, magnitude, seed, cuts=32, pole_speeds=None))]
fn synthetic_campaign<'py>(
    py: Python<'py>,
    effect: &str,
    magnitude: f64,
    seed: u64,
    cuts: usize,
    pole_speeds: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    use chatter_jobs::synthetic::{SyntheticCampaignRequest, synthetic_campaign};
    let effect = match effect {
        "none" => None,
        name => Some(
            name.parse::<chatter_gap::EffectClass>()
                .map_err(value_error)?,
        ),
    };
    let request = SyntheticCampaignRequest {
        cuts,
        pole_speeds,
        ..SyntheticCampaignRequest::new(effect, magnitude, seed)
    };
    let (nominal, observations) = synthetic_campaign(&request).map_err(value_error)?;
    Ok((
        to_py(py, &ModelFile::from_model(&nominal))?,
        from_json(py, &observations.to_json_string())?,
    ))
}

/// The compiled part of the `chatter` package.
#[pymodule]
fn _chatter(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_model, m)?)?;
    m.add_function(wrap_pyfunction!(load_observations, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(lobes, m)?)?;
    m.add_function(wrap_pyfunction!(multiplier, m)?)?;
    m.add_function(wrap_pyfunction!(sensitivity, m)?)?;
    m.add_function(wrap_pyfunction!(rcsa, m)?)?;
    m.add_function(wrap_pyfunction!(bands_geometric, m)?)?;
    m.add_function(wrap_pyfunction!(bands_perturbation, m)?)?;
    m.add_function(wrap_pyfunction!(bands_montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(_interruption_counters, m)?)?;
    m.add_function(wrap_pyfunction!(oma_observations, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(detect, m)?)?;
    m.add_function(wrap_pyfunction!(oma, m)?)?;
    m.add_function(wrap_pyfunction!(update, m)?)?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(read_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(run_campaign, m)?)?;
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_table, m)?)?;
    m.add_function(wrap_pyfunction!(synthetic_campaign, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
