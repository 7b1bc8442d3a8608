//! The application: its state (database, data folder, running jobs, computed lobes), the HTTP
//! routes and the request guard.
//!
//! # Routes
//! `GET /` the page, `GET /assets/...` its script and style (embedded in the binary); the JSON
//! API under `/api`: setups (`GET`/`POST /api/setups`, `GET /api/setups/{id}`), the tap test
//! (`POST .../frf`, multipart), a model file (`POST .../model`), the lobes
//! (`GET .../lobes?max_depth_mm&risk`), the cut log (`POST .../cuts`, `POST .../recordings`,
//! `POST .../observations`, `POST /api/cuts/{id}/result`), learning (`POST .../learn`,
//! `GET /api/jobs/{id}`, `POST /api/jobs/{id}/cancel`, `POST .../adopt`) and the exports
//! (`GET .../export/{model.json, observations.json, diagnosis.json}`).
//!
//! # Guard
//! Every request's `Host` must name this server when it listens on a loopback address (a page
//! of another site cannot reach it by rebinding a name of its own to 127.0.0.1), and every
//! state-changing request (not `GET`/`HEAD`) must come from this server's own page: an `Origin`
//! header, when present, must be `http://` and the `Host`, and without one `Sec-Fetch-Site`, when
//! present, must say `same-origin` or `none`. Bodies are limited to the largest upload
//! ([`crate::store::MAX_UPLOAD_BYTES`]) and a little more for the form's other fields.

use crate::db::{Db, NewCut, StoredFile};
use crate::error::{Result, ServeError};
use crate::store::{DataDir, Upload, UploadKind, check};
use crate::work::{self, FitRequest, LearnRequest, LobeRequest, RecordingRequest, TapDirections};
use axum::Json;
use axum::Router;
use axum::extract::{DefaultBodyLimit, Multipart, Path, Query, Request, State};
use axum::http::{HeaderMap, Method, header};
use axum::middleware::{self, Next};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use chatter_dynamics::{ModalModel, ModelFile, Observations};
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use tokio::sync::OnceCell;

const INDEX_HTML: &str = include_str!("../assets/index.html");
const APP_JS: &str = include_str!("../assets/app.js");
const APP_CSS: &str = include_str!("../assets/app.css");

/// Lobe diagrams kept in memory (per model version and request); the oldest half is dropped
/// beyond this.
const LOBE_CACHE: usize = 64;

type LobeKey = (i64, u64, u64);

/// The running application.
#[derive(Debug)]
pub struct App {
    db: Db,
    data: DataDir,
    loopback: bool,
    jobs: Mutex<HashMap<i64, Arc<JobProgress>>>,
    lobes: Mutex<HashMap<LobeKey, Arc<OnceCell<Value>>>>,
}

/// Progress and cancel flag of a running job, shared with its thread.
#[derive(Debug, Default)]
pub struct JobProgress {
    stage: Mutex<String>,
    detail: Mutex<String>,
    done: AtomicUsize,
    total: AtomicUsize,
    cancel: AtomicBool,
}

impl chatter_progress::Observer for JobProgress {
    fn steps_done(&self, done: usize, total: usize) {
        self.done.store(done, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    fn stage(&self, index: usize, beta: f64, _acceptance: f64) {
        *self
            .detail
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) =
            format!("tempering stage {index}, exponent {beta:.3}");
    }

    fn class_started(&self, index: usize, total: usize, _parameter: f64) {
        *self
            .detail
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) =
            format!("model class {} of {total}", index + 1);
    }

    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

impl work::Stages for JobProgress {
    fn step(&self, name: &str) {
        *self
            .stage
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = name.into();
        self.detail
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clear();
        self.done.store(0, Ordering::Relaxed);
        self.total.store(0, Ordering::Relaxed);
    }
}

impl App {
    /// Open the data folder `root` (created if needed) and its database; `loopback` says the
    /// server listens on a loopback address only (the Host check of the guard).
    pub fn open(root: &std::path::Path, loopback: bool) -> Result<Arc<Self>> {
        let data = DataDir::open(root)?;
        let db = Db::open(&data.database())?;
        let known = db.stored_names()?;
        data.remove_orphans(&known)?;
        Ok(Arc::new(Self {
            db,
            data,
            loopback,
            jobs: Mutex::new(HashMap::new()),
            lobes: Mutex::new(HashMap::new()),
        }))
    }

