//! The application's database: one SQLite file `chatter.sqlite` under the data folder, opened in
//! write-ahead-log mode with foreign keys enforced. Its schema is versioned by SQLite's
//! `user_version`: [`MIGRATIONS`] are applied in order, each in its own transaction, so a
//! database written by an older server is brought up to date when a newer one opens it.
//!
//! What is kept: setups (machine, tool, holder and the cutting process), uploaded files (the
//! name the user gave is only shown, the file lies under a generated name), model versions (the
//! latest is the setup's current model; a fitted model keeps its fit report), cuts (entered,
//! detected from a recording, or imported), identified poles and background jobs with their
//! results. Every write that belongs together is one transaction: a killed server leaves either
//! the whole change or none of it. A job that was running when the server stopped is marked
//! failed when it is opened again ([`Db::open`]).

use crate::error::{Result, ServeError};
use rusqlite::{Connection, OptionalExtension, params};
use serde::Serialize;
use std::path::Path;
use std::sync::{Mutex, MutexGuard};

/// The schema, one migration per version (`user_version` counts those applied).
pub const MIGRATIONS: &[&str] = &["
CREATE TABLE setups (
    id INTEGER PRIMARY KEY,
    name TEXT NOT NULL,
    machine TEXT NOT NULL,
    tool TEXT NOT NULL,
    holder TEXT NOT NULL,
    process_json TEXT NOT NULL,
    created_at TEXT NOT NULL DEFAULT (datetime('now'))
);
CREATE TABLE files (
    id INTEGER PRIMARY KEY,
    setup_id INTEGER NOT NULL REFERENCES setups(id),
    kind TEXT NOT NULL CHECK (kind IN ('frf', 'model', 'recording', 'observations')),
    original_name TEXT NOT NULL,
    stored_name TEXT NOT NULL UNIQUE,
    bytes INTEGER NOT NULL,
    created_at TEXT NOT NULL DEFAULT (datetime('now'))
);
CREATE TABLE models (
    id INTEGER PRIMARY KEY,
    setup_id INTEGER NOT NULL REFERENCES setups(id),
    model_json TEXT NOT NULL,
    source TEXT NOT NULL,
    fit_json TEXT,
    file_id INTEGER REFERENCES files(id),
    created_at TEXT NOT NULL DEFAULT (datetime('now'))
);
CREATE TABLE cuts (
    id INTEGER PRIMARY KEY,
    setup_id INTEGER NOT NULL REFERENCES setups(id),
    speed_rpm REAL NOT NULL,
    depth_mm REAL NOT NULL,
    radial_immersion REAL,
    stable INTEGER NOT NULL CHECK (stable IN (0, 1)),
    chatter_hz REAL,
    origin TEXT NOT NULL CHECK (origin IN ('entered', 'detected', 'imported')),
    overruled INTEGER NOT NULL DEFAULT 0 CHECK (overruled IN (0, 1)),
    recording_file_id INTEGER REFERENCES files(id),
    detection_json TEXT,
    note TEXT,
    created_at TEXT NOT NULL DEFAULT (datetime('now'))
);
CREATE TABLE poles (
    id INTEGER PRIMARY KEY,
    setup_id INTEGER NOT NULL REFERENCES setups(id),
    pole_json TEXT NOT NULL
);
CREATE TABLE jobs (
    id INTEGER PRIMARY KEY,
    setup_id INTEGER NOT NULL REFERENCES setups(id),
    kind TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('running', 'done', 'failed', 'cancelled')),
    request_json TEXT NOT NULL,
    result_json TEXT,
    error TEXT,
    created_at TEXT NOT NULL DEFAULT (datetime('now')),
    finished_at TEXT
);
"];

/// What a job that was running when the server stopped is marked with.
pub const INTERRUPTED: &str = "the server stopped while this job ran (killed or crashed); nothing of it was kept: run it again";

/// The database behind one lock: requests are short, and the lock makes every read see whole
/// transactions.
#[derive(Debug)]
pub struct Db {
    connection: Mutex<Connection>,
}

/// A setup: machine, tool and holder, and the cutting process its models share.
#[derive(Debug, Clone, Serialize)]
pub struct Setup {
    /// Row id.
    pub id: i64,
    /// Name the user gave.
    pub name: String,
    /// Machine.
    pub machine: String,
    /// Tool.
    pub tool: String,
    /// Holder.
    pub holder: String,
    /// The process as a model file without modes (`operation`, `cutting`).
    pub process: serde_json::Value,
    /// When it was created (UTC).
    pub created_at: String,
}

