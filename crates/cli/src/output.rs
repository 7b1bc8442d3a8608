//! Output files and folders, checked before the work starts and written atomically.
//!
//! - [`check_file`] and [`check_folder`] run before any computation, so a typo in `--out` never
//!   costs a long run: the parent folder must exist (it is not created silently) and be
//!   writable, and a file path must not be a folder.
//! - [`write_atomic`] writes a file to a temporary name beside it and renames it, so a failed or
//!   killed run never leaves a half-written file; the mode is 0666 less the umask, like any
//!   file a program creates.
//! - [`Folder`] collects the files of a multi-file result in memory and writes them at the end
//!   into a hidden sibling folder that is then renamed into place, so a killed run leaves either
//!   the previous folder or the complete new one, never a mixture.

use anyhow::{Context, Result, bail};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The folder a path is in (`.` for a bare file name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The parent folder of `path` exists and a file can be created in it.
fn check_parent(flag: &str, path: &Path) -> Result<()> {
    let parent = parent_of(path);
    if !parent.is_dir() {
        bail!(
            "{flag} {}: the folder {} does not exist; create it first",
            path.display(),
            parent.display()
        );
    }
    tempfile::Builder::new()
        .prefix(".chatter-probe")
        .tempfile_in(parent)
        .map(drop)
        .map_err(|e| {
            anyhow::anyhow!(
                "{flag} {}: cannot write in {}: {e}",
                path.display(),
                parent.display()
            )
        })
}

/// Check an output file before the work: not a folder, in an existing writable folder.
pub fn check_file(flag: &str, path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!(
            "{flag} {}: is a folder; expected a file name",
            path.display()
        );
    }
    check_parent(flag, path)
}

/// [`check_file`] of an optional output.
pub fn check_optional_file(flag: &str, path: Option<&Path>) -> Result<()> {
    path.map_or(Ok(()), |p| check_file(flag, p))
}

/// Check an output folder before the work: its parent exists and is writable, and if the folder
/// exists already it holds only what this command writes (`known` names), so replacing it loses
/// nothing of the user's.
pub fn check_folder(flag: &str, path: &Path, known: &[&str]) -> Result<()> {
    if path.exists() && !path.is_dir() {
        bail!("{flag} {}: is a file; expected a folder", path.display());
    }
    if path.is_dir() {
        let mut foreign = Vec::new();
        for entry in
            std::fs::read_dir(path).with_context(|| format!("{flag} {}", path.display()))?
        {
            let name = entry
                .with_context(|| format!("{flag} {}", path.display()))?
                .file_name()
                .to_string_lossy()
                .into_owned();
            if !known.contains(&name.as_str()) {
                foreign.push(name);
            }
        }
        if !foreign.is_empty() {
            foreign.sort();
            bail!(
                "{flag} {}: the folder exists and holds files this command does not write ({}); \
                 give a new or empty folder",
                path.display(),
                foreign.join(", ")
            );
        }
    }
    check_parent(flag, path)
}

/// Write `bytes` to `path` atomically (temporary file beside it, then rename). The parent folder
/// must exist ([`check_file`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let dir = parent_of(path);
    let mut tmp = tempfile::Builder::new()
        .prefix(".chatter-")
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes)
        .with_context(|| format!("writing {}", path.display()))?;
    tmp.persist(path)
        .map_err(|e| e.error)
        .with_context(|| format!("moving the result into {}", path.display()))?;
    Ok(())
}

/// Write `text` to `path` atomically, or to stdout when `path` is `None`.
pub fn emit(path: Option<&Path>, text: &str) -> Result<()> {
    match path {
        Some(p) => write_atomic(p, text.as_bytes()),
        None => {
            print!("{text}");
            Ok(())
        }
    }
}

