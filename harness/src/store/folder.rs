//! Result and plot folders as a whole (book: outputs.md): output paths checked before a run starts, one
//! writer per folder at a time (a lock, [`FolderLock`], whose file is there only while it is
//! held), stale temporary files of killed writers removed, and a folder-level commit so that a
//! reader never mixes the files of two runs.
//!
//! Every file a run writes goes through an [`OutputDir`], which writes it atomically (temp file +
//! rename) and records its size and digest. When the run has written everything it writes
//! `commit.json` (atomically, last): the list of its files. A reader ([`verify`]) refuses a folder
//! whose files do not match its commit: two runs interleaved, or a run killed between two of its
//! writes, leave such a folder, and the next run of the experiment rewrites it whole.

use crate::error::{HarnessError, Result};
pub use crate::store::folder_lock::{read_lock, FolderLock, ReadLock};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The commit file of a folder.
pub const COMMIT: &str = "commit.json";
/// The lock file of a folder (there only while a run holds the folder: see [`FolderLock`]).
pub const LOCK: &str = ".lock";
/// The format of [`Commit`].
pub const COMMIT_FORMAT: u32 = 1;

/// FNV-1a over bytes, as 16 hex digits (a consistency digest, not a cryptographic one).
pub fn digest(bytes: &[u8]) -> String {
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3));
    format!("{h:016x}")
}

/// Checks, without creating anything, that `path` is or can become a writable folder: it is a
/// folder, or it does not exist and its nearest existing ancestor is a folder. `field` names the
/// flag in the error (`--results`, `--plots`).
pub fn check_output_dir(field: &'static str, path: &Path) -> Result<()> {
    let mut p = path.to_path_buf();
    loop {
        match std::fs::metadata(&p) {
            Ok(m) if m.is_dir() => {
                if m.permissions().readonly() {
                    return Err(HarnessError::bad_output(field, path, format!("{} is read-only", p.display())));
                }
                return Ok(());
            }
            Ok(_) if p == path => return Err(HarnessError::bad_output(field, path, "is a file, not a folder")),
            Ok(_) => {
                return Err(HarnessError::bad_output(field, path, format!("{} is a file, not a folder", p.display())))
            }
            Err(e) if matches!(e.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory) => {}
            Err(e) => return Err(HarnessError::bad_output(field, path, e)),
        }
        match p.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => p = parent.to_path_buf(),
            _ => return Ok(()),
        }
    }
}

/// Checks a folder mcbench names below a root the user gave (`<results>/<experiment>`, a shard
/// folder, `<plots>/<experiment>`, `<results>/references`): as [`check_output_dir`], and it is not
/// a symbolic link (dangling or not), which would have the run write outside the folders named.
/// `field` names the flag of the root.
pub fn check_own_dir(field: &'static str, path: &Path) -> Result<()> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(HarnessError::bad_output(
            field,
            path,
            "is a symbolic link; mcbench writes into real folders below the one named, never through a link: remove it",
        ));
    }
    check_output_dir(field, path)
}

/// Whether `name` is a temporary file of an atomic write (`.<name>.tmp-<pid>[...]`).
fn is_temp(name: &str) -> bool {
    name.starts_with('.') && name.contains(".tmp-")
}

/// Removes the temporary files of killed writers directly in `dir` (call with the lock held:
/// every writer of the folder holds it, so any temporary file there is stale).
pub(crate) fn remove_stale_temps(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        // A symbolic link by that name goes too (the link, not what it points to).
        let plain = e.file_type().is_ok_and(|t| t.is_file() || t.is_symlink());
        if e.file_name().to_str().is_some_and(is_temp) && plain {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// One file of a commit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CommittedFile {
    /// File name inside the folder (no path separators).
    pub name: String,
    /// Size in bytes.
    pub bytes: u64,
    /// [`digest`] of its content.
    pub digest: String,
}

/// `commit.json`: the files a finished run wrote into a folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Commit {
    /// [`COMMIT_FORMAT`].
    pub format: u32,
    /// The run's id (also `meta.run_id` in summary.json).
    pub run: String,
    /// For a plots folder: the id of the results it was drawn from.
    #[serde(default)]
    pub source_run: Option<String>,
    /// The files, in the order written.
    pub files: Vec<CommittedFile>,
}

/// A folder a run writes into: every write is atomic and recorded for the commit.
#[derive(Debug)]
pub struct OutputDir {
    dir: PathBuf,
    files: Mutex<Vec<CommittedFile>>,
}

