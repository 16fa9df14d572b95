//! The binary part of a record (format 2): a cell's per-integral moments and its repetition
//! blocks as little-endian columns, each column's bytes transposed (byte 0 of every value, then
//! byte 1, ...) so that the sign, exponent and high mantissa bytes, which vary little along a
//! column, sit together where deflate finds them. Every value is kept bit for bit (non-finite ones
//! included):
//!
//! ```text
//! marker: u32 LE (FORMAT2) | k: u32 LE (integrals x 3) | channels: u8 (3, or 1 when each
//!   integral's three channels hold the same moments bit for bit, as in grey test beds)
//! moments (j = k / 3 x channels values a column):  n | mean | m2 | m3 | mean_comp
//! b: u32 LE (repetition blocks) | reps | sq | p_err | cpu_seconds | wall_seconds |
//!   display_sq (0 where absent) | display_sq present: b x u8
//! costs length: u32 LE | costs: JSON object of one array of b counts per cost field
//! ```
//!
//! Format 1 (a `k` first, five plain columns of moments, blocks in the JSON part) is still read.

use crate::run::cell::RepBlock;
use mcbench_core::stats::Moments;
use mcbench_core::task::Costs;
use std::collections::BTreeMap;

/// The first word of a format-2 binary part. It is not a multiple of 3, so it is never a
/// format-1 part's moment count.
pub const FORMAT2: u32 = 0x4D43_4232;

/// Appends `values` (8 bytes each) transposed: byte `i` of every value, for `i` in 0..8.
fn put_column(out: &mut Vec<u8>, values: &[[u8; 8]]) {
    for i in 0..8 {
        out.extend(values.iter().map(|v| v[i]));
    }
}

fn f64_column(out: &mut Vec<u8>, values: impl Iterator<Item = f64>) {
    put_column(out, &values.map(f64::to_le_bytes).collect::<Vec<_>>());
}

fn u64_column(out: &mut Vec<u8>, values: impl Iterator<Item = u64>) {
    put_column(out, &values.map(u64::to_le_bytes).collect::<Vec<_>>());
}

/// Reads a format-2 part front to back; every read checks the length left.
struct Cursor<'a> {
    bytes: &'a [u8],
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        if self.bytes.len() < n {
            return Err(format!("its {what} are cut short"));
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn column(&mut self, n: usize, what: &str) -> Result<Vec<[u8; 8]>, String> {
        let len = n.checked_mul(8).ok_or_else(|| format!("its {what} do not fit in memory"))?;
        let b = self.take(len, what)?;
        Ok((0..n).map(|j| std::array::from_fn(|i| b[i * n + j])).collect())
    }
    fn f64s(&mut self, n: usize, what: &str) -> Result<Vec<f64>, String> {
        Ok(self.column(n, what)?.into_iter().map(f64::from_le_bytes).collect())
    }
    fn u64s(&mut self, n: usize, what: &str) -> Result<Vec<u64>, String> {
        Ok(self.column(n, what)?.into_iter().map(u64::from_le_bytes).collect())
    }
}

/// A moment's whole state as bits, for comparing bit for bit.
fn bits(m: &Moments) -> (u64, [u64; 4]) {
    let (n, v) = m.raw();
    (n, v.map(f64::to_bits))
}

/// Whether each integral's three channels hold the same moments, bit for bit.
fn grey(moments: &[[Moments; 3]]) -> bool {
    moments.iter().all(|m| bits(&m[0]) == bits(&m[1]) && bits(&m[0]) == bits(&m[2]))
}

/// The costs of the blocks as a JSON object of columns (`{"samples": [..], ...}`): field names
/// once, counts as numbers.
fn costs_json(blocks: &[RepBlock]) -> String {
    let mut cols: BTreeMap<String, Vec<serde_json::Value>> = BTreeMap::new();
    for b in blocks {
        if let Ok(serde_json::Value::Object(fields)) = serde_json::to_value(b.costs) {
            for (name, v) in fields {
                cols.entry(name).or_default().push(v);
            }
        }
    }
    serde_json::to_string(&cols).unwrap_or_default()
}