/// A model version of a setup.
#[derive(Debug, Clone, Serialize)]
pub struct ModelRow {
    /// Row id.
    pub id: i64,
    /// The model file (JSON).
    pub model: serde_json::Value,
    /// Where it came from (`fitted from tap.uff`, `uploaded model.json`, `diagnosed`, ...).
    pub source: String,
    /// The fit report of a fitted model.
    pub fit: Option<serde_json::Value>,
    /// When it was stored (UTC).
    pub created_at: String,
}

/// A logged cut.
#[derive(Debug, Clone, Serialize)]
pub struct CutRow {
    /// Row id.
    pub id: i64,
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Axial depth (mm).
    pub depth_mm: f64,
    /// Radial immersion of this cut when it differs from the setup's.
    pub radial_immersion: Option<f64>,
    /// Stable (true) or chatter.
    pub stable: bool,
    /// Chatter frequency (Hz).
    pub chatter_hz: Option<f64>,
    /// `entered`, `detected` or `imported`.
    pub origin: String,
    /// The user overruled detection's verdict.
    pub overruled: bool,
    /// Name of the recording the verdict came from.
    pub recording: Option<String>,
    /// Detection's numbers (verdict, evidence) for a detected cut.
    pub detection: Option<serde_json::Value>,
    /// Free text.
    pub note: Option<String>,
}

/// A background job.
#[derive(Debug, Clone, Serialize)]
pub struct JobRow {
    /// Row id.
    pub id: i64,
    /// Its setup.
    pub setup_id: i64,
    /// `learn`.
    pub kind: String,
    /// `running`, `done`, `failed` or `cancelled`.
    pub status: String,
    /// The request.
    pub request: serde_json::Value,
    /// The result of a finished job.
    pub result: Option<serde_json::Value>,
    /// Why it failed.
    pub error: Option<String>,
    /// Started (UTC).
    pub created_at: String,
    /// Finished (UTC).
    pub finished_at: Option<String>,
}

/// A file as stored: its generated name under the data folder's `files/` and the name shown.
#[derive(Debug, Clone)]
pub struct StoredFile {
    /// `frf`, `model`, `recording` or `observations`.
    pub kind: &'static str,
    /// The name the user gave (shown, never used as a path).
    pub original_name: String,
    /// The generated name.
    pub stored_name: String,
    /// Size.
    pub bytes: usize,
}

/// A new cut: what the cut log or detection adds.
#[derive(Debug, Clone)]
pub struct NewCut {
    /// The observations-format cut (speed, depth, immersion, result, chatter frequency, note).
    pub cut: chatter_dynamics::Cut,
    /// `entered`, `detected` or `imported`.
    pub origin: &'static str,
    /// Detection's numbers of a detected cut.
    pub detection: Option<serde_json::Value>,
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or(serde_json::Value::Null)
}

impl Db {
    /// Open (or create) `path`, bring its schema up to date and mark the jobs that were running
    /// when the last server stopped as failed ([`INTERRUPTED`]).
    pub fn open(path: &Path) -> Result<Self> {
        let mut c = Connection::open(path)?;
        c.pragma_update(None, "journal_mode", "WAL")?;
        c.pragma_update(None, "synchronous", "FULL")?;
        c.pragma_update(None, "foreign_keys", "ON")?;
        c.busy_timeout(std::time::Duration::from_secs(10))?;
        let version: i64 = c.pragma_query_value(None, "user_version", |r| r.get(0))?;
        let known = MIGRATIONS.len() as i64;
        if version > known {
            return Err(ServeError::bad(
                "database",
                format!(
                    "{} has schema version {version}, newer than this program's {known}: use \
                     the newer chatter, or another --data folder",
                    path.display()
                ),
            ));
        }
        for (k, sql) in MIGRATIONS.iter().enumerate().skip(version as usize) {
            let t = c.transaction()?;
            t.execute_batch(sql)?;
            t.pragma_update(None, "user_version", k as i64 + 1)?;
            t.commit()?;
        }
        c.execute(
            "UPDATE jobs SET status = 'failed', error = ?1, finished_at = datetime('now') \
             WHERE status = 'running'",
            params![INTERRUPTED],
        )?;
        Ok(Self {
            connection: Mutex::new(c),
        })
    }

    fn lock(&self) -> MutexGuard<'_, Connection> {
        // a panic while the lock was held cannot leave a transaction half-applied (SQLite rolls
        // it back), so the connection stays usable
        self.connection
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The schema version of the open database.
    pub fn schema_version(&self) -> Result<i64> {
        Ok(self
            .lock()
            .pragma_query_value(None, "user_version", |r| r.get(0))?)
    }