impl OutputDir {
    /// A writer into `dir` (created on the first write).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        OutputDir { dir: dir.into(), files: Mutex::new(Vec::new()) }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// `<dir>/<name>`.
    pub fn join(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    fn note(&self, name: String, bytes: &[u8]) {
        let entry = CommittedFile { name, bytes: bytes.len() as u64, digest: digest(bytes) };
        if let Ok(mut files) = self.files.lock() {
            files.retain(|f| f.name != entry.name);
            files.push(entry);
        }
    }

    /// Writes `<dir>/<name>` atomically and records it.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf> {
        let path = self.dir.join(name);
        crate::output::write_atomic(&path, bytes)?;
        self.note(name.to_string(), bytes);
        Ok(path)
    }

    /// Writes `rows` as `<dir>/<name>` with the csv crate (a header from the row type's field
    /// names, one record per row), atomically, and records it.
    pub fn write_csv<T: serde::Serialize>(&self, name: &str, rows: &[T]) -> Result<PathBuf> {
        let path = self.dir.join(name);
        let mut w = csv::Writer::from_writer(Vec::new());
        for r in rows {
            w.serialize(r).map_err(|e| HarnessError::write(&path, e))?;
        }
        let bytes = w.into_inner().map_err(|e| HarnessError::write(&path, e))?;
        self.write(name, &bytes)
    }

    /// Records a file that was written into the folder by other means (the PNG encoder writes its
    /// own files; they are renamed into place atomically, then read back here for the digest).
    pub fn record(&self, path: &Path) -> Result<()> {
        let name = path
            .strip_prefix(&self.dir)
            .ok()
            .and_then(|p| p.to_str())
            .filter(|n| !n.contains('/'))
            .ok_or_else(|| HarnessError::write(path, format!("not directly in {}", self.dir.display())))?;
        let bytes = std::fs::read(path).map_err(|e| HarnessError::write(path, e))?;
        self.note(name.to_string(), &bytes);
        Ok(())
    }

    /// Writes `commit.json`, last: the run's files become one consistent set for readers.
    pub fn commit(&self, run: &str, source_run: Option<&str>) -> Result<()> {
        let files = self.files.lock().map(|f| f.clone()).unwrap_or_default();
        let commit =
            Commit { format: COMMIT_FORMAT, run: run.to_string(), source_run: source_run.map(String::from), files };
        let text = serde_json::to_string_pretty(&commit).map_err(|e| HarnessError::write(self.join(COMMIT), e))?;
        crate::output::write_atomic(&self.join(COMMIT), text.as_bytes())
    }
}

/// Reads `<dir>/commit.json` and checks that every file it lists is there with its committed
/// size and digest, and that `required` files are among them. A folder without a commit (an
/// unfinished first run, or written by another program) or with files of another run is refused.
pub fn verify(dir: &Path, required: &[&str]) -> Result<Commit> {
    let path = dir.join(COMMIT);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        let why = if e.kind() == std::io::ErrorKind::NotFound {
            "missing: not the folder of a finished run (re-run the experiment to finish it)".to_string()
        } else {
            e.to_string()
        };
        HarnessError::bad_file(&path, why)
    })?;
    let commit: Commit =
        serde_json::from_str(&text).map_err(|e| HarnessError::bad_file(&path, format!("corrupt ({e})")))?;
    if commit.format != COMMIT_FORMAT {
        return Err(HarnessError::bad_file(
            &path,
            format!("format {} (this mcbench reads {COMMIT_FORMAT})", commit.format),
        ));
    }
    for f in &commit.files {
        let plain = !f.name.is_empty()
            && !f.name.starts_with('.')
            && !f.name.contains(['/', '\\'])
            && Path::new(&f.name).file_name().is_some_and(|n| n == f.name.as_str());
        if !plain {
            return Err(HarnessError::bad_file(&path, format!("corrupt (file name {:?} is not a plain name)", f.name)));
        }
        let file = dir.join(&f.name);
        let bytes = std::fs::read(&file).map_err(|e| {
            HarnessError::bad_file(
                &path,
                format!("lists {} but it cannot be read ({e}); re-run the experiment", f.name),
            )
        })?;
        if bytes.len() as u64 != f.bytes || digest(&bytes) != f.digest {
            return Err(HarnessError::bad_file(
                &file,
                "mixed folder: this file is not the one the last finished run committed (another run wrote it, or a run was killed while writing); re-run the experiment",
            ));
        }
    }
    for r in required {
        if !commit.files.iter().any(|f| f.name == *r) {
            return Err(HarnessError::bad_file(&path, format!("corrupt (does not list {r})")));
        }
    }
    Ok(commit)
}

