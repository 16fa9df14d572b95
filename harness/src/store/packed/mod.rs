//! The payload of a store record ([`crate::store`]): a cell's statistics, compressed. Per-integral
//! moments and repetition blocks are most of a cell, and JSON spends about 20 characters on each
//! of their numbers, so they are packed as little-endian columns ([`columns`]: counts, means, sums
//! of squares and cubes, mean compensations, and each block's sums, times and costs; bit for bit,
//! non-finite values included) after the rest of the cell as JSON, and the whole is deflated:
//!
//! ```text
//! deflate( meta length: u32 LE | meta: JSON of the record with empty `moments` and `blocks` |
//!          columns (columns::pack) )
//! ```
//!
//! [`encode_cell`] / [`decode_cell`] handle a finished cell, [`encode_block`] / [`decode_block`] a
//! shard's repetition block. Records written by earlier versions (format 1: the moments as five
//! plain columns, the blocks in the JSON part) are still read.

pub mod columns;

use crate::run::cell::CellResult;
use crate::run::shard::BlockFile;
use flate2::read::DeflateDecoder;
use flate2::write::DeflateEncoder;
use mcbench_core::stats::Moments;
use std::io::{Read, Write};

/// At most this many bytes are inflated from one record (a damaged record cannot make the reader
/// allocate more).
pub const MAX_INFLATED: u64 = 1 << 32;

/// A record's two parts before compression: the JSON text and the binary columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Parts {
    /// JSON of the record with empty `moments` (and, in format 2, empty `blocks`).
    pub meta: String,
    /// The moments and blocks as columns ([`columns::pack`]), or a format-1 record's moments.
    pub columns: Vec<u8>,
}

/// Packs moments into format 1's columns (`k: u32 LE` and five plain columns), as records of
/// earlier versions hold them.
pub fn pack_moments(moments: &[[Moments; 3]]) -> Vec<u8> {
    let all: Vec<(u64, [f64; 4])> = moments.iter().flat_map(|m| m.iter().map(Moments::raw)).collect();
    let mut out = Vec::with_capacity(4 + all.len() * 40);
    out.extend_from_slice(&(all.len() as u32).to_le_bytes());
    for (n, _) in &all {
        out.extend_from_slice(&n.to_le_bytes());
    }
    for field in 0..4 {
        for (_, v) in &all {
            out.extend_from_slice(&v[field].to_le_bytes());
        }
    }
    out
}

/// Unpacks format 1's moment columns ([`pack_moments`]); `Err` says what does not fit.
pub fn unpack_moments(bytes: &[u8]) -> Result<Vec<[Moments; 3]>, String> {
    let head: [u8; 4] = bytes.get(..4).and_then(|b| b.try_into().ok()).ok_or("no moment count")?;
    let k = u32::from_le_bytes(head) as usize;
    if !k.is_multiple_of(3) {
        return Err(format!("{k} moments are not 3 channels per integral"));
    }
    let cols = &bytes[4..];
    if cols.len() as u64 != k as u64 * 40 {
        return Err(format!("{} bytes of moments, {k} moments take {}", cols.len(), k as u64 * 40));
    }
    let word = |at: usize| -> [u8; 8] { cols[at..at + 8].try_into().unwrap_or([0; 8]) };
    let f = |field: usize, i: usize| f64::from_le_bytes(word(8 * (k * (1 + field) + i)));
    let one = |i: usize| Moments::from_raw(u64::from_le_bytes(word(8 * i)), [f(0, i), f(1, i), f(2, i), f(3, i)]);
    Ok((0..k / 3).map(|j| [one(3 * j), one(3 * j + 1), one(3 * j + 2)]).collect())
}

/// Compresses a record's parts.
pub fn join(parts: &Parts) -> Vec<u8> {
    let mut e = DeflateEncoder::new(Vec::new(), flate2::Compression::best());
    let written = e
        .write_all(&(parts.meta.len() as u32).to_le_bytes())
        .and_then(|()| e.write_all(parts.meta.as_bytes()))
        .and_then(|()| e.write_all(&parts.columns));
    // Writing into a Vec cannot fail.
    written.and_then(|()| e.finish()).unwrap_or_default()
}