    /// The database.
    pub fn db(&self) -> &Db {
        &self.db
    }

    /// The data folder.
    pub(crate) fn data(&self) -> &DataDir {
        &self.data
    }

    /// The setup's current model, parsed.
    fn model(&self, setup_id: i64) -> Result<(i64, ModalModel)> {
        self.db.setup(setup_id)?;
        let row = self.db.current_model(setup_id)?.ok_or_else(|| {
            ServeError::bad(
                "model",
                "this setup has no model yet: upload a tap test or a model file on the Machine \
                 & tool screen",
            )
        })?;
        let model =
            ModalModel::from_json_str(&row.model.to_string(), std::path::Path::new("model"))
                .map_err(|e| ServeError::Job(format!("the stored model: {e}")))?;
        Ok((row.id, model))
    }

    /// The setup's cut log and poles as an observations file.
    fn observations(&self, setup_id: i64) -> Result<Observations> {
        let cuts = self
            .db
            .cuts(setup_id)?
            .into_iter()
            .enumerate()
            .map(|(k, c)| chatter_dynamics::Cut {
                chatter_hz: if c.stable { None } else { c.chatter_hz },
                radial_immersion: c.radial_immersion,
                note: c.note,
                sequence: Some(k as i64 + 1),
                ..chatter_dynamics::Cut::labelled(c.speed_rpm, c.depth_mm, c.stable)
            })
            .collect();
        Ok(Observations {
            cuts,
            poles: self.db.poles(setup_id)?,
            signals: Vec::new(),
        })
    }
}

/// The router of `app`.
pub fn router(app: Arc<App>) -> Router {
    Router::new()
        .route("/", get(|| async { Html(INDEX_HTML) }))
        .route(
            "/assets/app.js",
            get(|| async { asset(APP_JS, "text/javascript") }),
        )
        .route(
            "/assets/app.css",
            get(|| async { asset(APP_CSS, "text/css") }),
        )
        .route("/api/setups", get(list_setups).post(add_setup))
        .route("/api/setups/{id}", get(setup_detail))
        .route("/api/setups/{id}/frf", post(upload_frf))
        .route("/api/setups/{id}/model", post(upload_model))
        .route("/api/setups/{id}/lobes", get(lobes))
        .route("/api/setups/{id}/cuts", post(add_cut))
        .route("/api/setups/{id}/recordings", post(upload_recording))
        .route("/api/setups/{id}/observations", post(upload_observations))
        .route("/api/setups/{id}/learn", post(start_learn))
        .route("/api/setups/{id}/adopt", post(adopt_model))
        .route("/api/setups/{id}/export/{name}", get(export))
        .route("/api/cuts/{id}/result", post(set_cut_result))
        .route("/api/jobs/{id}", get(job_status))
        .route("/api/jobs/{id}/cancel", post(cancel_job))
        .layer(DefaultBodyLimit::max(
            crate::store::MAX_UPLOAD_BYTES + 256 * 1024,
        ))
        .layer(middleware::from_fn_with_state(app.clone(), guard))
        .with_state(app)
}

fn asset(body: &'static str, kind: &'static str) -> Response {
    ([(header::CONTENT_TYPE, kind)], body).into_response()
}

/// Whether a Host header names a loopback address.
fn loopback_host(host: &str) -> bool {
    let name = match host.rsplit_once(':') {
        Some((n, port)) if port.chars().all(|c| c.is_ascii_digit()) => n,
        _ => host,
    };
    matches!(name, "localhost" | "127.0.0.1" | "[::1]")
}

/// The request guard (module docs).
async fn guard(State(app): State<Arc<App>>, request: Request, next: Next) -> Response {
    match check_origin(&app, request.method(), request.headers()) {
        Ok(()) => next.run(request).await,
        Err(e) => e.into_response(),
    }
}

fn check_origin(app: &App, method: &Method, headers: &HeaderMap) -> Result<()> {
    let text = |name: header::HeaderName| {
        headers
            .get(name)
            .map(|v| v.to_str().unwrap_or("(not text)").to_string())
    };
    let host = text(header::HOST).unwrap_or_default();
    if app.loopback && !loopback_host(&host) {
        return Err(ServeError::CrossOrigin(format!(
            "Host `{host}` is not this server's loopback address"
        )));
    }
    if matches!(*method, Method::GET | Method::HEAD) {
        return Ok(());
    }
    match text(header::ORIGIN) {
        Some(origin) if origin != format!("http://{host}") => Err(ServeError::CrossOrigin(
            format!("Origin `{origin}` is not this server (http://{host})"),
        )),
        Some(_) => Ok(()),
        None => match headers.get("sec-fetch-site").and_then(|v| v.to_str().ok()) {
            None | Some("same-origin" | "none") => Ok(()),
            Some(site) => Err(ServeError::CrossOrigin(format!(
                "a {site} request without an Origin"
            ))),
        },
    }
}

/// A multipart form: its text fields and its one file.
struct Form {
    fields: HashMap<String, String>,
    file: Option<Upload>,
}

impl Form {
    async fn read(mut multipart: Multipart) -> Result<Self> {
        let form_error = |e: axum::extract::multipart::MultipartError| {
            if e.status() == axum::http::StatusCode::PAYLOAD_TOO_LARGE {
                ServeError::bad(
                    "file",
                    format!(
                        "the upload is larger than the {} MiB limit",
                        crate::store::MAX_UPLOAD_BYTES / 1048576
                    ),
                )
            } else {
                ServeError::bad("form", e.body_text())
            }
        };
        let mut form = Form {
            fields: HashMap::new(),
            file: None,
        };
        while let Some(field) = multipart.next_field().await.map_err(form_error)? {
            let name = field.name().unwrap_or_default().to_string();
            if name == "file" {
                let shown = field.file_name().unwrap_or_default().to_string();
                let bytes = field.bytes().await.map_err(form_error)?;
                form.file = Some(Upload {
                    name: shown,
                    bytes: bytes.to_vec(),
                });
            } else {
                let value = field.text().await.map_err(form_error)?;
                form.fields.insert(name, value.trim().to_string());
            }
        }
        Ok(form)
    }