fn costs_from_json(text: &[u8], b: usize) -> Result<Vec<Costs>, String> {
    let cols: BTreeMap<String, Vec<serde_json::Value>> =
        serde_json::from_slice(text).map_err(|e| format!("its block costs do not parse: {e}"))?;
    (0..b)
        .map(|i| {
            let mut fields = serde_json::Map::new();
            for (name, col) in &cols {
                let v = col.get(i).ok_or_else(|| format!("block costs `{name}` hold {} of {b} blocks", col.len()))?;
                fields.insert(name.clone(), v.clone());
            }
            serde_json::from_value(serde_json::Value::Object(fields)).map_err(|e| format!("block costs: {e}"))
        })
        .collect()
}

/// The format-2 binary part of moments and repetition blocks.
pub fn pack(moments: &[[Moments; 3]], blocks: &[RepBlock]) -> Vec<u8> {
    let channels = if grey(moments) { 1 } else { 3 };
    let stored: Vec<(u64, [f64; 4])> = moments.iter().flat_map(|m| m[..channels].iter().map(Moments::raw)).collect();
    let mut out = Vec::with_capacity(9 + stored.len() * 40 + blocks.len() * 60);
    out.extend_from_slice(&FORMAT2.to_le_bytes());
    out.extend_from_slice(&((moments.len() * 3) as u32).to_le_bytes());
    out.push(channels as u8);
    u64_column(&mut out, stored.iter().map(|s| s.0));
    for field in 0..4 {
        f64_column(&mut out, stored.iter().map(|s| s.1[field]));
    }
    out.extend_from_slice(&(blocks.len() as u32).to_le_bytes());
    u64_column(&mut out, blocks.iter().map(|b| b.reps));
    f64_column(&mut out, blocks.iter().map(|b| b.sq));
    f64_column(&mut out, blocks.iter().map(|b| b.p_err));
    f64_column(&mut out, blocks.iter().map(|b| b.cpu_seconds));
    f64_column(&mut out, blocks.iter().map(|b| b.wall_seconds));
    f64_column(&mut out, blocks.iter().map(|b| b.display_sq.unwrap_or(0.0)));
    out.extend(blocks.iter().map(|b| u8::from(b.display_sq.is_some())));
    let costs = costs_json(blocks);
    out.extend_from_slice(&(costs.len() as u32).to_le_bytes());
    out.extend_from_slice(costs.as_bytes());
    out
}