/// Inflates a record's payload into its parts; `Err` says what is wrong.
pub fn split(payload: &[u8]) -> Result<Parts, String> {
    let mut raw = Vec::new();
    DeflateDecoder::new(payload)
        .take(MAX_INFLATED)
        .read_to_end(&mut raw)
        .map_err(|e| format!("it does not inflate: {e}"))?;
    let head: [u8; 4] = raw.get(..4).and_then(|b| b.try_into().ok()).ok_or("it is empty")?;
    let len = u32::from_le_bytes(head) as usize;
    let meta = raw.get(4..4 + len).ok_or("its JSON part is cut short")?;
    let meta = std::str::from_utf8(meta).map_err(|_| "its JSON part is not UTF-8")?.to_string();
    Ok(Parts { meta, columns: raw[4 + len..].to_vec() })
}

fn one_line(e: serde_json::Error) -> String {
    e.to_string().lines().next().unwrap_or("malformed").to_string()
}

/// The columns of a cell's statistics, and the cell without them (for its JSON part).
fn take_columns(cell: &CellResult) -> (CellResult, Vec<u8>) {
    let columns = columns::pack(&cell.moments, &cell.blocks);
    // Field by field, so the moments and blocks are not copied only to be dropped.
    let meta = CellResult {
        key: cell.key.clone(),
        moments: Vec::new(),
        costs: cell.costs,
        estimates: cell.estimates,
        time: cell.time.clone(),
        cpu_time: cell.cpu_time.clone(),
        diagnostics: cell.diagnostics.clone(),
        rep_dev: cell.rep_dev.clone(),
        rep_sq: cell.rep_sq.clone(),
        blocks: Vec::new(),
    };
    (meta, columns)
}

/// Puts a record's columns back into the cell its JSON part gave.
fn put_columns(cell: &mut CellResult, bytes: &[u8]) -> Result<(), String> {
    if !cell.moments.is_empty() {
        return Err("moments in its JSON part".into());
    }
    if bytes.get(..4) == Some(&columns::FORMAT2.to_le_bytes()[..]) {
        if !cell.blocks.is_empty() {
            return Err("blocks in its JSON part".into());
        }
        (cell.moments, cell.blocks) = columns::unpack(bytes)?;
    } else {
        cell.moments = unpack_moments(bytes)?;
    }
    Ok(())
}

/// The payload of a finished cell.
pub fn encode_cell(cell: &CellResult) -> Vec<u8> {
    let (meta, columns) = take_columns(cell);
    join(&Parts { meta: serde_json::to_string(&meta).unwrap_or_default(), columns })
}

/// A cell from its payload; `Err` says what is wrong.
pub fn decode_cell(payload: &[u8]) -> Result<CellResult, String> {
    let parts = split(payload)?;
    let mut cell: CellResult = serde_json::from_str(&parts.meta).map_err(one_line)?;
    put_columns(&mut cell, &parts.columns)?;
    Ok(cell)
}

/// The payload of a shard's repetition block.
pub fn encode_block(block: &BlockFile) -> Vec<u8> {
    let (stats, columns) = take_columns(&block.stats);
    let meta = BlockFile { stats, ..block.clone() };
    join(&Parts { meta: serde_json::to_string(&meta).unwrap_or_default(), columns })
}

