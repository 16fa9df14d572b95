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
use crate::store::folder::LOCK;
use crate::store::made_dirs::MadeDirs;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};

/// How often a writer starts again when a folder it made or found vanished before it opened the
/// lock file in it (another writer removed the empty folder it had made as it let go).
const RETRIES: usize = 100;

/// An exclusive hold on a folder: only one mcbench writes a folder at a time. Released when
/// dropped (the lock file is removed, then closed), and by the system when the process dies (the
/// file of a killed holder stays until the next holder releases it). The folders it made are
/// removed again on release when they are still empty, so a refused command leaves none behind.
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
    #[cfg_attr(not(unix), allow(dead_code))]
    path: PathBuf,
    dir: PathBuf,
    _made: MadeDirs,
}

impl FolderLock {
    /// Creates `dir` if needed and takes its lock; with `wait`, blocks until the holder is done,
    /// else refuses with [`HarnessError::Busy`] (exit 3). Then removes stale temporary files
    /// (`.<name>.tmp-<pid>...`) that killed writers left in `dir` and in `subdirs` of it. A lock
    /// file that is a symbolic link, or not a plain file of one link, is refused (exit 2) and left
    /// as it is: the lock never opens a file outside `dir`, nor writes one. On a refusal the
    /// folders it made are removed again.
    pub fn acquire(dir: &Path, wait: bool, subdirs: &[&str]) -> Result<FolderLock> {
        let path = dir.join(LOCK);
        let io = |e: std::io::Error| HarnessError::write(&path, e);
        let mut made = MadeDirs::default();
        let mut retries = 0;
        let mut file = loop {
            match MadeDirs::create(dir) {
                Ok(m) => made.absorb(m),
                Err(e) if e.kind() == ErrorKind::NotFound && retries < RETRIES => {
                    retries += 1;
                    continue;
                }
                Err(e) => return Err(HarnessError::write(dir, e)),
            }
            let file = match open(&path, true) {
                Ok(f) => f,
                Err(e) if e.kind() == ErrorKind::NotFound && is_link(dir) => {
                    return Err(HarnessError::bad_file(dir, "is a symbolic link to nothing"));
                }
                Err(e) if e.kind() == ErrorKind::NotFound && retries < RETRIES => {
                    retries += 1;
                    continue;
                }
                Err(e) => return Err(refusal(&path, e, |p, e| HarnessError::write(p, e))),
            };
            check_plain(&path, &file)?;
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
        crate::store::folder::remove_stale_temps(dir);
        for s in subdirs {
            crate::store::folder::remove_stale_temps(&dir.join(s));
        }
        Ok(FolderLock { _file: file, path, dir: dir.to_path_buf(), _made: made })
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
        // Removed while still held; closing the file (dropping the field, after this) unlocks it,
        // then the folders it made go if nothing else is in them.
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
/// is a folder the reader cannot write that has no lock file. A lock file that is a symbolic link
/// or not a plain file is refused (exit 2) and left as it is.
pub fn read_lock(dir: &Path, wait: bool) -> Result<Option<ReadLock>> {
    let path = dir.join(LOCK);
    let io = |e: std::io::Error| HarnessError::bad_file(&path, e);
    loop {
        // Read-write (and created) where it can be; read-only, for an existing file, where not.
        let file = match open(&path, true).or_else(|_| open(&path, false)) {
            Ok(f) => f,
            Err(e) if std::fs::symlink_metadata(&path).is_ok_and(|m| !m.is_file()) => {
                return Err(refusal(&path, e, |p, e| HarnessError::bad_file(p, e)))
            }
            Err(_) => return Ok(None),
        };
        check_plain(&path, &file)?;
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

/// Opens the lock file at `path` without following a symbolic link there (the open fails on
/// one): read-write and created if needed with `write`, else read-only. Non-blocking, so that a
/// FIFO in its place cannot hang the open (a lock file is a regular file, where the flag changes
/// nothing: `flock` blocks or not by its own flag).
fn open(path: &Path, write: bool) -> std::io::Result<File> {
    let mut o = OpenOptions::new();
    o.read(true);
    if write {
        o.write(true).create(true).truncate(false);
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    o.open(path)
}

/// Whether `path` is a symbolic link (dangling or not).
fn is_link(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
}

/// The error of a lock file that could not be opened: a symbolic link or a folder in its place is
/// refused (exit 2) naming it; anything else is `other`'s.
fn refusal(path: &Path, e: std::io::Error, other: fn(&Path, std::io::Error) -> HarnessError) -> HarnessError {
    match std::fs::symlink_metadata(path).map(|m| m.file_type()) {
        Ok(t) if t.is_symlink() => HarnessError::bad_file(
            path,
            "is a symbolic link; mcbench does not follow it (a lock file is a plain file it creates): remove it",
        ),
        Ok(t) if !t.is_file() => HarnessError::bad_file(path, NOT_PLAIN),
        _ => other(path, e),
    }
}

/// Why a lock file that is not a regular file is refused.
const NOT_PLAIN: &str = "is not a plain file (mcbench creates it as one): remove it";

/// Refuses (exit 2) an opened lock file that is not a regular file, or that has other hard links
/// (its content would be written through them): mcbench creates it as a plain file of one link.
fn check_plain(path: &Path, file: &File) -> Result<()> {
    let m = file.metadata().map_err(|e| HarnessError::bad_file(path, e))?;
    if !m.is_file() {
        return Err(HarnessError::bad_file(path, NOT_PLAIN));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if m.nlink() > 1 {
            return Err(HarnessError::bad_file(
                path,
                format!("has {} hard links (mcbench creates it with one): remove it", m.nlink()),
            ));
        }
    }
    Ok(())
}

/// Whether `path` still names the open `file` (same device and inode): false once a releaser
/// removed it, or replaced it with a fresh one (or anything else, a symbolic link included).
#[cfg(unix)]
fn names(path: &Path, file: &File) -> std::io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    let held = file.metadata()?;
    match std::fs::symlink_metadata(path) {
        Ok(now) => Ok(now.dev() == held.dev() && now.ino() == held.ino()),
        Err(e) if e.kind() == ErrorKind::NotFound => Ok(false),
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
#[path = "folder_lock_tests.rs"]
mod tests;
