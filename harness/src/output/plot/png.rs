//! PNG files of figures: a figure is rendered into an RGB buffer and written as an indexed
//! (palette) PNG, atomically. Plots use a handful of colours; only anti-aliased edges add more, so
//! a figure with at most 256 colours is stored exactly and a busier one keeps its 256 most
//! frequent colours, every other pixel taking the nearest of them (about 2% of the pixels of a
//! line plot, all on glyph and line edges). That makes a file about a sixth of the RGB encoding's,
//! and the same figure gives the same bytes every time.

use super::ensure_font;
use crate::error::{HarnessError, Result};
use crate::output::write_atomic;
use plotters::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// Renders a figure of `size` pixels with `draw` (given a bitmap drawing area) and writes it to
/// `path` as a PNG, atomically.
pub fn write_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> std::result::Result<(), String>,
) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    ensure_font(dir)?;
    let mut rgb = vec![255u8; size.0 as usize * size.1 as usize * 3];
    super::style::guarded(|| draw(BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area()))
        .map_err(|e| HarnessError::write(path, e))?;
    let bytes = encode(&rgb, size).map_err(|e| HarnessError::write(path, e))?;
    write_atomic(path, &bytes)
}

/// The palette (at most 256 colours, most frequent first, ties by colour) and each pixel's
/// index into it.
fn quantize(rgb: &[u8]) -> (Vec<[u8; 3]>, Vec<u8>) {
    let key = |p: &[u8]| u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]);
    let mut counts: HashMap<u32, u64> = HashMap::new();
    // Figures are mostly runs of one colour: count a run at once.
    let mut run = (u32::MAX, 0u64);
    for p in rgb.chunks_exact(3) {
        let k = key(p);
        if k == run.0 {
            run.1 += 1;
        } else {
            if run.1 > 0 {
                *counts.entry(run.0).or_default() += run.1;
            }
            run = (k, 1);
        }
    }
    if run.1 > 0 {
        *counts.entry(run.0).or_default() += run.1;
    }
    let mut by_count: Vec<(u32, u64)> = counts.into_iter().collect();
    by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let split = |c: u32| [(c >> 16) as u8, (c >> 8) as u8, c as u8];
    let palette: Vec<[u8; 3]> = by_count.iter().take(256).map(|(c, _)| split(*c)).collect();
    let mut index: HashMap<u32, u8> = HashMap::with_capacity(by_count.len());
    for (k, (c, _)) in by_count.iter().enumerate() {
        let i = if k < 256 {
            k
        } else {
            let [r, g, b] = split(*c);
            let d = |p: &[u8; 3]| {
                let (dr, dg, db) =
                    (i32::from(r) - i32::from(p[0]), i32::from(g) - i32::from(p[1]), i32::from(b) - i32::from(p[2]));
                dr * dr + dg * dg + db * db
            };
            (0..palette.len()).min_by_key(|&j| (d(&palette[j]), j)).unwrap_or(0)
        };
        index.insert(*c, i as u8);
    }
    let mut last = (u32::MAX, 0u8);
    let pixels = rgb
        .chunks_exact(3)
        .map(|p| {
            let k = key(p);
            if k != last.0 {
                last = (k, index[&k]);
            }
            last.1
        })
        .collect();
    (palette, pixels)
}

/// An indexed PNG of the RGB buffer `rgb` of `size` pixels (zlib's default level: the best level
/// takes half as long again for the same size on figures).
pub(super) fn encode(rgb: &[u8], (w, h): (u32, u32)) -> std::result::Result<Vec<u8>, String> {
    let (palette, pixels) = quantize(rgb);
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(palette.concat());
        enc.set_compression(png::Compression::Default);
        enc.set_filter(png::FilterType::NoFilter);
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&pixels).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// `data:image/png;base64,...` of PNG bytes, for an image embedded in an SVG.
pub(super) fn data_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", crate::output::html::png::base64(png))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn few_colours_are_kept_exactly_and_many_map_to_the_nearest_frequent_one() {
        let mut rgb = Vec::new();
        for i in 0..300u32 {
            // White dominates; then 299 distinct dark greys, one pixel each.
            let px = if i == 0 { [255, 255, 255] } else { [(i % 250) as u8, (i / 250) as u8, 0] };
            rgb.extend_from_slice(&px);
        }
        rgb.extend_from_slice(&[255, 255, 255].repeat(100));
        let (palette, pixels) = quantize(&rgb);
        assert_eq!(palette.len(), 256);
        assert_eq!(palette[0], [255, 255, 255]);
        let d = |p: &[u8], q: &[u8; 3]| (0..3).map(|c| (i32::from(p[c]) - i32::from(q[c])).pow(2)).sum::<i32>();
        for (p, i) in rgb.chunks_exact(3).zip(&pixels) {
            let q = palette[*i as usize];
            let best = palette.iter().map(|q| d(p, q)).min().unwrap();
            assert_eq!(d(p, &q), best, "{p:?} drawn as {q:?}, not the nearest");
        }
        let few = [[0u8, 0, 0], [10, 20, 30]].concat().repeat(8);
        let (palette, pixels) = quantize(&few);
        assert_eq!(palette.len(), 2);
        assert_eq!(pixels, [0, 1].repeat(8));
    }

    #[test]
    fn data_uris_are_base64() {
        assert_eq!(data_uri(b"Man"), "data:image/png;base64,TWFu");
        assert_eq!(data_uri(b"Ma"), "data:image/png;base64,TWE=");
        assert_eq!(data_uri(b"M"), "data:image/png;base64,TQ==");
        assert_eq!(data_uri(b""), "data:image/png;base64,");
    }

    #[test]
    fn a_figure_is_written_as_an_indexed_png_and_the_same_bytes_each_time() {
        let dir = tempfile::tempdir().unwrap();
        let draw = |area: DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>| {
            area.fill(&WHITE).map_err(|e| e.to_string())?;
            area.draw(&Circle::new((20, 20), 10, RED.filled())).map_err(|e| e.to_string())?;
            area.present().map_err(|e| e.to_string())
        };
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        write_png(&a, (64, 48), draw).unwrap();
        write_png(&b, (64, 48), draw).unwrap();
        let bytes = std::fs::read(&a).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert_eq!(bytes[25], 3, "colour type 3: indexed");
        assert_eq!(bytes, std::fs::read(&b).unwrap());
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "no temporary files left: {names:?}");
    }
}