/// Unpacks [`pack`]'s bytes (after checking they start with [`FORMAT2`]); `Err` says what does
/// not fit.
pub fn unpack(bytes: &[u8]) -> Result<(Vec<[Moments; 3]>, Vec<RepBlock>), String> {
    let mut c = Cursor { bytes };
    if c.u32("format")? != FORMAT2 {
        return Err("its columns are not format 2".into());
    }
    let k = c.u32("moment count")? as usize;
    if !k.is_multiple_of(3) {
        return Err(format!("{k} moments are not 3 channels per integral"));
    }
    let channels = c.take(1, "channel count")?[0] as usize;
    if channels != 1 && channels != 3 {
        return Err(format!("{channels} stored channels (1 or 3)"));
    }
    let j = k / 3 * channels;
    let n = c.u64s(j, "moments")?;
    let cols: Vec<Vec<f64>> = (0..4).map(|_| c.f64s(j, "moments")).collect::<Result<_, _>>()?;
    let one = |i: usize| Moments::from_raw(n[i], [cols[0][i], cols[1][i], cols[2][i], cols[3][i]]);
    let moments = (0..k / 3)
        .map(|i| if channels == 1 { [one(i), one(i), one(i)] } else { [one(3 * i), one(3 * i + 1), one(3 * i + 2)] })
        .collect();
    let b = c.u32("block count")? as usize;
    let reps = c.u64s(b, "blocks")?;
    let f: Vec<Vec<f64>> = (0..5).map(|_| c.f64s(b, "blocks")).collect::<Result<_, _>>()?;
    let present = c.take(b, "blocks")?.to_vec();
    let len = c.u32("block costs")? as usize;
    let costs = costs_from_json(c.take(len, "block costs")?, b)?;
    if !c.bytes.is_empty() {
        return Err(format!("{} bytes follow its columns", c.bytes.len()));
    }
    let blocks = costs
        .into_iter()
        .enumerate()
        .map(|(i, costs)| RepBlock {
            reps: reps[i],
            sq: f[0][i],
            p_err: f[1][i],
            cpu_seconds: f[2][i],
            wall_seconds: f[3][i],
            display_sq: (present[i] != 0).then_some(f[4][i]),
            costs,
        })
        .collect();
    Ok((moments, blocks))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blocks() -> Vec<RepBlock> {
        (0..3)
            .map(|i| RepBlock {
                reps: 4 + i,
                sq: 0.1 * i as f64,
                p_err: f64::NAN,
                cpu_seconds: 1e-6 * i as f64,
                display_sq: (i != 1).then_some(-0.0),
                wall_seconds: 2e-6,
                costs: Costs { samples: 10 * i, fetches: u64::MAX, ..Default::default() },
            })
            .collect()
    }

    fn same(a: &[[Moments; 3]], b: &[[Moments; 3]]) -> bool {
        a.len() == b.len() && a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| bits(x) == bits(y))
    }

    fn moments(grey: bool) -> Vec<[Moments; 3]> {
        (0..4)
            .map(|i| {
                let m = |c: usize| {
                    let mut m = Moments::default();
                    m.extend((0..5).map(|r| (i * 7 + r) as f64 * 0.37 + if grey { 0.0 } else { c as f64 }));
                    m
                };
                [m(0), m(1), m(2)]
            })
            .collect()
    }

    #[test]
    fn grey_and_coloured_moments_and_blocks_round_trip_bit_for_bit() {
        for grey_cell in [true, false] {
            let mut m = moments(grey_cell);
            m[2] = std::array::from_fn(|_| Moments::from_raw(5, [0.5, f64::INFINITY, f64::NEG_INFINITY, -1e-17]));
            assert_eq!(grey(&m), grey_cell);
            let packed = pack(&m, &blocks());
            assert_eq!(packed[8], if grey_cell { 1 } else { 3 });
            let (back, bl) = unpack(&packed).expect("unpacks");
            assert!(same(&back, &m));
            assert_eq!(bl.len(), 3);
            for (a, b) in bl.iter().zip(&blocks()) {
                assert_eq!(
                    (a.reps, a.sq, a.cpu_seconds, a.wall_seconds, &a.costs),
                    (b.reps, b.sq, b.cpu_seconds, b.wall_seconds, &b.costs)
                );
                assert_eq!(a.p_err.to_bits(), b.p_err.to_bits());
                assert_eq!(a.display_sq.map(f64::to_bits), b.display_sq.map(f64::to_bits));
            }
        }
    }

    #[test]
    fn a_channel_differing_in_one_bit_keeps_three_channels() {
        let mut m = moments(true);
        let (n, mut v) = m[3][1].raw();
        v[3] = f64::from_bits(v[3].to_bits() ^ 1);
        m[3][1] = Moments::from_raw(n, v);
        assert!(!grey(&m));
        assert!(same(&unpack(&pack(&m, &[])).expect("unpacks").0, &m));
    }

    #[test]
    fn every_cut_or_extended_part_is_refused() {
        let packed = pack(&moments(false), &blocks());
        for len in 0..packed.len() {
            assert!(unpack(&packed[..len]).is_err(), "cut at {len}");
        }
        let mut long = packed.clone();
        long.push(0);
        assert!(unpack(&long).expect_err("extended").contains("follow"));
        let mut bad = packed;
        bad[8] = 2;
        assert!(unpack(&bad).expect_err("channels").contains("stored channels"));
    }
}
