//! Tests of the folder lock: the lock file's life, readers and writers, links and other files
//! in its place, and the folders a lock makes.

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
    assert!(!d.exists(), "nothing left: the folder it made went with the file");
    std::fs::create_dir(&d).expect("folder");
    drop(FolderLock::acquire(&d, false, &[]).expect("free again"));
    assert!(!d.join(LOCK).exists());
    assert!(std::fs::read_dir(&d).expect("folder").next().is_none(), "nothing left in the folder");
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
fn a_lock_file_that_is_a_link_or_not_a_plain_file_is_refused_and_left_alone() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path().join("r");
    std::fs::create_dir(&d).expect("folder");
    let outside = dir.path().join("outside");
    std::fs::write(&outside, b"precious").expect("file");
    let lock = d.join(LOCK);
    let gone = dir.path().join("gone");
    for target in [&outside, &gone] {
        std::os::unix::fs::symlink(target, &lock).expect("link");
        let e = FolderLock::acquire(&d, false, &[]).expect_err("a link");
        assert_eq!(e.exit_code(), 2, "{e}");
        assert!(e.to_string().contains(".lock: is a symbolic link"), "{e}");
        let e = read_lock(&d, false).expect_err("a link");
        assert_eq!(e.exit_code(), 2, "{e}");
        assert!(std::fs::symlink_metadata(&lock).expect("still there").file_type().is_symlink());
        std::fs::remove_file(&lock).expect("unlink");
    }
    assert_eq!(std::fs::read(&outside).expect("target"), b"precious");
    assert!(!gone.exists(), "a dangling link's target is not created");
    // A hard link to a file elsewhere: its content would be written through it.
    std::fs::hard_link(&outside, &lock).expect("hard link");
    let e = FolderLock::acquire(&d, false, &[]).expect_err("two links");
    assert!(e.exit_code() == 2 && e.to_string().contains("hard links"), "{e}");
    assert!(read_lock(&d, false).is_err());
    assert_eq!(std::fs::read(&outside).expect("target"), b"precious");
    std::fs::remove_file(&lock).expect("unlink");
    // A folder in its place.
    std::fs::create_dir(&lock).expect("folder");
    assert_eq!(FolderLock::acquire(&d, false, &[]).expect_err("a folder").exit_code(), 2);
    assert_eq!(read_lock(&d, false).expect_err("a folder").exit_code(), 2);
    assert!(lock.is_dir());
}

#[test]
fn a_refused_lock_leaves_no_folder_it_made() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A run's results folder is locked (made, with its parent), then its plots folder is
    // refused because another holds it: releasing the first lock removes what it made.
    let plots = dir.path().join("plots/x");
    let other = FolderLock::acquire(&plots, false, &[]).expect("free");
    let results = FolderLock::acquire(&dir.path().join("results/x"), false, &[]).expect("free");
    let e = FolderLock::acquire(&plots, false, &[]).expect_err("busy");
    assert_eq!(e.exit_code(), 3);
    drop(results);
    assert!(!dir.path().join("results").exists(), "nothing left of the results folder");
    assert!(plots.join(LOCK).exists(), "the holder's folder and file stay");
    drop(other);
    // A folder that was there before stays, even empty; so does a made one with a file in it.
    let d = dir.path().join("kept");
    std::fs::create_dir(&d).expect("folder");
    drop(FolderLock::acquire(&d, false, &[]).expect("free"));
    assert!(d.is_dir());
    let lock = FolderLock::acquire(&d.join("new"), false, &[]).expect("free");
    std::fs::write(d.join("new/file"), b"x").expect("write");
    drop(lock);
    assert!(d.join("new/file").exists());
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

#[test]
fn writers_that_make_and_remove_a_shared_parent_never_fail() {
    // Writers lock sibling folders below folders that come and go: each makes what it lacks and
    // removes it again empty as it lets go, while the others make theirs beside it. A folder
    // vanishing between its making and the lock file's open is made again, never an error.
    const WRITERS: usize = 4;
    const ROUNDS: usize = 500;
    let dir = tempfile::tempdir().expect("tempdir");
    let root = dir.path().join("root");
    std::thread::scope(|s| {
        for w in 0..WRITERS {
            let root = &root;
            s.spawn(move || {
                for r in 0..ROUNDS {
                    let d = root.join(format!("round-{}/w{w}", r % 3));
                    drop(FolderLock::acquire(&d, false, &[]).expect("never fails"));
                }
            });
        }
    });
    // A folder its maker let go of while another writer was inside stays (it is not the other's
    // to remove): only empty folders may be left, no lock file.
    let mut stack = vec![root];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten() {
            let p = e.expect("entry").path();
            assert!(p.is_dir(), "{} left", p.display());
            stack.push(p);
        }
    }
}
