//! The cell store: one append-only file per results folder (`cells.store`) and per shard folder
//! (`blocks.store`) instead of one file per cell. It is a log of named records, each framed by its
//! length and two checksums:
//!
//! ```text
//! header  "MCBSTORE" | format: u32 LE
//! record  len: u32 LE | crc32(len): u32 LE | crc32(body): u32 LE | body (len bytes)
//! body    name length: u16 LE | name (UTF-8) | payload (a compressed cell, crate::store::packed)
//! ```
//!
//! A writer (one per folder: the caller holds the folder's lock) appends each record with one
//! write and syncs it, so a finished record is never lost. A process killed while appending
//! leaves at most a torn last record: its bytes run past the end of the file (or its checksum
//! fails and nothing follows it). Readers drop such a tail and keep every record before it; the
//! next writer truncates it before appending. A record that fails its checksum with more records
//! after it, a header that is not a store's, or a body that does not parse is corrupt: refused as
//! bad input naming the file (exit 2). Records are read back by name; when a name was appended
//! twice (two runs raced, or a merge was repeated) the last record is the one read, and the next
//! writer compacts the file to one record per name.

pub mod folder;
pub(crate) mod folder_lock;
pub(crate) mod made_dirs;
pub mod packed;
pub mod references;

use crate::error::{HarnessError, Result};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The store of a results folder: the finished cells of every run into it.
pub const CELLS: &str = "cells.store";
/// The store of a shard folder: the finished repetition blocks of its units.
pub const BLOCKS: &str = "blocks.store";
/// The first bytes of a store.
pub const MAGIC: &[u8; 8] = b"MCBSTORE";
/// The format this mcbench writes and reads.
pub const FORMAT: u32 = 1;
/// Bytes of the file header (magic and format).
pub const HEADER_LEN: usize = 12;
/// Bytes of a record's frame before its body.
pub const FRAME_LEN: usize = 12;

/// What is wrong with a store file.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StoreError {
    /// The header is not a store's.
    #[error("not an mcbench cell store (it does not start with MCBSTORE)")]
    NotAStore,
    /// Another format.
    #[error("cell store format {0} (this mcbench reads {FORMAT})")]
    Format(u32),
    /// A damaged record with records after it.
    #[error("corrupt record at byte {offset} ({why}); delete the file to recompute its cells")]
    Corrupt {
        /// Where the record starts.
        offset: usize,
        /// What failed.
        why: String,
    },
}

/// One record: a name and its payload, as stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// What the payload is (a cell's or block's name).
    pub name: String,
    /// The payload bytes.
    pub payload: Vec<u8>,
}