    fn file(&mut self) -> Result<Upload> {
        self.file
            .take()
            .ok_or_else(|| ServeError::bad("file", "no file chosen"))
    }

    /// An optional number field (empty is absent).
    fn number(&self, name: &str) -> Result<Option<f64>> {
        match self.fields.get(name).map(String::as_str) {
            None | Some("") => Ok(None),
            Some(text) => text
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .map(Some)
                .ok_or_else(|| ServeError::bad(name, format!("`{text}`: expected a number"))),
        }
    }

    fn required(&self, name: &str) -> Result<f64> {
        self.number(name)?
            .ok_or_else(|| ServeError::bad(name, "missing: expected a number"))
    }
}

/// Run blocking work (the science crates) off the async threads.
async fn blocking<T: Send + 'static>(f: impl FnOnce() -> Result<T> + Send + 'static) -> Result<T> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ServeError::Job(format!("the computation stopped: {e}")))?
}

async fn list_setups(State(app): State<Arc<App>>) -> Result<Json<Value>> {
    Ok(Json(json!({ "setups": app.db.setups()? })))
}

/// A new setup's form.
#[derive(Debug, Deserialize)]
struct NewSetup {
    name: String,
    #[serde(default)]
    machine: String,
    #[serde(default)]
    tool: String,
    #[serde(default)]
    holder: String,
    teeth: i64,
    radial_immersion: f64,
    direction: String,
    tool_diameter_mm: Option<f64>,
    ks_n_per_mm2: f64,
    beta_deg: f64,
}