/// The files of a multi-file result, written together by [`Folder::commit`].
pub struct Folder {
    target: PathBuf,
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Folder {
    /// An empty result for the folder `target`, checked with [`check_folder`] against the names
    /// `known` (files and subfolders this command writes).
    pub fn new(flag: &str, target: &Path, known: &[&str]) -> Result<Self> {
        check_folder(flag, target, known)?;
        Ok(Self {
            target: target.to_path_buf(),
            files: Vec::new(),
        })
    }

    /// Add a file at `relative` (may contain a subfolder).
    pub fn add(&mut self, relative: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) {
        self.files.push((relative.into(), bytes.into()));
    }

    /// The bytes added at `relative`, if any (the report page reads the plots back).
    pub fn get(&self, relative: impl AsRef<Path>) -> Option<&[u8]> {
        let relative = relative.as_ref();
        self.files
            .iter()
            .find(|(r, _)| r == relative)
            .map(|(_, bytes)| bytes.as_slice())
    }

    /// The final path of `relative` (for messages).
    pub fn path_of(&self, relative: impl AsRef<Path>) -> PathBuf {
        self.target.join(relative)
    }

    /// The final paths of the files added so far.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.files
            .iter()
            .map(|(relative, _)| self.target.join(relative))
            .collect()
    }

    /// Write every file into a hidden sibling folder, then rename it over the target (the
    /// previous target, if any, is renamed aside first and removed after). Returns the paths
    /// written.
    pub fn commit(self) -> Result<Vec<PathBuf>> {
        let parent = parent_of(&self.target);
        let name = self
            .target
            .file_name()
            .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
        let staging = Staging::create(parent, &format!(".{name}.partial-{}", std::process::id()))?;
        for (relative, bytes) in &self.files {
            let path = staging.0.join(relative);
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("creating {}", dir.display()))?;
            }
            std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
        }
        let old = parent.join(format!(".{name}.old-{}", std::process::id()));
        let replaced = self.target.is_dir();
        if replaced {
            std::fs::rename(&self.target, &old)
                .with_context(|| format!("moving the previous {} aside", self.target.display()))?;
        }
        if let Err(e) = std::fs::rename(&staging.0, &self.target) {
            if replaced {
                // put the previous result back
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(e)
                .with_context(|| format!("moving the result into {}", self.target.display()));
        }
        staging.keep();
        if replaced {
            std::fs::remove_dir_all(&old)
                .with_context(|| format!("removing the previous result {}", old.display()))?;
        }
        Ok(self.paths())
    }
}

/// A staging folder removed on drop unless kept.
struct Staging(PathBuf);

impl Staging {
    fn create(parent: &Path, name: &str) -> Result<Self> {
        let path = parent.join(name);
        std::fs::create_dir(&path).with_context(|| format!("creating {}", path.display()))?;
        Ok(Self(path))
    }
    fn keep(mut self) {
        self.0 = PathBuf::new();
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.0.as_os_str().is_empty() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_replaces_its_previous_result_and_refuses_foreign_files() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        let mut f = Folder::new("--out", &target, &["a.txt", "sub"]).unwrap();
        f.add("a.txt", "one");
        f.add("sub/b.txt", "two");
        f.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("sub/b.txt")).unwrap(),
            "two"
        );
        let mut f = Folder::new("--out", &target, &["a.txt", "sub"]).unwrap();
        f.add("a.txt", "three");
        f.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("a.txt")).unwrap(),
            "three"
        );
        assert!(!target.join("sub").exists());
        std::fs::write(target.join("mine.txt"), "keep").unwrap();
        let e = Folder::new("--out", &target, &["a.txt"]).err().unwrap();
        assert!(e.to_string().contains("mine.txt"), "{e}");
        // nothing but the result is left in the parent
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_missing_parent_is_an_error_before_the_work() {
        let dir = tempfile::tempdir().unwrap();
        let e = check_file("--out", &dir.path().join("no/such/file.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not exist"), "{e}");
        assert!(check_file("--out", dir.path()).is_err());
    }
}