/// The crc32 of `bytes`.
fn crc(bytes: &[u8]) -> u32 {
    let mut c = flate2::Crc::new();
    c.update(bytes);
    c.sum()
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The bytes of one framed record.
pub fn frame(name: &str, payload: &[u8]) -> Vec<u8> {
    let name = &name.as_bytes()[..name.len().min(u16::MAX as usize)];
    let len = (2 + name.len() + payload.len()) as u32;
    let mut out = Vec::with_capacity(FRAME_LEN + len as usize);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(&crc(&len.to_le_bytes()).to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    out.extend_from_slice(&(name.len() as u16).to_le_bytes());
    out.extend_from_slice(name);
    out.extend_from_slice(payload);
    let body_crc = crc(&out[FRAME_LEN..]);
    out[8..12].copy_from_slice(&body_crc.to_le_bytes());
    out
}

/// The header of a new store.
pub fn header() -> Vec<u8> {
    let mut h = MAGIC.to_vec();
    h.extend_from_slice(&FORMAT.to_le_bytes());
    h
}

/// The records of a store's bytes, and where its valid part ends (a torn tail after it is
/// dropped). An empty file, or the beginning of a header a killed writer left, holds none.
pub fn scan(bytes: &[u8]) -> std::result::Result<(Vec<Record>, usize), StoreError> {
    if bytes.len() < HEADER_LEN {
        return if MAGIC.starts_with(&bytes[..bytes.len().min(MAGIC.len())]) {
            Ok((Vec::new(), 0))
        } else {
            Err(StoreError::NotAStore)
        };
    }
    if &bytes[..MAGIC.len()] != MAGIC {
        return Err(StoreError::NotAStore);
    }
    let format = u32_at(bytes, MAGIC.len());
    if format != FORMAT {
        return Err(StoreError::Format(format));
    }
    let mut records = Vec::new();
    let mut at = HEADER_LEN;
    while at < bytes.len() {
        let rest = &bytes[at..];
        if rest.len() < FRAME_LEN {
            break; // a torn frame
        }
        let corrupt = |why: &str| StoreError::Corrupt { offset: at, why: why.to_string() };
        let len = u32_at(rest, 0) as usize;
        if crc(&rest[..4]) != u32_at(rest, 4) {
            if rest.iter().all(|&b| b == 0) {
                break; // a tail a crash extended with zeros
            }
            return Err(corrupt("its length fails its checksum"));
        }
        if len > rest.len() - FRAME_LEN {
            break; // a torn record: its bytes run past the end
        }
        let body = &rest[FRAME_LEN..FRAME_LEN + len];
        let end = at + FRAME_LEN + len;
        if crc(body) != u32_at(rest, 8) {
            if end == bytes.len() {
                break; // the last record, damaged while it was written
            }
            return Err(corrupt("it fails its checksum"));
        }
        if body.len() < 2 {
            return Err(corrupt("no name"));
        }
        let name_len = u16::from_le_bytes([body[0], body[1]]) as usize;
        let name = body
            .get(2..2 + name_len)
            .and_then(|n| std::str::from_utf8(n).ok())
            .ok_or_else(|| corrupt("its name is not UTF-8 inside the record"))?;
        records.push(Record { name: name.to_string(), payload: body[2 + name_len..].to_vec() });
        at = end;
    }
    Ok((records, at))
}

/// A store read back: its records, checked, looked up by name.
#[derive(Debug, Default)]
pub struct Store {
    path: PathBuf,
    records: Vec<Record>,
    index: HashMap<String, usize>,
    valid: usize,
    len: usize,
}

impl Store {
    /// Reads the store at `path` (none there: an empty store). A torn tail is dropped; a corrupt
    /// record, a file that is not a store, or a symbolic link in its place (mcbench writes its
    /// stores itself, never through a link) is bad input naming the file.
    pub fn open(path: &Path) -> Result<Store> {
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
            return Err(HarnessError::bad_file(path, "is a symbolic link; mcbench does not follow it: remove it"));
        }
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => return Err(HarnessError::bad_file(path, e)),
        };
        Store::from_bytes(path, &bytes)
    }

    fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Store> {
        let (records, valid) = scan(bytes).map_err(|e| HarnessError::bad_file(path, e))?;
        let index = records.iter().enumerate().map(|(i, r)| (r.name.clone(), i)).collect();
        Ok(Store { path: path.to_path_buf(), records, index, valid, len: bytes.len() })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The last record named `name`.
    pub fn get(&self, name: &str) -> Option<&Record> {
        self.index.get(name).map(|&i| &self.records[i])
    }

    /// Every record, in file order (a name appended twice appears twice).
    pub fn records(&self) -> &[Record] {
        &self.records
    }

    /// Bytes of a torn tail that were dropped (0 for a whole store).
    pub fn torn_bytes(&self) -> usize {
        self.len - self.valid
    }

    /// Whether some name has more than one record.
    fn has_duplicates(&self) -> bool {
        self.index.len() < self.records.len()
    }
}

/// Writes a store holding `records` (in that order) to `path` atomically (temp file + rename):
/// a compaction, or a tool's or test's edit.
pub fn write_records(path: &Path, records: &[Record]) -> Result<()> {
    let mut bytes = header();
    for r in records {
        bytes.extend(frame(&r.name, &r.payload));
    }
    crate::output::write_atomic(path, &bytes)
}

/// Appends records to a store; the caller holds the folder's lock, so it is the only writer.
#[derive(Debug)]
pub struct StoreWriter {
    file: File,
    path: PathBuf,
}

impl StoreWriter {
    /// Opens `path` for appending: creates it (header written atomically) when absent, truncates
    /// a torn tail, and compacts a store holding a name twice to its last record of each name.
    /// A corrupt store is refused as in [`Store::open`].
    pub fn open(path: &Path) -> Result<StoreWriter> {
        let store = Store::open(path)?;
        if store.len < HEADER_LEN {
            crate::output::write_atomic(path, &header())?;
        } else if store.has_duplicates() {
            let mut last: Vec<(usize, &Record)> = store.index.values().map(|&i| (i, &store.records[i])).collect();
            last.sort_by_key(|(i, _)| *i);
            let kept: Vec<Record> = last.into_iter().map(|(_, r)| r.clone()).collect();
            write_records(path, &kept)?;
        }
        let mut options = OpenOptions::new();
        options.read(true).write(true);
        #[cfg(unix)]
        {
            // Appended to as it is, never through a link that took its place since it was read.
            use std::os::unix::fs::OpenOptionsExt;
            options.custom_flags(libc::O_NOFOLLOW);
        }
        let mut file = options.open(path).map_err(|e| HarnessError::write(path, e))?;
        if store.torn_bytes() > 0 && !store.has_duplicates() && store.len >= HEADER_LEN {
            file.set_len(store.valid as u64).map_err(|e| HarnessError::write(path, e))?;
        }
        file.seek(SeekFrom::End(0)).map_err(|e| HarnessError::write(path, e))?;
        Ok(StoreWriter { file, path: path.to_path_buf() })
    }

    /// Appends one record with a single write and syncs it to disk.
    pub fn append(&mut self, name: &str, payload: &[u8]) -> Result<()> {
        let bytes = frame(name, payload);
        self.file.write_all(&bytes).and_then(|()| self.file.sync_data()).map_err(|e| HarnessError::write(&self.path, e))
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(name: &str, payload: &[u8]) -> Record {
        Record { name: name.into(), payload: payload.to_vec() }
    }

    fn three(path: &Path) -> Vec<u8> {
        let mut w = StoreWriter::open(path).expect("opens");
        for (n, p) in [("a", &b"first"[..]), ("b", b"second"), ("c", b"third")] {
            w.append(n, p).expect("appends");
        }
        std::fs::read(path).expect("reads")
    }

    #[test]
    fn records_read_back_by_name_and_a_missing_store_is_empty() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(CELLS);
        assert!(Store::open(&path).expect("empty").records().is_empty());
        three(&path);
        let s = Store::open(&path).expect("reads");
        assert_eq!(s.records().len(), 3);
        assert_eq!(s.get("b"), Some(&rec("b", b"second")));
        assert_eq!(s.get("z"), None);
        assert_eq!(s.torn_bytes(), 0);
    }

    #[test]
    fn a_torn_tail_is_dropped_and_truncated_by_the_next_writer() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(CELLS);
        let whole = three(&path);
        let last = frame("c", b"third").len();
        // Every cut inside the last record, and garbage or zeros in place of its end.
        for cut in 1..last {
            std::fs::write(&path, &whole[..whole.len() - cut]).expect("cut");
            let s = Store::open(&path).expect("a torn tail is not an error");
            assert_eq!(s.records(), &[rec("a", b"first"), rec("b", b"second")], "cut {cut}");
        }
        let mut damaged = whole.clone();
        let n = damaged.len();
        damaged[n - 2] ^= 0xff;
        std::fs::write(&path, &damaged).expect("damage");
        assert_eq!(Store::open(&path).expect("dropped").records().len(), 2);
        let mut zeros = whole[..whole.len() - last].to_vec();
        zeros.extend(std::iter::repeat_n(0u8, 40));
        std::fs::write(&path, &zeros).expect("zeros");
        assert_eq!(Store::open(&path).expect("dropped").records().len(), 2);
        // The next writer truncates the tail, so what it appends is read back.
        std::fs::write(&path, &whole[..whole.len() - 3]).expect("cut");
        StoreWriter::open(&path).expect("opens").append("d", b"fourth").expect("appends");
        let s = Store::open(&path).expect("reads");
        assert_eq!(s.records().iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["a", "b", "d"]);
        assert_eq!(s.torn_bytes(), 0);
        // A killed first writer's partial header is an empty store.
        std::fs::write(&path, &MAGIC[..5]).expect("partial header");
        assert!(Store::open(&path).expect("empty").records().is_empty());
        StoreWriter::open(&path).expect("opens").append("e", b"x").expect("appends");
        assert_eq!(Store::open(&path).expect("reads").records(), &[rec("e", b"x")]);
    }

    #[test]
    fn a_corrupt_record_in_the_middle_is_refused_naming_the_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(CELLS);
        let whole = three(&path);
        let second = HEADER_LEN + frame("a", b"first").len();
        for (at, needle) in [(second + FRAME_LEN + 4, "fails its checksum"), (second + 1, "length fails")] {
            let mut bad = whole.clone();
            bad[at] ^= 0x01;
            std::fs::write(&path, &bad).expect("damage");
            let e = Store::open(&path).expect_err("refused").to_string();
            assert!(e.contains(CELLS) && e.contains(needle) && e.contains(&format!("byte {second}")), "{e}");
            assert_eq!(Store::open(&path).expect_err("refused").exit_code(), 2);
            assert!(StoreWriter::open(&path).is_err(), "a writer does not append after a corrupt record");
            assert_eq!(std::fs::read(&path).expect("reads"), bad, "a refused store is left as it is");
        }
        std::fs::write(&path, b"{\"key\": 1}\n and more").expect("other file");
        assert!(Store::open(&path).expect_err("refused").to_string().contains("not an mcbench cell store"));
        let mut other = whole.clone();
        other[8] = 9;
        std::fs::write(&path, &other).expect("other format");
        assert!(Store::open(&path).expect_err("refused").to_string().contains("format 9"));
    }

    #[test]
    fn a_name_appended_twice_reads_its_last_record_and_the_next_writer_compacts() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(CELLS);
        three(&path);
        StoreWriter::open(&path).expect("opens").append("b", b"again").expect("appends");
        let s = Store::open(&path).expect("reads");
        assert_eq!((s.records().len(), s.get("b")), (4, Some(&rec("b", b"again"))));
        StoreWriter::open(&path).expect("compacts");
        let s = Store::open(&path).expect("reads");
        assert_eq!(s.records(), &[rec("a", b"first"), rec("c", b"third"), rec("b", b"again")]);
    }
}