/// The process of a setup as a model file without modes, checked.
fn process_of(s: &NewSetup) -> Result<Value> {
    let process = json!({
        "operation": {
            "kind": "milling",
            "teeth": s.teeth,
            "radial_immersion": s.radial_immersion,
            "direction": s.direction,
            "tool_diameter_mm": s.tool_diameter_mm,
        },
        "cutting": {"ks_n_per_mm2": s.ks_n_per_mm2, "beta_deg": s.beta_deg},
        "modes": [],
    });
    let file: ModelFile = serde_json::from_value(process.clone())
        .map_err(|e| ServeError::bad("setup", e.to_string()))?;
    file.validate_process()
        .map_err(|e| ServeError::bad("setup", e.to_string()))?;
    Ok(process)
}

async fn add_setup(State(app): State<Arc<App>>, Json(s): Json<NewSetup>) -> Result<Json<Value>> {
    let name = s.name.trim();
    if name.is_empty() || name.chars().count() > 200 {
        return Err(ServeError::bad(
            "name",
            "expected a name of 1 to 200 characters",
        ));
    }
    let process = process_of(&s)?;
    let id = app
        .db
        .add_setup(name, &s.machine, &s.tool, &s.holder, &process)?;
    Ok(Json(json!({ "id": id })))
}

async fn setup_detail(State(app): State<Arc<App>>, Path(id): Path<i64>) -> Result<Json<Value>> {
    let setup = app.db.setup(id)?;
    let files: Vec<Value> = app
        .db
        .files(id)?
        .into_iter()
        .map(|(kind, name, _, bytes)| json!({"kind": kind, "name": name, "bytes": bytes}))
        .collect();
    Ok(Json(json!({
        "setup": setup,
        "model": app.db.current_model(id)?,
        "model_versions": app.db.model_count(id)?,
        "cuts": app.db.cuts(id)?,
        "poles": app.db.poles(id)?.len(),
        "files": files,
        "jobs": app.db.jobs(id)?,
    })))
}

/// Stage an upload, run `parse` on it, and keep the file only with the rows `store` writes.
async fn with_upload<T: Send + 'static>(
    app: &Arc<App>,
    setup_id: i64,
    upload: Upload,
    kind: UploadKind,
    parse: impl FnOnce(&std::path::Path, &str) -> Result<T> + Send + 'static,
    store: impl FnOnce(&Db, &StoredFile, &T) -> Result<()> + Send + 'static,
) -> Result<T> {
    app.db.setup(setup_id)?;
    let extension = check(&upload, kind)?;
    let app = app.clone();
    blocking(move || {
        let staged = app.data.stage(kind, extension, &upload.bytes)?;
        let parsed = parse(&staged.path, &upload.name)?;
        let stored = StoredFile {
            kind: kind.name(),
            original_name: upload.name.clone(),
            stored_name: staged.stored_name.clone(),
            bytes: upload.bytes.len(),
        };
        let kept = staged.keep()?;
        if let Err(e) = store(&app.db, &stored, &parsed) {
            kept.forget();
            return Err(e);
        }
        Ok(parsed)
    })
    .await
}

async fn upload_frf(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    multipart: Multipart,
) -> Result<Json<Value>> {
    let mut form = Form::read(multipart).await?;
    let modes = match form.number("modes")? {
        Some(n) if n.fract() == 0.0 && n >= 1.0 => Some(n as usize),
        Some(n) => {
            return Err(ServeError::bad(
                "modes",
                format!("{n}: expected a count >= 1"),
            ));
        }
        None => None,
    };
    let request = FitRequest {
        fmin_hz: form.number("fmin_hz")?,
        fmax_hz: form.number("fmax_hz")?,
        modes,
        directions: TapDirections::parse(form.fields.get("direction").map_or("", String::as_str))?,
    };
    let upload = form.file()?;
    let setup = app.db.setup(id)?;
    let process: ModelFile = serde_json::from_value(setup.process.clone())
        .map_err(|e| ServeError::Job(format!("the stored process: {e}")))?;
    let current: Option<ModelFile> = app
        .db
        .current_model(id)?
        .and_then(|m| serde_json::from_value(m.model).ok());
    let (_, report) = with_upload(
        &app,
        id,
        upload,
        UploadKind::Frf,
        move |path, shown| work::fit_tap_test(path, shown, &process, current.as_ref(), &request),
        move |db, file, (model, report)| {
            db.add_model(
                id,
                model,
                &format!("fitted to the tap test {}", file.original_name),
                Some(report),
                Some(file),
            )
            .map(drop)
        },
    )
    .await?;
    Ok(Json(json!({ "fit": report })))
}