    /// Add a setup; its id.
    pub fn add_setup(
        &self,
        name: &str,
        machine: &str,
        tool: &str,
        holder: &str,
        process: &serde_json::Value,
    ) -> Result<i64> {
        let c = self.lock();
        c.execute(
            "INSERT INTO setups (name, machine, tool, holder, process_json) VALUES (?1, ?2, ?3, \
             ?4, ?5)",
            params![name, machine, tool, holder, process.to_string()],
        )?;
        Ok(c.last_insert_rowid())
    }

    /// Every setup, newest first.
    pub fn setups(&self) -> Result<Vec<Setup>> {
        let c = self.lock();
        let mut s = c.prepare(
            "SELECT id, name, machine, tool, holder, process_json, created_at FROM setups \
             ORDER BY id DESC",
        )?;
        let rows = s.query_map([], setup_of)?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// One setup.
    pub fn setup(&self, id: i64) -> Result<Setup> {
        self.lock()
            .query_row(
                "SELECT id, name, machine, tool, holder, process_json, created_at FROM setups \
                 WHERE id = ?1",
                params![id],
                setup_of,
            )
            .optional()?
            .ok_or_else(|| ServeError::NotFound(format!("setup {id}")))
    }

    /// Store a model version (with the file it came from, if any) in one transaction; its id.
    pub fn add_model(
        &self,
        setup_id: i64,
        model_json: &str,
        source: &str,
        fit: Option<&serde_json::Value>,
        file: Option<&StoredFile>,
    ) -> Result<i64> {
        let mut c = self.lock();
        let t = c.transaction()?;
        let file_id = file.map(|f| insert_file(&t, setup_id, f)).transpose()?;
        t.execute(
            "INSERT INTO models (setup_id, model_json, source, fit_json, file_id) VALUES (?1, \
             ?2, ?3, ?4, ?5)",
            params![
                setup_id,
                model_json,
                source,
                fit.map(|f| f.to_string()),
                file_id
            ],
        )?;
        let id = t.last_insert_rowid();
        t.commit()?;
        Ok(id)
    }

    /// The setup's current model (the latest version), if it has one.
    pub fn current_model(&self, setup_id: i64) -> Result<Option<ModelRow>> {
        Ok(self
            .lock()
            .query_row(
                "SELECT id, model_json, source, fit_json, created_at FROM models WHERE setup_id \
                 = ?1 ORDER BY id DESC LIMIT 1",
                params![setup_id],
                |r| {
                    Ok(ModelRow {
                        id: r.get(0)?,
                        model: json(&r.get::<_, String>(1)?),
                        source: r.get(2)?,
                        fit: r.get::<_, Option<String>>(3)?.as_deref().map(json),
                        created_at: r.get(4)?,
                    })
                },
            )
            .optional()?)
    }

    /// How many model versions the setup has.
    pub fn model_count(&self, setup_id: i64) -> Result<i64> {
        Ok(self.lock().query_row(
            "SELECT count(*) FROM models WHERE setup_id = ?1",
            params![setup_id],
            |r| r.get(0),
        )?)
    }

    /// Store cuts and poles (and the file they came from) in one transaction.
    pub fn add_cuts(
        &self,
        setup_id: i64,
        cuts: &[NewCut],
        poles: &[chatter_dynamics::PoleObservation],
        file: Option<&StoredFile>,
    ) -> Result<Vec<i64>> {
        let mut c = self.lock();
        let t = c.transaction()?;
        let file_id = file.map(|f| insert_file(&t, setup_id, f)).transpose()?;
        let mut ids = Vec::with_capacity(cuts.len());
        for n in cuts {
            let cut = &n.cut;
            t.execute(
                "INSERT INTO cuts (setup_id, speed_rpm, depth_mm, radial_immersion, stable, \
                 chatter_hz, origin, recording_file_id, detection_json, note) VALUES (?1, ?2, \
                 ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                params![
                    setup_id,
                    cut.speed_rpm,
                    cut.depth_mm,
                    cut.radial_immersion,
                    cut.stable,
                    cut.chatter_hz,
                    n.origin,
                    if n.origin == "detected" {
                        file_id
                    } else {
                        None
                    },
                    n.detection.as_ref().map(|d| d.to_string()),
                    cut.note
                ],
            )?;
            ids.push(t.last_insert_rowid());
        }
        for p in poles {
            t.execute(
                "INSERT INTO poles (setup_id, pole_json) VALUES (?1, ?2)",
                params![
                    setup_id,
                    serde_json::to_string(p).map_err(|e| ServeError::Job(e.to_string()))?
                ],
            )?;
        }
        t.commit()?;
        Ok(ids)
    }

