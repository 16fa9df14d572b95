//! The lock of a folder (book: outputs.md): one writer at a time, or any number of readers, through an
//! advisory `flock` on `<dir>/.lock`, a file that exists only while someone holds it.
//!
//! The file is removed on release (unlink, then close), so a finished folder holds no lock file.
//! Whoever takes the lock therefore checks, once it holds the `flock`, that the path still names
//! the file it opened: if a releaser unlinked it meanwhile, the hold is on a file no one else will
//! ever open, and it starts again on a fresh one. Only a holder of the exclusive lock on the file
//! the path names removes it, so the path keeps naming a held lock file for as long as it is held.
//! The lock is taken on a regular file opened read-write (on NFS `flock` is emulated with `fcntl`
//! locks, which need a writable descriptor for an exclusive lock).

use crate::error::{HarnessError, Result};
use crate::folder::LOCK;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// An exclusive hold on a folder: only one mcbench writes a folder at a time. Released when
/// dropped (the lock file is removed, then closed), and by the system when the process dies (the
/// file of a killed holder stays until the next holder releases it).
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
    #[cfg_attr(not(unix), allow(dead_code))]
    path: PathBuf,
    dir: PathBuf,
}

impl FolderLock {
    /// Creates `dir` if needed and takes its lock; with `wait`, blocks until the holder is done,
    /// else refuses with [`HarnessError::Busy`] (exit 3). Then removes stale temporary files
    /// (`.<name>.tmp-<pid>...`) that killed writers left in `dir` and in `subdirs` of it.
    pub fn acquire(dir: &Path, wait: bool, subdirs: &[&str]) -> Result<FolderLock> {
        std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
        let path = dir.join(LOCK);
        let io = |e: std::io::Error| HarnessError::write(&path, e);
        let mut file = loop {
            let file = open(&path).map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) if wait => file.lock().map_err(io)?,
                Err(TryLockError::WouldBlock) if !names(&path, &file).map_err(io)? => continue,
                Err(TryLockError::WouldBlock) => return Err(busy(dir, &file)),
                Err(TryLockError::Error(e)) => return Err(io(e)),
            }
            if names(&path, &file).map_err(io)? {
                break file;
            }
        };
        // The holder's pid, for the message of a refused second run.
        let _ = file.set_len(0).and_then(|()| write!(file, "{}", std::process::id()));
        crate::folder::remove_stale_temps(dir);
        for s in subdirs {
            crate::folder::remove_stale_temps(&dir.join(s));
        }
        Ok(FolderLock { _file: file, path, dir: dir.to_path_buf() })
    }

    /// The locked folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

// Elsewhere an open file cannot be removed: the lock file stays there, as it always did.
#[cfg(unix)]
impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still held; closing the file (dropping the field, after this) unlocks it.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A shared hold on a folder for reading (see [`read_lock`]); released when dropped.
#[derive(Debug)]
#[cfg_attr(not(unix), allow(dead_code))]
pub struct ReadLock {
    file: File,
    path: PathBuf,
}

// Elsewhere the lock file stays there, as it always did.
#[cfg(unix)]
impl Drop for ReadLock {
    fn drop(&mut self) {
        // The last reader out removes the file: the hold turns exclusive without waiting only if
        // no one else holds it (then removed, then closed). Otherwise it is just closed: another
        // reader still holds it, and a later holder removes it.
        if self.file.try_lock().is_ok() && names(&self.path, &self.file).unwrap_or(false) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// A shared hold on a folder for reading: no writer can hold it meanwhile; with `wait`, blocks
/// until the writer is done, else refuses with [`HarnessError::Busy`] (exit 3). The reader creates
/// the lock file if no one holds the folder now, and the last holder out removes it again. A
/// folder that does not exist is read without a lock and stays missing (nothing is created); so
/// is a folder the reader cannot write that has no lock file.
pub fn read_lock(dir: &Path, wait: bool) -> Result<Option<ReadLock>> {
    let path = dir.join(LOCK);
    let io = |e: std::io::Error| HarnessError::bad_file(&path, e);
    loop {
        // Read-write (and created) where it can be; read-only, for an existing file, where not.
        let Ok(file) = open(&path).or_else(|_| File::open(&path)) else { return Ok(None) };
        match file.try_lock_shared() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) if wait => file.lock_shared().map_err(io)?,
            Err(TryLockError::WouldBlock) if !names(&path, &file).map_err(io)? => continue,
            Err(TryLockError::WouldBlock) => return Err(busy(dir, &file)),
            Err(TryLockError::Error(e)) => return Err(io(e)),
        }
        if names(&path, &file).map_err(io)? {
            return Ok(Some(ReadLock { file, path }));
        }
    }
}

/// Opens (creating it if needed) the lock file at `path`, read-write.
fn open(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().create(true).truncate(false).read(true).write(true).open(path)
}