async fn upload_model(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    multipart: Multipart,
) -> Result<Json<Value>> {
    let upload = Form::read(multipart).await?.file()?;
    let (_, file) = with_upload(
        &app,
        id,
        upload,
        UploadKind::Model,
        |path, shown| {
            let text = std::fs::read_to_string(path).map_err(|e| ServeError::io(path, e))?;
            work::check_model(&text, shown)
        },
        move |db, file, (_, model)| {
            let text =
                serde_json::to_string_pretty(model).map_err(|e| ServeError::Job(e.to_string()))?;
            db.add_model(
                id,
                &text,
                &format!("uploaded {}", file.original_name),
                None,
                Some(file),
            )
            .map(drop)
        },
    )
    .await?;
    Ok(Json(json!({ "model": file })))
}

/// The page's lobe request; defaults 20 mm and risk 0.05.
#[derive(Debug, Deserialize)]
struct LobeQuery {
    max_depth_mm: Option<f64>,
    risk: Option<f64>,
}

async fn lobes(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    Query(q): Query<LobeQuery>,
) -> Result<Json<Value>> {
    let request = LobeRequest {
        max_depth_mm: q.max_depth_mm.unwrap_or(20.0),
        risk: q.risk.unwrap_or(0.05),
    };
    let (model_id, model) = app.model(id)?;
    let key = (
        model_id,
        request.max_depth_mm.to_bits(),
        request.risk.to_bits(),
    );
    let cell = {
        let mut cache = app
            .lobes
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if cache.len() >= LOBE_CACHE {
            let mut keys: Vec<LobeKey> = cache.keys().copied().collect();
            keys.sort_unstable();
            for k in &keys[..keys.len() / 2] {
                cache.remove(k);
            }
        }
        cache.entry(key).or_default().clone()
    };
    // concurrent requests for the same diagram wait for one computation
    let started = std::time::Instant::now();
    let diagram = cell
        .get_or_try_init(|| {
            blocking(move || work::lobes(&model, &request, &chatter_progress::Silent))
        })
        .await?
        .clone();
    let cuts = app.db.cuts(id)?;
    Ok(Json(json!({
        "diagram": diagram,
        "model_id": model_id,
        "cuts": cuts,
        "server_ms": started.elapsed().as_secs_f64() * 1e3,
    })))
}

/// A cut entered on the page.
#[derive(Debug, Deserialize)]
struct EnteredCut {
    speed_rpm: f64,
    depth_mm: f64,
    stable: bool,
    chatter_hz: Option<f64>,
    radial_immersion: Option<f64>,
    note: Option<String>,
}

async fn add_cut(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    Json(c): Json<EnteredCut>,
) -> Result<Json<Value>> {
    app.db.setup(id)?;
    let cut = chatter_dynamics::Cut {
        chatter_hz: if c.stable { None } else { c.chatter_hz },
        radial_immersion: c.radial_immersion,
        note: c.note.filter(|n| !n.trim().is_empty()),
        ..chatter_dynamics::Cut::labelled(c.speed_rpm, c.depth_mm, c.stable)
    };
    let check = Observations {
        cuts: vec![cut.clone()],
        ..Observations::default()
    };
    check
        .validate()
        .map_err(|e| ServeError::bad("cut", e.to_string().replace("cuts[0].", "")))?;
    let ids = app.db.add_cuts(
        id,
        &[NewCut {
            cut,
            origin: "entered",
            detection: None,
        }],
        &[],
        None,
    )?;
    Ok(Json(json!({ "id": ids[0] })))
}