/// A fresh run id: a digest of the experiment, the process and the time.
pub fn run_id(experiment: &str) -> String {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0);
    digest(format!("{experiment}:{}:{nanos}", std::process::id()).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_commit_verifies_until_a_file_changes() {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = OutputDir::new(dir.path().join("r"));
        out.write("a.csv", b"x,y\n1,2\n").expect("write");
        out.write("b.json", b"{}").expect("write");
        out.commit("run1", None).expect("commit");
        let c = verify(out.path(), &["a.csv"]).expect("consistent");
        assert_eq!(c.files.len(), 2);
        assert!(verify(out.path(), &["c.csv"]).is_err(), "a required file that is not listed");
        std::fs::write(out.join("a.csv"), b"x,y\n1,3\n").expect("overwrite");
        let e = verify(out.path(), &[]).expect_err("mixed");
        assert!(e.to_string().contains("mixed folder") && e.exit_code() == 2, "{e}");
    }

    #[test]
    fn a_second_lock_is_refused_and_stale_temps_are_removed() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path().join("r");
        std::fs::create_dir_all(d.join("sub")).expect("dirs");
        std::fs::write(d.join(".summary.csv.tmp-123"), b"half").expect("temp");
        std::fs::write(d.join("sub/.x.json.tmp-9"), b"half").expect("temp");
        let lock = FolderLock::acquire(&d, false, &["sub"]).expect("free");
        assert!(!d.join(".summary.csv.tmp-123").exists() && !d.join("sub/.x.json.tmp-9").exists());
        let e = FolderLock::acquire(&d, false, &[]).expect_err("held");
        assert_eq!(e.exit_code(), 3, "{e}");
        assert!(read_lock(&d, false).is_err(), "a reader waits for the writer");
        drop(lock);
        assert!(FolderLock::acquire(&d, false, &[]).is_ok());
        assert!(read_lock(&d, false).expect("free").is_some());
    }

    #[test]
    #[cfg(unix)]
    fn temp_files_are_never_written_through_a_link() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path().join("r");
        std::fs::create_dir(&d).expect("folder");
        let outside = dir.path().join("outside");
        std::fs::write(&outside, b"precious").expect("file");
        // A link where this process's next temp file goes, and a dangling one a killed writer's
        // name: the write replaces the first, the lock removes the second, neither is followed.
        let tmp = d.join(format!(".a.csv.tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(&outside, &tmp).expect("link");
        crate::output::write_atomic(&d.join("a.csv"), b"x,y\n").expect("written");
        assert_eq!(std::fs::read(&outside).expect("outside"), b"precious");
        assert!(std::fs::symlink_metadata(&tmp).is_err(), "the temp name is free again");
        let stale = d.join(".b.csv.tmp-4242");
        std::os::unix::fs::symlink(dir.path().join("gone"), &stale).expect("link");
        drop(FolderLock::acquire(&d, false, &[]).expect("free"));
        assert!(std::fs::symlink_metadata(&stale).is_err(), "removed");
        assert!(!dir.path().join("gone").exists());
    }

    #[test]
    #[cfg(unix)]
    fn folders_below_a_root_are_not_links() {
        let dir = tempfile::tempdir().expect("tempdir");
        let elsewhere = dir.path().join("elsewhere");
        std::fs::create_dir(&elsewhere).expect("folder");
        let root = dir.path().join("results");
        std::fs::create_dir(&root).expect("root");
        std::os::unix::fs::symlink(&elsewhere, root.join("to-folder")).expect("link");
        std::os::unix::fs::symlink(dir.path().join("gone"), root.join("dangling")).expect("link");
        for name in ["to-folder", "dangling"] {
            let e = check_own_dir("--results", &root.join(name)).expect_err("a link");
            assert!(e.exit_code() == 2 && e.to_string().contains("is a symbolic link"), "{e}");
        }
        assert!(check_own_dir("--results", &root.join("new")).is_ok());
        // The root itself may be a link: the user named it.
        let linked_root = dir.path().join("linked");
        std::os::unix::fs::symlink(&elsewhere, &linked_root).expect("link");
        assert!(check_own_dir("--results", &linked_root.join("x")).is_ok());
    }

    #[test]
    fn output_paths_must_be_folders() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("f");
        std::fs::write(&file, b"").expect("file");
        assert!(check_output_dir("--plots", &file).is_err());
        assert!(check_output_dir("--plots", &file.join("below")).is_err());
        assert!(check_output_dir("--plots", &dir.path().join("new/deeper")).is_ok());
        assert!(!dir.path().join("new").exists(), "nothing is created");
    }
}