    /// The setup's cuts in the order they were logged.
    pub fn cuts(&self, setup_id: i64) -> Result<Vec<CutRow>> {
        let c = self.lock();
        let mut s = c.prepare(
            "SELECT c.id, c.speed_rpm, c.depth_mm, c.radial_immersion, c.stable, c.chatter_hz, \
             c.origin, c.overruled, f.original_name, c.detection_json, c.note FROM cuts c LEFT \
             JOIN files f ON f.id = c.recording_file_id WHERE c.setup_id = ?1 ORDER BY c.id",
        )?;
        let rows = s.query_map(params![setup_id], |r| {
            Ok(CutRow {
                id: r.get(0)?,
                speed_rpm: r.get(1)?,
                depth_mm: r.get(2)?,
                radial_immersion: r.get(3)?,
                stable: r.get(4)?,
                chatter_hz: r.get(5)?,
                origin: r.get(6)?,
                overruled: r.get(7)?,
                recording: r.get(8)?,
                detection: r.get::<_, Option<String>>(9)?.as_deref().map(json),
                note: r.get(10)?,
            })
        })?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// The setup's identified poles.
    pub fn poles(&self, setup_id: i64) -> Result<Vec<chatter_dynamics::PoleObservation>> {
        let c = self.lock();
        let mut s = c.prepare("SELECT pole_json FROM poles WHERE setup_id = ?1 ORDER BY id")?;
        let texts = s
            .query_map(params![setup_id], |r| r.get::<_, String>(0))?
            .collect::<rusqlite::Result<Vec<_>>>()?;
        texts
            .iter()
            .map(|t| serde_json::from_str(t).map_err(|e| ServeError::Job(format!("pole: {e}"))))
            .collect()
    }

    /// Confirm or overrule a cut's result: `stable`, with the chatter frequency dropped when it
    /// becomes stable. Returns the setup of the cut.
    pub fn set_cut_result(&self, cut_id: i64, stable: bool) -> Result<i64> {
        let mut c = self.lock();
        let t = c.transaction()?;
        let (setup_id, was): (i64, bool) = t
            .query_row(
                "SELECT setup_id, stable FROM cuts WHERE id = ?1",
                params![cut_id],
                |r| Ok((r.get(0)?, r.get(1)?)),
            )
            .optional()?
            .ok_or_else(|| ServeError::NotFound(format!("cut {cut_id}")))?;
        if was != stable {
            t.execute(
                "UPDATE cuts SET stable = ?2, overruled = 1 - overruled, chatter_hz = CASE WHEN \
                 ?2 THEN NULL ELSE chatter_hz END WHERE id = ?1",
                params![cut_id, stable],
            )?;
        }
        t.commit()?;
        Ok(setup_id)
    }

    /// Files of a setup: (kind, name shown, stored name, bytes).
    pub fn files(&self, setup_id: i64) -> Result<Vec<(String, String, String, i64)>> {
        let c = self.lock();
        let mut s = c.prepare(
            "SELECT kind, original_name, stored_name, bytes FROM files WHERE setup_id = ?1 \
             ORDER BY id",
        )?;
        let rows = s.query_map(params![setup_id], |r| {
            Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?))
        })?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// Start a job: a `running` row; its id.
    pub fn start_job(&self, setup_id: i64, kind: &str, request: &serde_json::Value) -> Result<i64> {
        let c = self.lock();
        c.execute(
            "INSERT INTO jobs (setup_id, kind, status, request_json) VALUES (?1, ?2, 'running', \
             ?3)",
            params![setup_id, kind, request.to_string()],
        )?;
        Ok(c.last_insert_rowid())
    }

    /// Finish a job: its status with its result or error, in one statement.
    pub fn finish_job(
        &self,
        job_id: i64,
        status: &str,
        result: Option<&serde_json::Value>,
        error: Option<&str>,
    ) -> Result<()> {
        self.lock().execute(
            "UPDATE jobs SET status = ?2, result_json = ?3, error = ?4, finished_at = \
             datetime('now') WHERE id = ?1",
            params![job_id, status, result.map(|r| r.to_string()), error],
        )?;
        Ok(())
    }