async fn upload_recording(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    multipart: Multipart,
) -> Result<Json<Value>> {
    let mut form = Form::read(multipart).await?;
    let request = RecordingRequest {
        speed_rpm: form.required("speed_rpm")?,
        depth_mm: form.required("depth_mm")?,
        sample_rate_hz: form.number("sample_rate_hz")?,
    };
    let upload = form.file()?;
    let model = app.model(id).ok().map(|(_, m)| m);
    let (_, report) = with_upload(
        &app,
        id,
        upload,
        UploadKind::Recording,
        move |path, shown| work::detect(path, shown, &request, model.as_ref()),
        move |db, file, (cut, report)| {
            db.add_cuts(
                id,
                &[NewCut {
                    cut: cut.clone(),
                    origin: "detected",
                    detection: Some(report.clone()),
                }],
                &[],
                Some(file),
            )
            .map(drop)
        },
    )
    .await?;
    Ok(Json(json!({ "detection": report })))
}

async fn upload_observations(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    multipart: Multipart,
) -> Result<Json<Value>> {
    let upload = Form::read(multipart).await?.file()?;
    let model = app.model(id).ok().map(|(_, m)| m);
    let observations = with_upload(
        &app,
        id,
        upload,
        UploadKind::Observations,
        move |path, shown| {
            let text = std::fs::read_to_string(path).map_err(|e| ServeError::io(path, e))?;
            let origin = std::path::Path::new(shown);
            let o = if shown.to_ascii_lowercase().ends_with(".csv") {
                Observations::from_cuts_csv(&text, origin)
            } else {
                Observations::from_json_str(&text, origin)
            }
            .map_err(|e| ServeError::bad("file", e.to_string()))?;
            if !o.signals.is_empty() {
                return Err(ServeError::bad(
                    "file",
                    format!(
                        "`{shown}` lists signal records, which refer to files on your disk: \
                         upload each recording on its own"
                    ),
                ));
            }
            if let Some(m) = &model {
                o.check_against(m)
                    .map_err(|e| ServeError::bad("file", format!("`{shown}`: {e}")))?;
            }
            Ok(o)
        },
        move |db, file, o| {
            let cuts: Vec<NewCut> = o
                .cuts
                .iter()
                .map(|c| NewCut {
                    cut: c.clone(),
                    origin: "imported",
                    detection: None,
                })
                .collect();
            db.add_cuts(id, &cuts, &o.poles, Some(file)).map(drop)
        },
    )
    .await?;
    Ok(Json(json!({
        "cuts": observations.cuts.len(),
        "poles": observations.poles.len(),
    })))
}

/// Confirm or overrule a cut.
#[derive(Debug, Deserialize)]
struct CutResult {
    stable: bool,
}

async fn set_cut_result(
    State(app): State<Arc<App>>,
    Path(cut): Path<i64>,
    Json(r): Json<CutResult>,
) -> Result<Json<Value>> {
    let setup = app.db.set_cut_result(cut, r.stable)?;
    Ok(Json(json!({ "setup_id": setup })))
}

async fn start_learn(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    body: Option<Json<LearnRequest>>,
) -> Result<Json<Value>> {
    let request = body.map_or_else(LearnRequest::default, |Json(r)| r);
    let (_, model) = app.model(id)?;
    let observations = app.observations(id)?;
    if observations.cuts.is_empty() && observations.poles.is_empty() {
        return Err(ServeError::bad(
            "cut log",
            "no cuts logged yet: enter cuts or upload recordings on the Cut log screen first",
        ));
    }
    let request_json = serde_json::to_value(request).map_err(|e| ServeError::Job(e.to_string()))?;
    let job = app.db.start_job(id, "learn", &request_json)?;
    let progress = Arc::new(JobProgress::default());
    app.jobs
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .insert(job, progress.clone());
    let worker = app.clone();
    std::thread::Builder::new()
        .name(format!("job-{job}"))
        .spawn(move || {
            let outcome = work::learn(&model, &observations, &request, progress.as_ref());
            let cancelled = progress.cancel.load(Ordering::Relaxed);
            let written = match (&outcome, cancelled) {
                (Ok(result), _) => worker.db.finish_job(job, "done", Some(result), None),
                (Err(_), true) => worker.db.finish_job(
                    job,
                    "cancelled",
                    None,
                    Some("cancelled by the user; nothing was kept"),
                ),
                (Err(e), false) => worker
                    .db
                    .finish_job(job, "failed", None, Some(&e.to_string())),
            };
            // a job whose row cannot be written stays `running` and is marked failed at the
            // next start, as after a crash
            drop(written);
            worker
                .jobs
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .remove(&job);
        })
        .map_err(|e| ServeError::Job(format!("starting the job: {e}")))?;
    Ok(Json(json!({ "job": job })))
}

