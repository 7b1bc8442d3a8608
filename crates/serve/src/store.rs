//! The data folder (`--data`): `chatter.sqlite`, uploaded files under `files/` by generated
//! names, and `tmp/` where an upload waits while it is checked.
//!
//! An upload is checked before anything is kept: its name must be a plain file name with an
//! allowed extension (the name is shown, never used as a path: only the extension is kept, in
//! the generated name), its size within [`MAX_UPLOAD_BYTES`], its bytes of the declared kind
//! (text for CSV, JSON and the text FRF formats; a RIFF/WAVE header for WAV; an MPEG frame or ID3
//! tag for MP3). The bytes are then staged under `tmp/` and parsed there by the science crates'
//! readers; only a file that parses and computes is renamed into `files/` and recorded in the
//! database. A refused upload leaves neither a file nor a row ([`Staged`] removes its file when
//! dropped), and files that a crash left between the rename and the database commit are removed
//! when the folder is opened again ([`DataDir::remove_orphans`]).

use crate::error::{Result, ServeError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The largest upload kept (bytes): 8 MiB, a minute of 48 kHz stereo 16-bit WAV is 11 MiB, so a
/// recording longer than about 40 s must be cut; tap tests and models are far smaller.
pub const MAX_UPLOAD_BYTES: usize = 8 * 1024 * 1024;

/// Longest file name shown (characters).
const MAX_NAME_CHARS: usize = 200;

/// What an upload is for, with the extensions it takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UploadKind {
    /// A tap-test FRF: `.csv`, `.uff`/`.unv` (dataset 58), `.frf` (CutPro), `.txt`.
    Frf,
    /// A model file (`.json`).
    Model,
    /// A cut's recording: `.wav`, `.mp3`, `.csv`.
    Recording,
    /// An observations file (`.json`) or a cuts table (`.csv`).
    Observations,
}

impl UploadKind {
    /// The database's name of the kind.
    pub fn name(self) -> &'static str {
        match self {
            Self::Frf => "frf",
            Self::Model => "model",
            Self::Recording => "recording",
            Self::Observations => "observations",
        }
    }

    /// The extensions taken.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Self::Frf => &["csv", "uff", "unv", "frf", "txt"],
            Self::Model => &["json"],
            Self::Recording => &["wav", "mp3", "csv"],
            Self::Observations => &["json", "csv"],
        }
    }
}