    /// One job.
    pub fn job(&self, id: i64) -> Result<JobRow> {
        self.lock()
            .query_row(&format!("{JOB_COLUMNS} WHERE id = ?1"), params![id], job_of)
            .optional()?
            .ok_or_else(|| ServeError::NotFound(format!("job {id}")))
    }

    /// The setup's jobs, newest first.
    pub fn jobs(&self, setup_id: i64) -> Result<Vec<JobRow>> {
        let c = self.lock();
        let mut s = c.prepare(&format!(
            "{JOB_COLUMNS} WHERE setup_id = ?1 ORDER BY id DESC"
        ))?;
        let rows = s.query_map(params![setup_id], job_of)?;
        Ok(rows.collect::<rusqlite::Result<_>>()?)
    }

    /// The generated names of every stored file.
    pub fn stored_names(&self) -> Result<std::collections::HashSet<String>> {
        let c = self.lock();
        let mut s = c.prepare("SELECT stored_name FROM files")?;
        let names = s.query_map([], |r| r.get::<_, String>(0))?;
        Ok(names.collect::<rusqlite::Result<_>>()?)
    }

    /// Rows per table (setups, files, models, cuts, poles, jobs): what a refused upload must
    /// leave unchanged.
    pub fn counts(&self) -> Result<[i64; 6]> {
        let c = self.lock();
        let mut out = [0; 6];
        for (k, t) in ["setups", "files", "models", "cuts", "poles", "jobs"]
            .iter()
            .enumerate()
        {
            out[k] = c.query_row(&format!("SELECT count(*) FROM {t}"), [], |r| r.get(0))?;
        }
        Ok(out)
    }
}

const JOB_COLUMNS: &str = "SELECT id, setup_id, kind, status, request_json, result_json, error, \
                           created_at, finished_at FROM jobs";

fn job_of(r: &rusqlite::Row) -> rusqlite::Result<JobRow> {
    Ok(JobRow {
        id: r.get(0)?,
        setup_id: r.get(1)?,
        kind: r.get(2)?,
        status: r.get(3)?,
        request: json(&r.get::<_, String>(4)?),
        result: r.get::<_, Option<String>>(5)?.as_deref().map(json),
        error: r.get(6)?,
        created_at: r.get(7)?,
        finished_at: r.get(8)?,
    })
}

fn setup_of(r: &rusqlite::Row) -> rusqlite::Result<Setup> {
    Ok(Setup {
        id: r.get(0)?,
        name: r.get(1)?,
        machine: r.get(2)?,
        tool: r.get(3)?,
        holder: r.get(4)?,
        process: json(&r.get::<_, String>(5)?),
        created_at: r.get(6)?,
    })
}

fn insert_file(t: &rusqlite::Transaction, setup_id: i64, f: &StoredFile) -> Result<i64> {
    t.execute(
        "INSERT INTO files (setup_id, kind, original_name, stored_name, bytes) VALUES (?1, ?2, \
         ?3, ?4, ?5)",
        params![
            setup_id,
            f.kind,
            f.original_name,
            f.stored_name,
            f.bytes as i64
        ],
    )?;
    Ok(t.last_insert_rowid())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn migrations_apply_once_and_running_jobs_fail_on_reopen() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("chatter.sqlite");
        let db = Db::open(&path).unwrap();
        assert_eq!(db.schema_version().unwrap(), MIGRATIONS.len() as i64);
        let setup = db
            .add_setup("s", "m", "t", "h", &serde_json::json!({}))
            .unwrap();
        let running = db
            .start_job(setup, "learn", &serde_json::json!({}))
            .unwrap();
        let finished = db
            .start_job(setup, "learn", &serde_json::json!({}))
            .unwrap();
        db.finish_job(finished, "done", Some(&serde_json::json!({"k": 1})), None)
            .unwrap();
        drop(db);
        let db = Db::open(&path).unwrap();
        assert_eq!(db.schema_version().unwrap(), MIGRATIONS.len() as i64);
        let j = db.job(running).unwrap();
        assert_eq!(
            (j.status.as_str(), j.error.as_deref()),
            ("failed", Some(INTERRUPTED))
        );
        assert_eq!(db.job(finished).unwrap().status, "done");
        assert_eq!(db.setups().unwrap().len(), 1);
    }

    #[test]
    fn a_newer_schema_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("chatter.sqlite");
        Connection::open(&path)
            .unwrap()
            .pragma_update(None, "user_version", 99)
            .unwrap();
        let e = Db::open(&path).unwrap_err().to_string();
        assert!(e.contains("schema version 99"), "{e}");
    }
}