async fn job_status(State(app): State<Arc<App>>, Path(id): Path<i64>) -> Result<Json<Value>> {
    let row = app.db.job(id)?;
    let live = app
        .jobs
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .get(&id)
        .cloned();
    let progress = live.map(|p| {
        json!({
            "stage": p.stage.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone(),
            "detail": p.detail.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone(),
            "done": p.done.load(Ordering::Relaxed),
            "total": p.total.load(Ordering::Relaxed),
            "cancel_requested": p.cancel.load(Ordering::Relaxed),
        })
    });
    Ok(Json(json!({ "job": row, "progress": progress })))
}

async fn cancel_job(State(app): State<Arc<App>>, Path(id): Path<i64>) -> Result<Json<Value>> {
    let row = app.db.job(id)?;
    let live = app
        .jobs
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .get(&id)
        .cloned();
    match live {
        Some(p) => {
            p.cancel.store(true, Ordering::Relaxed);
            Ok(Json(json!({ "cancelling": id })))
        }
        None => Err(ServeError::bad(
            "job",
            format!("job {id} is not running (it is {})", row.status),
        )),
    }
}

/// Which learned model to adopt.
#[derive(Debug, Deserialize)]
struct Adopt {
    job: i64,
    /// `update` (the posterior-mean model) or `diagnosis` (the diagnosed machine).
    which: String,
}

async fn adopt_model(
    State(app): State<Arc<App>>,
    Path(id): Path<i64>,
    Json(a): Json<Adopt>,
) -> Result<Json<Value>> {
    let row = app.db.job(a.job)?;
    if row.setup_id != id || row.status != "done" {
        return Err(ServeError::bad(
            "job",
            format!("job {} is not a finished job of setup {id}", a.job),
        ));
    }
    let model = row
        .result
        .as_ref()
        .and_then(|r| r.get(a.which.as_str()))
        .and_then(|r| r.get("model"))
        .ok_or_else(|| {
            ServeError::bad(
                "which",
                format!("`{}`: expected update or diagnosis", a.which),
            )
        })?;
    let text = serde_json::to_string_pretty(model).map_err(|e| ServeError::Job(e.to_string()))?;
    work::check_model(&text, "the learned model")?;
    let model_id = app.db.add_model(
        id,
        &text,
        &format!("learned by job {} ({})", a.job, a.which),
        None,
        None,
    )?;
    Ok(Json(json!({ "model_id": model_id })))
}

async fn export(
    State(app): State<Arc<App>>,
    Path((id, name)): Path<(i64, String)>,
) -> Result<Response> {
    let body = match name.as_str() {
        "model.json" => {
            let row = app
                .db
                .current_model(id)?
                .ok_or_else(|| ServeError::NotFound(format!("a model of setup {id}")))?;
            serde_json::to_string_pretty(&row.model)
        }
        "observations.json" => Ok(app.observations(id)?.to_json_string()),
        "diagnosis.json" => {
            let job = app
                .db
                .jobs(id)?
                .into_iter()
                .find(|j| j.status == "done")
                .ok_or_else(|| {
                    ServeError::NotFound(format!("a finished learning run of setup {id}"))
                })?;
            serde_json::to_string_pretty(&job.result)
        }
        other => return Err(ServeError::NotFound(format!("export {other}"))),
    }
    .map_err(|e| ServeError::Job(e.to_string()))?;
    Ok((
        [
            (header::CONTENT_TYPE, "application/json".to_string()),
            (
                header::CONTENT_DISPOSITION,
                format!("attachment; filename=\"setup{id}-{name}\""),
            ),
        ],
        body,
    )
        .into_response())
}
