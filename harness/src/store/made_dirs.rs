//! Folders a writer creates, removed again when it lets go of them empty: a refused or failed
//! command leaves no new empty folder behind (the folders of a lock that was refused, or of a
//! results folder whose plots folder another run holds).

use std::path::{Path, PathBuf};

/// The folders [`MadeDirs::create`] made, deepest first. Dropping it removes those that are still
/// empty, deepest first, and stops at the first one that is not (a folder this process did not
/// make is never removed; neither is one that holds anything).
#[derive(Debug, Default)]
pub struct MadeDirs(Vec<PathBuf>);

impl MadeDirs {
    /// Creates `dir` and the ancestors it lacks, recording those this call made. A folder that
    /// appears meanwhile (another process made it) is used as it is and not recorded. On an error
    /// the folders made so far are removed again.
    pub fn create(dir: &Path) -> std::io::Result<MadeDirs> {
        let mut missing = Vec::new();
        let mut p = dir;
        loop {
            match std::fs::symlink_metadata(p) {
                Ok(_) => break,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => missing.push(p.to_path_buf()),
                Err(e) => return Err(e),
            }
            match p.parent() {
                Some(parent) if !parent.as_os_str().is_empty() => p = parent,
                _ => break,
            }
        }
        let mut made = MadeDirs::default();
        for d in missing.iter().rev() {
            match std::fs::create_dir(d) {
                Ok(()) => made.0.insert(0, d.clone()),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
                Err(e) => return Err(e),
            }
        }
        Ok(made)
    }

    /// Takes over the folders `later` made (removed before these: they may lie inside them).
    pub fn absorb(&mut self, mut later: MadeDirs) {
        later.0.append(&mut self.0);
        self.0 = std::mem::take(&mut later.0);
    }
}

impl Drop for MadeDirs {
    fn drop(&mut self) {
        for d in &self.0 {
            // Fails on a folder that is not empty: its parents are not either.
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_folders_made_and_left_empty_are_removed() {
        let dir = tempfile::tempdir().expect("tempdir");
        let top = dir.path().join("a");
        let made = MadeDirs::create(&top.join("b/c")).expect("made");
        assert!(top.join("b/c").is_dir());
        drop(made);
        assert!(!top.exists(), "all three were made here and left empty");
        // A folder that was there is kept; a made one that holds a file is kept, with its parents.
        std::fs::create_dir(&top).expect("there before");
        let made = MadeDirs::create(&top.join("b/c")).expect("made");
        std::fs::write(top.join("b/kept"), b"x").expect("file");
        drop(made);
        assert!(!top.join("b/c").exists() && top.join("b/kept").exists());
        // Absorbed folders go with the others, the later ones first.
        let mut first = MadeDirs::create(&top.join("x")).expect("made");
        first.absorb(MadeDirs::create(&top.join("x/y/z")).expect("made"));
        drop(first);
        assert!(!top.join("x").exists() && top.exists());
        // A file in the way: an error, and nothing made.
        std::fs::write(top.join("file"), b"x").expect("file");
        assert!(MadeDirs::create(&top.join("file/below")).is_err());
        assert_eq!(std::fs::read_dir(&top).expect("top").count(), 2, "only b and file");
    }
}