/// A shard's repetition block from its payload; `Err` says what is wrong.
pub fn decode_block(payload: &[u8]) -> Result<BlockFile, String> {
    let parts = split(payload)?;
    let mut block: BlockFile = serde_json::from_str(&parts.meta).map_err(one_line)?;
    put_columns(&mut block.stats, &parts.columns)?;
    Ok(block)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cell::{CellKey, TimeStats};
    use mcbench_core::budget::Budget;

    fn cell() -> CellResult {
        let mut moments = Vec::new();
        for i in 0..5 {
            let mut m: [Moments; 3] = Default::default();
            for (c, mc) in m.iter_mut().enumerate() {
                for r in 0..4 {
                    mc.push(0.1 * (i * 3 + c) as f64 + 1e-3 * r as f64 * std::f64::consts::PI);
                }
            }
            moments.push(m);
        }
        moments[1][2] = Moments::from_raw(4, [0.5, f64::INFINITY, f64::NEG_INFINITY, -1e-17]);
        let mut time = TimeStats::default();
        time.push(1e-5);
        CellResult {
            key: CellKey {
                testbed: "gradient-plane".into(),
                variant: "default".into(),
                testbed_params: "{\"resolution\":4}".into(),
                estimator: "is0_cv0".into(),
                budget: Budget::samples(16).expect("budget"),
                reps: 4,
                seed: 1,
                version: "0".into(),
            },
            moments,
            costs: Default::default(),
            estimates: 20,
            time: time.clone(),
            cpu_time: Some(time),
            diagnostics: vec![("cells".into(), 3.0)],
            rep_dev: Moments::default(),
            rep_sq: Moments::default(),
            blocks: (0..2)
                .map(|i| crate::run::cell::RepBlock {
                    reps: 2,
                    sq: 0.3 + i as f64,
                    display_sq: Some(0.1),
                    ..Default::default()
                })
                .collect(),
        }
    }

    /// A format-1 payload, as earlier versions wrote it: the blocks in the JSON part.
    fn format1(c: &CellResult) -> Vec<u8> {
        let meta = CellResult { moments: Vec::new(), ..c.clone() };
        join(&Parts { meta: serde_json::to_string(&meta).expect("json"), columns: pack_moments(&c.moments) })
    }

    #[test]
    fn cells_and_blocks_round_trip_bit_for_bit() {
        let c = cell();
        let back = decode_cell(&encode_cell(&c)).expect("decodes");
        assert_eq!(back.key, c.key);
        for (a, b) in back.moments.iter().flatten().zip(c.moments.iter().flatten()) {
            let ((na, va), (nb, vb)) = (a.raw(), b.raw());
            assert_eq!(na, nb);
            assert_eq!(va.map(f64::to_bits), vb.map(f64::to_bits));
        }
        assert_eq!(back.moments.len(), 5);
        assert_eq!(back.blocks, c.blocks);
        let b = BlockFile { block: 1, blocks: 3, stats: c.clone() };
        let back = decode_block(&encode_block(&b)).expect("decodes");
        assert_eq!((back.block, back.blocks, back.stats.moments.len()), (1, 3, 5));
        assert!(decode_block(&encode_cell(&c)).is_err(), "a cell is not a block");
    }

    #[test]
    fn format_1_records_are_still_read() {
        let c = cell();
        assert_eq!(decode_cell(&format1(&c)).expect("decodes"), c);
    }

    #[test]
    fn damaged_payloads_are_refused_saying_why() {
        let c = cell();
        let payload = encode_cell(&c);
        assert!(decode_cell(&payload[..payload.len() / 2]).is_err());
        assert!(decode_cell(b"not deflate at all").is_err());
        let mut parts = split(&payload).expect("splits");
        parts.columns.truncate(parts.columns.len() - 8);
        assert!(decode_cell(&join(&parts)).expect_err("short").contains("cut short"));
        let mut parts = split(&payload).expect("splits");
        parts.columns[4] = 4;
        assert!(decode_cell(&join(&parts)).expect_err("count").contains("3 channels"));
        let mut parts = split(&payload).expect("splits");
        let block = serde_json::to_string(&crate::run::cell::RepBlock::default()).expect("json");
        parts.meta = parts.meta.replace("\"blocks\":[]", &format!("\"blocks\":[{block}]"));
        assert!(decode_cell(&join(&parts)).expect_err("blocks").contains("blocks in its JSON part"));
        let mut v1 = split(&format1(&c)).expect("splits");
        v1.columns.truncate(v1.columns.len() - 8);
        assert!(decode_cell(&join(&v1)).expect_err("short").contains("bytes of moments"));
        let mut parts = split(&payload).expect("splits");
        parts.meta = parts.meta.replace("\"moments\":[]", "\"moments\":[[]]");
        assert!(decode_cell(&join(&parts)).is_err());
        let mut parts = split(&payload).expect("splits");
        parts.meta.truncate(10);
        assert!(decode_cell(&join(&parts)).is_err());
    }
}