/// A file as the browser sent it.
#[derive(Debug, Clone)]
pub struct Upload {
    /// The name the user's file had.
    pub name: String,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

/// Check an upload's name, size and bytes for `kind`; the extension it is stored with.
pub fn check(upload: &Upload, kind: UploadKind) -> Result<&'static str> {
    let name = upload.name.as_str();
    let bad = |message: String| Err(ServeError::bad("file", message));
    if name.is_empty() {
        return bad("no file chosen".into());
    }
    if name.chars().count() > MAX_NAME_CHARS {
        return bad(format!(
            "a name of {} characters; expected at most {MAX_NAME_CHARS}",
            name.chars().count()
        ));
    }
    if name.contains(['/', '\\', ':'])
        || name.starts_with('.')
        || name.chars().any(char::is_control)
    {
        return bad(format!(
            "name `{}`: expected a plain file name (no folders, drive letters or leading dot); \
             the file is stored under a generated name anyway",
            name.escape_debug()
        ));
    }
    let allowed = kind.extensions();
    let extension = name
        .rsplit_once('.')
        .map(|(_, e)| e.to_ascii_lowercase())
        .unwrap_or_default();
    let Some(&extension) = allowed.iter().find(|e| **e == extension) else {
        return bad(format!(
            "`{name}`: a {} file must end in {}",
            kind.name(),
            allowed
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    };
    if upload.bytes.is_empty() {
        return bad(format!("`{name}` is empty (0 bytes)"));
    }
    if upload.bytes.len() > MAX_UPLOAD_BYTES {
        return bad(format!(
            "`{name}` has {:.1} MiB; the limit is {} MiB",
            upload.bytes.len() as f64 / 1048576.0,
            MAX_UPLOAD_BYTES / 1048576
        ));
    }
    let text = || {
        std::str::from_utf8(&upload.bytes)
            .ok()
            .filter(|t| !t.contains('\0'))
            .is_some()
    };
    let ok = match extension {
        "wav" => {
            upload.bytes.len() >= 12
                && &upload.bytes[0..4] == b"RIFF"
                && &upload.bytes[8..12] == b"WAVE"
        }
        "mp3" => {
            upload.bytes.starts_with(b"ID3")
                || (upload.bytes.len() >= 2
                    && upload.bytes[0] == 0xff
                    && upload.bytes[1] & 0xe0 == 0xe0)
        }
        // universal files may be binary (dataset 58b); their reader judges them
        "uff" | "unv" => true,
        _ => text(),
    };
    if !ok {
        return bad(format!(
            "`{name}` is not a {} file: {}",
            extension.to_ascii_uppercase(),
            match extension {
                "wav" => "no RIFF/WAVE header",
                "mp3" => "no ID3 tag or MPEG frame at its start",
                _ => "expected UTF-8 text",
            }
        ));
    }
    Ok(extension)
}

/// The data folder.
#[derive(Debug, Clone)]
pub struct DataDir {
    root: PathBuf,
}

static COUNTER: AtomicU64 = AtomicU64::new(0);

impl DataDir {
    /// Create (if needed) `root` with `files/` and `tmp/`, and empty `tmp/` (uploads a stopped
    /// server was checking).
    pub fn open(root: &Path) -> Result<Self> {
        for dir in [root.to_path_buf(), root.join("files"), root.join("tmp")] {
            std::fs::create_dir_all(&dir).map_err(|e| ServeError::io(&dir, e))?;
        }
        let tmp = root.join("tmp");
        let entries = std::fs::read_dir(&tmp).map_err(|e| ServeError::io(&tmp, e))?;
        for entry in entries.flatten() {
            let _ = std::fs::remove_file(entry.path());
        }
        Ok(Self {
            root: root.to_path_buf(),
        })
    }

    /// The database file.
    pub fn database(&self) -> PathBuf {
        self.root.join("chatter.sqlite")
    }

    /// Write `bytes` under `tmp/` by a generated name with `extension`.
    pub fn stage(&self, kind: UploadKind, extension: &str, bytes: &[u8]) -> Result<Staged> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64);
        let stored_name = format!(
            "{}-{nanos:x}-{:x}-{:x}.{extension}",
            kind.name(),
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let path = self.root.join("tmp").join(&stored_name);
        std::fs::write(&path, bytes).map_err(|e| ServeError::io(&path, e))?;
        Ok(Staged {
            path,
            stored_name,
            files: self.root.join("files"),
            kept: false,
        })
    }

    /// Remove the files under `files/` that the database does not know (`known` stored names):
    /// what a crash between an upload's rename and its database commit left.
    pub fn remove_orphans(&self, known: &std::collections::HashSet<String>) -> Result<usize> {
        let dir = self.root.join("files");
        let mut removed = 0;
        for entry in std::fs::read_dir(&dir)
            .map_err(|e| ServeError::io(&dir, e))?
            .flatten()
        {
            let name = entry.file_name().to_string_lossy().into_owned();
            if !known.contains(&name) && std::fs::remove_file(entry.path()).is_ok() {
                removed += 1;
            }
        }
        Ok(removed)
    }
}

/// An upload under `tmp/`: removed when dropped unless [`Staged::keep`] moved it to `files/`.
#[derive(Debug)]
pub struct Staged {
    /// Where it lies now (what the readers open).
    pub path: PathBuf,
    /// Its generated name.
    pub stored_name: String,
    files: PathBuf,
    kept: bool,
}

impl Staged {
    /// Move it to `files/`; the database row is written next, and [`Kept::forget`] undoes the
    /// move when that fails.
    pub fn keep(mut self) -> Result<Kept> {
        let to = self.files.join(&self.stored_name);
        std::fs::rename(&self.path, &to).map_err(|e| ServeError::io(&to, e))?;
        self.kept = true;
        Ok(Kept { path: to })
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.kept {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// A file moved to `files/`.
#[derive(Debug)]
pub struct Kept {
    path: PathBuf,
}

impl Kept {
    /// Remove it again (its database row could not be written).
    pub fn forget(self) {
        let _ = std::fs::remove_file(&self.path);
    }
}