/// Whether `path` still names the open `file` (same device and inode): false once a releaser
/// removed it, or replaced it with a fresh one.
#[cfg(unix)]
fn names(path: &Path, file: &File) -> std::io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    let held = file.metadata()?;
    match std::fs::metadata(path) {
        Ok(now) => Ok(now.dev() == held.dev() && now.ino() == held.ino()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(e) => Err(e),
    }
}

/// Elsewhere the lock file is never removed, so the path always names the file opened.
#[cfg(not(unix))]
fn names(_path: &Path, _file: &File) -> std::io::Result<bool> {
    Ok(true)
}

/// The refusal of a folder whose lock `file` someone else holds, naming the pid it wrote.
fn busy(dir: &Path, mut file: &File) -> HarnessError {
    let mut holder = String::new();
    let _ = file.read_to_string(&mut holder);
    let holder = holder.trim();
    let holder = if holder.is_empty() { "unknown".to_string() } else { holder.to_string() };
    HarnessError::Busy { path: dir.to_path_buf(), holder }
}

// The removal of the file is what they check, and it happens on unix only.
#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

    #[test]
    fn a_released_lock_leaves_no_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path().join("r");
        let lock = FolderLock::acquire(&d, false, &[]).expect("free");
        let pid = std::fs::read_to_string(d.join(LOCK)).expect("held: the file is there");
        assert_eq!(pid, std::process::id().to_string());
        let e = FolderLock::acquire(&d, false, &[]).expect_err("held");
        assert_eq!(e.exit_code(), 3, "{e}");
        assert!(e.to_string().contains(&format!("(pid {pid})")), "{e}");
        drop(lock);
        assert!(!d.join(LOCK).exists(), "released");
        assert!(std::fs::read_dir(&d).expect("folder").next().is_none(), "nothing left in the folder");
        drop(FolderLock::acquire(&d, false, &[]).expect("free again"));
        assert!(!d.join(LOCK).exists());
    }

    #[test]
    fn the_last_reader_out_removes_the_file_and_a_missing_folder_stays_missing() {
        let dir = tempfile::tempdir().expect("tempdir");
        let missing = dir.path().join("missing");
        assert!(read_lock(&missing, false).expect("no folder").is_none());
        assert!(!missing.exists(), "nothing is created");
        let d = dir.path().join("r");
        std::fs::create_dir(&d).expect("folder");
        let first = read_lock(&d, false).expect("free").expect("created");
        let second = read_lock(&d, false).expect("readers share").expect("opened");
        let e = FolderLock::acquire(&d, false, &[]).expect_err("readers hold it");
        assert_eq!(e.exit_code(), 3, "{e}");
        drop(first);
        assert!(d.join(LOCK).exists(), "another reader still holds it");
        drop(second);
        assert!(!d.join(LOCK).exists(), "the last reader out removes it");
        // A stale file (a killed holder's, whose flock the system released) is taken over and
        // removed on release, by a writer or by a lone reader.
        std::fs::write(d.join(LOCK), b"12345").expect("stale");
        let lock = FolderLock::acquire(&d, false, &[]).expect("free");
        assert_eq!(std::fs::read_to_string(d.join(LOCK)).expect("held"), std::process::id().to_string());
        drop(lock);
        assert!(!d.join(LOCK).exists());
        std::fs::write(d.join(LOCK), b"12345").expect("stale");
        drop(read_lock(&d, false).expect("free").expect("opened"));
        assert!(!d.join(LOCK).exists());
    }

    #[test]
    fn writers_never_overlap_each_other_or_readers() {
        const WRITERS: usize = 4;
        const READERS: usize = 2;
        const ROUNDS: usize = 100;
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path().join("r");
        std::fs::create_dir(&d).expect("folder");
        let writing = AtomicBool::new(false);
        let reading = AtomicUsize::new(0);
        let count = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..WRITERS {
                s.spawn(|| {
                    for _ in 0..ROUNDS {
                        let lock = FolderLock::acquire(&d, true, &[]).expect("waits");
                        assert!(!writing.swap(true, Ordering::SeqCst), "two writers inside");
                        assert_eq!(reading.load(Ordering::SeqCst), 0, "a reader inside with a writer");
                        // A read-modify-write that loses counts if two writers interleave.
                        let n = count.load(Ordering::SeqCst);
                        std::thread::yield_now();
                        count.store(n + 1, Ordering::SeqCst);
                        writing.store(false, Ordering::SeqCst);
                        drop(lock);
                    }
                });
            }
            for _ in 0..READERS {
                s.spawn(|| {
                    for _ in 0..ROUNDS {
                        let lock = read_lock(&d, true).expect("waits").expect("the folder exists");
                        reading.fetch_add(1, Ordering::SeqCst);
                        assert!(!writing.load(Ordering::SeqCst), "a writer inside with a reader");
                        std::thread::yield_now();
                        reading.fetch_sub(1, Ordering::SeqCst);
                        drop(lock);
                    }
                });
            }
        });
        assert_eq!(count.load(Ordering::SeqCst), WRITERS * ROUNDS);
        assert!(!d.join(LOCK).exists(), "the last one out removed the lock file");
    }
}
