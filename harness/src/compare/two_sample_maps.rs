//! Where the two-sample test's integrals are pixels: their place (read from run A's
//! `integrals.csv`), the map of the per-pixel Welch statistic drawn by the report's pixel maps
//! ([`crate::output::html::pixel_maps`]: A's mean and standard error in place of the mean, B's in
//! place of the reference, so its z is the Welch t and its relative error `|A - B| / |B|`), and
//! the tiles (`two_sample_tiles.csv`).

use super::two_sample::{IntegralTest, TwoSample};
use crate::error::Result;
use crate::output::html::pixel_maps::{pixel_maps, PixelGroup};
use crate::output::integrals::IntegralRow;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Pixels a tile has on a side.
pub const TILE: usize = 8;

/// The pixel (column, row) of each (test bed, variant, integral) of one experiment.
type Places = HashMap<(String, String, usize), (usize, usize)>;

/// Pixel places by experiment folder, read once each.
#[derive(Default)]
pub struct Geometry {
    read: HashMap<PathBuf, Places>,
}

impl Geometry {
    /// Fills `px` and `py` of `tests` (of `testbed`/`variant`) from the `integrals.csv` of the
    /// experiment folder `dir`; left empty where it has none.
    pub fn place(&mut self, dir: &Path, testbed: &str, variant: &str, tests: &mut [IntegralTest]) -> Result<()> {
        if !self.read.contains_key(dir) {
            let rows = crate::output::html::read_integrals(dir)?;
            let places = rows.into_iter().map(|r| ((r.testbed, r.variant, r.integral), (r.px, r.py))).collect();
            self.read.insert(dir.to_path_buf(), places);
        }
        let places = &self.read[dir];
        for t in tests {
            if let Some(&(px, py)) = places.get(&(testbed.to_string(), variant.to_string(), t.integral)) {
                (t.px, t.py) = (Some(px), Some(py));
            }
        }
        Ok(())
    }
}

/// The per-pixel map of each row whose integrals are pixels of an image at least 2 x 2, with the
/// row's index.
pub fn maps(t: &TwoSample) -> Vec<(usize, PixelGroup)> {
    let mut out = Vec::new();
    for (k, r) in t.rows.iter().enumerate() {
        let rows: Vec<IntegralRow> = t
            .integrals
            .iter()
            .filter(|i| (&i.testbed, &i.variant, i.budget) == (&r.testbed, &r.variant, r.budget) && !i.p.is_nan())
            .filter_map(|i| {
                Some(IntegralRow {
                    testbed: i.testbed.clone(),
                    variant: i.variant.clone(),
                    estimator: format!("{} - {}", r.estimator_a, r.estimator_b),
                    integral: i.integral,
                    px: i.px?,
                    py: i.py?,
                    channel: i.channel,
                    reference: i.mean_b,
                    reference_se: i.se_b,
                    mean: i.mean_a,
                    std_err: i.se_a,
                    geometry: Vec::new(),
                    estimator_id: String::new(),
                })
            })
            .collect();
        out.extend(pixel_maps(&rows).into_iter().map(|g| (k, g)));
    }
    out
}

/// One tile of `two_sample_tiles.csv`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tile {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Budget per estimate.
    pub budget: u64,
    /// Frame of a sequence (0 for a still image).
    pub frame: usize,
    /// Tile column (pixels `TILE * tile_x ..`).
    pub tile_x: usize,
    /// Tile row.
    pub tile_y: usize,
    /// Pixels with a test in the tile.
    pub pixels: usize,
    /// Mean over them of the pixel's Welch t (its channel of largest |t|). With independent
    /// pixels, `mean_z * sqrt(pixels)` is standard normal when the two agree.
    pub mean_z: f64,
}

/// The tiles of every map.
pub fn tiles(t: &TwoSample, maps: &[(usize, PixelGroup)]) -> Vec<Tile> {
    let mut out = Vec::new();
    for (k, g) in maps {
        let r = &t.rows[*k];
        let Some(z) = g.estimators.first().map(|e| &e.z) else { continue };
        let (w, h) = (g.width, g.height);
        for frame in 0..g.frames {
            for ty in 0..h.div_ceil(TILE) {
                for tx in 0..w.div_ceil(TILE) {
                    let zs: Vec<f64> = (ty * TILE..((ty + 1) * TILE).min(h))
                        .flat_map(|y| (tx * TILE..((tx + 1) * TILE).min(w)).map(move |x| frame * w * h + y * w + x))
                        .map(|i| z[i])
                        .filter(|z| z.is_finite())
                        .collect();
                    out.push(Tile {
                        testbed: r.testbed.clone(),
                        variant: r.variant.clone(),
                        budget: r.budget,
                        frame,
                        tile_x: tx,
                        tile_y: ty,
                        pixels: zs.len(),
                        mean_z: if zs.is_empty() { f64::NAN } else { zs.iter().sum::<f64>() / zs.len() as f64 },
                    });
                }
            }
        }
    }
    out
}

/// `two_sample_tiles.csv`.
pub fn tiles_csv_bytes(tiles: &[Tile]) -> std::result::Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for t in tiles {
        w.serialize(t)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test(integral: usize, px: usize, py: usize, mean_a: f64) -> IntegralTest {
        IntegralTest {
            testbed: "t".into(),
            variant: "v".into(),
            budget: 4,
            integral,
            px: Some(px),
            py: Some(py),
            channel: 0,
            mean_a,
            se_a: 0.1,
            mean_b: 1.0,
            se_b: 0.1,
            t: f64::NAN,
            df: f64::NAN,
            p: 0.5,
        }
    }

    #[test]
    fn the_map_z_is_the_welch_t_and_tiles_average_it() {
        // A 10 x 2 image: tiles 8 and 2 pixels wide.
        let integrals: Vec<IntegralTest> = (0..20)
            .map(|i| test(i, i % 10, i / 10, if i % 10 < 8 { 1.0 } else { 1.0 + 3.0 * 0.02f64.sqrt() }))
            .collect();
        let (row, _) = super::super::two_sample::test_cell(&Default::default(), &Default::default());
        let row = super::super::two_sample::TwoSampleRow {
            testbed: "t".into(),
            variant: "v".into(),
            budget: 4,
            estimator_a: "a".into(),
            estimator_b: "b".into(),
            ..row
        };
        let t = TwoSample { estimator_a: "a".into(), estimator_b: "b".into(), rows: vec![row], integrals };
        let m = maps(&t);
        assert_eq!(m.len(), 1);
        let g = &m[0].1;
        assert_eq!((g.width, g.height, g.frames), (10, 2, 1));
        // (mean_a - mean_b) / sqrt(se_a^2 + se_b^2) = 3 sqrt(0.02) / sqrt(0.02) = 3 on the right.
        assert!((g.estimators[0].z[9] - 3.0).abs() < 1e-9 && g.estimators[0].z[0] == 0.0);
        let tiles = tiles(&t, &m);
        assert_eq!(tiles.len(), 2);
        assert_eq!((tiles[0].pixels, tiles[0].mean_z), (16, 0.0));
        assert!((tiles[1].mean_z - 3.0).abs() < 1e-9 && tiles[1].pixels == 4);
    }
}
