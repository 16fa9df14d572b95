//! Named baselines: copies of a run's results folders kept under
//! `<results>/baselines/NAME/<experiment>` (`run --save-baseline NAME`), to compare later runs
//! against (`run --baseline NAME`, `compare NAME B`). Saving replaces, experiment by experiment,
//! the folders of the experiments the run wrote and keeps the baseline's others; each folder is
//! copied into a temporary folder beside it and renamed into place, so a baseline folder is
//! always a whole finished run.

use super::load::{plain_name, BASELINES};
use crate::error::{HarnessError, Result};
use std::path::{Path, PathBuf};

/// Refuses a baseline name that is not a plain name (`field`: the flag).
pub fn check_name(field: &'static str, name: &str) -> Result<()> {
    if plain_name(name) {
        Ok(())
    } else {
        Err(mcbench_core::error::ConfigError::invalid(
            field,
            name,
            "must be a plain name: letters, digits, '-', '_' and '.', at most 64 characters, not starting with '.'",
        )
        .into())
    }
}

/// The folder of baseline `name` below `results`.
pub fn folder(results: &Path, name: &str) -> PathBuf {
    results.join(BASELINES).join(name)
}

/// Checks, before a run writes anything, that baseline `name` can be saved below `results`: a
/// plain name, and neither `baselines` nor its folder a symbolic link or a file.
pub fn check_save(results: &Path, name: &str) -> Result<()> {
    check_name("--save-baseline", name)?;
    crate::store::folder::check_own_dir("--results", &results.join(BASELINES))?;
    crate::store::folder::check_own_dir("--results", &folder(results, name))
}

/// Copies each finished experiment folder of `dirs` into baseline `name` below `results`; returns
/// the baseline's folder.
pub fn save(results: &Path, name: &str, dirs: &[PathBuf]) -> Result<PathBuf> {
    check_save(results, name)?;
    let base = folder(results, name);
    std::fs::create_dir_all(&base).map_err(|e| HarnessError::write(&base, e))?;
    let pid = std::process::id();
    for dir in dirs {
        let commit = crate::store::folder::verify(dir, &["summary.json", "summary.csv"])?;
        let exp = dir
            .file_name()
            .and_then(|n| n.to_str())
            .filter(|n| plain_name(n))
            .ok_or_else(|| HarnessError::bad_file(dir, "not an experiment's results folder"))?;
        let (tmp, old, dest) =
            (base.join(format!(".{exp}.tmp-{pid}")), base.join(format!(".{exp}.old-{pid}")), base.join(exp));
        crate::store::folder::check_own_dir("--results", &dest)?;
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir(&tmp).map_err(|e| HarnessError::write(&tmp, e))?;
        let mut names: Vec<String> = commit.files.iter().map(|f| f.name.clone()).collect();
        names.push(crate::store::folder::COMMIT.to_string());
        if dir.join(crate::store::CELLS).is_file() {
            names.push(crate::store::CELLS.to_string());
        }
        for n in &names {
            let from = dir.join(n);
            let link = std::fs::symlink_metadata(&from).map(|m| m.file_type().is_symlink()).unwrap_or(false);
            if link {
                let _ = std::fs::remove_dir_all(&tmp);
                return Err(HarnessError::bad_file(&from, "is a symbolic link; mcbench does not follow it"));
            }
            if let Err(e) = std::fs::copy(&from, tmp.join(n)) {
                let _ = std::fs::remove_dir_all(&tmp);
                return Err(HarnessError::write(tmp.join(n), e));
            }
        }
        if dest.exists() {
            std::fs::rename(&dest, &old).map_err(|e| HarnessError::write(&dest, e))?;
        }
        std::fs::rename(&tmp, &dest).map_err(|e| HarnessError::write(&dest, e))?;
        let _ = std::fs::remove_dir_all(&old);
    }
    Ok(base)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_could_leave_the_folder_are_refused() {
        for bad in ["", "../x", "a/b", ".hidden", &"x".repeat(65)] {
            let e = check_name("--save-baseline", bad).expect_err(bad);
            assert_eq!(e.exit_code(), 2);
            assert!(e.to_string().contains("--save-baseline"), "{e}");
        }
        check_name("--baseline", "main-2.0_a").expect("plain");
    }

    #[test]
    fn a_saved_baseline_replaces_only_the_experiments_saved() {
        let dir = tempfile::tempdir().expect("tempdir");
        let results = dir.path().join("results");
        let run = crate::store::folder::OutputDir::new(results.join("exp"));
        run.write("summary.json", b"{}").expect("write");
        run.write("summary.csv", b"a\n").expect("write");
        run.commit("r1", None).expect("commit");
        let kept = folder(&results, "main").join("other");
        std::fs::create_dir_all(&kept).expect("mkdir");
        let base = save(&results, "main", &[results.join("exp")]).expect("saved");
        assert_eq!(std::fs::read(base.join("exp").join("summary.csv")).expect("copied"), b"a\n");
        crate::store::folder::verify(&base.join("exp"), &["summary.json"]).expect("a whole run");
        assert!(kept.is_dir(), "the baseline's other experiments stay");
        let left: Vec<_> = std::fs::read_dir(&base).expect("dir").map(|e| e.expect("e").file_name()).collect();
        assert_eq!(left.len(), 2, "no temporary folder is left: {left:?}");
        // Saving again replaces the folder whole.
        let again = crate::store::folder::OutputDir::new(results.join("exp"));
        again.write("summary.json", b"{}").expect("write");
        again.write("summary.csv", b"b\n").expect("write");
        again.commit("r2", None).expect("commit");
        save(&results, "main", &[results.join("exp")]).expect("saved");
        assert_eq!(std::fs::read(base.join("exp").join("summary.csv")).expect("copied"), b"b\n");
    }
}
