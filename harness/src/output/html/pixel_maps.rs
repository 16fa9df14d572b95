//! Per-pixel maps of the largest budget for test beds whose integrals are pixels (a width and a
//! height of at least 2; frames of a sequence side by side): the z-score of each pixel's mean
//! against its reference, and its relative error. Drawn with the heat maps' colour scales
//! ([`crate::output::plot::heatmap::colour`]) as small inline PNG images, one pair per estimator.
//!
//! - z = (mean - reference) / sqrt(std_err^2 + reference_se^2) per channel; a pixel shows the
//!   channel of largest |z| (a zero denominator gives 0 when mean = reference, else +-infinity,
//!   drawn saturated).
//! - relative error = |mean - reference| / |reference| over the RGB channels (Euclidean norms);
//!   undefined (grey) where the reference is 0 and the mean is not.

use super::markup::{esc, table, Cell};
use super::png::Rgb8;
use crate::error::Result;
use crate::output::integrals::IntegralRow;
use crate::output::plot::heatmap::{colour, Fill, Scale};
use crate::output::query::Query;
use crate::output::report::sig;
use std::fmt::Write as _;

/// z beyond which the colour saturates.
const Z_LIMIT: f64 = 4.0;
/// The |z| a pixel is counted beyond (0.27% of pixels by chance without bias).
const Z_FLAG: f64 = 3.0;
/// Decades of relative error the colour scale spans at most.
const DECADES: f64 = 4.0;
/// Colour of frame gaps.
const GAP: [u8; 3] = [150, 150, 150];

/// The maps of one estimator: `frames x height x width` values, frame-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimatorMaps {
    /// Estimator name.
    pub estimator: String,
    /// z-score per pixel and frame.
    pub z: Vec<f64>,
    /// Relative error per pixel and frame.
    pub rel: Vec<f64>,
}

/// The maps of one (test bed, variant).
#[derive(Clone, Debug, PartialEq)]
pub struct PixelGroup {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Frames per pixel (1 for a still image).
    pub frames: usize,
    /// One entry per estimator, in the order of the rows.
    pub estimators: Vec<EstimatorMaps>,
}

fn first_seen<'a>(keys: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for k in keys {
        if !out.contains(&k) {
            out.push(k);
        }
    }
    out
}

/// The maps of every (test bed, variant) of `rows` whose integrals are pixels of an image at least
/// 2 x 2, in order of first appearance.
pub fn pixel_maps(rows: &[IntegralRow]) -> Vec<PixelGroup> {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !keys.contains(&(r.testbed.as_str(), r.variant.as_str())) {
            keys.push((&r.testbed, &r.variant));
        }
    }
    keys.into_iter()
        .filter_map(|(t, v)| {
            let rows: Vec<&IntegralRow> = Query::new(rows).testbed(t).variant(v).iter().collect();
            group(t, v, &rows)
        })
        .collect()
}

fn group(testbed: &str, variant: &str, rows: &[&IntegralRow]) -> Option<PixelGroup> {
    let width = rows.iter().map(|r| r.px + 1).max()?;
    let height = rows.iter().map(|r| r.py + 1).max()?;
    let integrals = rows.iter().map(|r| r.integral + 1).max()?;
    if width < 2 || height < 2 {
        return None;
    }
    let frames = (integrals / (width * height)).max(1);
    let estimators = first_seen(rows.iter().map(|r| r.estimator.as_str()))
        .into_iter()
        .map(|e| {
            let mine: Vec<&&IntegralRow> = Query::new(rows).estimator(e).iter().collect();
            maps_of(e, &mine, width, height, frames)
        })
        .collect();
    Some(PixelGroup { testbed: testbed.into(), variant: variant.into(), width, height, frames, estimators })
}

fn maps_of(estimator: &str, rows: &[&&IntegralRow], width: usize, height: usize, frames: usize) -> EstimatorMaps {
    let n = width * height * frames;
    let (mut z, mut dev2, mut ref2, mut seen) = (vec![f64::NAN; n], vec![0.0; n], vec![0.0; n], vec![false; n]);
    for r in rows {
        let k = (r.integral % frames) * width * height + r.py * width + r.px;
        if r.px >= width || r.py >= height || k >= n {
            continue;
        }
        let d = r.mean - r.reference;
        let spread = (r.std_err * r.std_err + r.reference_se * r.reference_se).sqrt();
        let zc = if spread > 0.0 {
            d / spread
        } else if d == 0.0 {
            0.0
        } else {
            d.signum() * f64::INFINITY
        };
        if !zc.is_nan() && (z[k].is_nan() || zc.abs() > z[k].abs()) {
            z[k] = zc;
        }
        dev2[k] += d * d;
        ref2[k] += r.reference * r.reference;
        seen[k] = true;
    }
    let rel = (0..n)
        .map(|k| match (seen[k], dev2[k], ref2[k]) {
            (false, ..) => f64::NAN,
            (true, 0.0, _) => 0.0,
            (true, d, r) if r > 0.0 => (d / r).sqrt(),
            _ => f64::NAN,
        })
        .collect();
    EstimatorMaps { estimator: estimator.into(), z, rel }
}

/// The log10 range the relative-error colours span in a group: from the 1st to the 99th
/// percentile of its positive finite values (a few pixels with a near-zero reference do not wash
/// out the rest), at most [`DECADES`] and at least half a decade wide.
fn rel_range(g: &PixelGroup) -> (f64, f64) {
    let mut logs: Vec<f64> =
        g.estimators.iter().flat_map(|e| &e.rel).filter(|v| v.is_finite() && **v > 0.0).map(|v| v.log10()).collect();
    if logs.is_empty() {
        return (-3.0, 0.0);
    }
    logs.sort_by(f64::total_cmp);
    let at = |q: f64| logs[((logs.len() - 1) as f64 * q).round() as usize];
    let hi = at(0.99);
    (at(0.01).max(hi - DECADES).min(hi - 0.5), hi)
}

fn rgb(c: plotters::style::RGBColor) -> [u8; 3] {
    [c.0, c.1, c.2]
}

fn z_scale() -> Scale {
    Scale::Diverging { limit: Z_LIMIT, label: "z".into() }
}

fn rel_scale((lo, hi): (f64, f64)) -> Scale {
    Scale::Sequential { lo, hi, label: "log10 relative error".into() }
}

fn z_colour(z: f64) -> [u8; 3] {
    let v = if z.is_infinite() { z.signum() * Z_LIMIT } else { z };
    rgb(colour(&if v.is_nan() { Fill::Empty } else { Fill::Value(v) }, &z_scale()))
}

fn rel_colour(rel: f64, range: (f64, f64)) -> [u8; 3] {
    let fill = match rel {
        r if r.is_nan() => Fill::Empty,
        r if r <= 0.0 => Fill::Value(range.0),
        r => Fill::Value(r.log10()),
    };
    rgb(colour(&fill, &rel_scale(range)))
}

/// One map as an image: frames left to right with a 1-pixel gap.
fn image(g: &PixelGroup, values: &[f64], paint: impl Fn(f64) -> [u8; 3]) -> Rgb8 {
    let (w, h, f) = (g.width, g.height, g.frames);
    let mut img = Rgb8::filled(f * w + f - 1, h, GAP);
    for frame in 0..f {
        for y in 0..h {
            for x in 0..w {
                img.set(frame * (w + 1) + x, y, paint(values[frame * w * h + y * w + x]));
            }
        }
    }
    img
}

/// A CSS gradient of `scale` from `lo` to `hi` (9 stops).
fn gradient(scale: &Scale, lo: f64, hi: f64) -> String {
    let stops: Vec<String> = (0..9)
        .map(|k| {
            let [r, g, b] = rgb(colour(&Fill::Value(lo + (hi - lo) * k as f64 / 8.0), scale));
            format!("rgb({r},{g},{b})")
        })
        .collect();
    format!("<span class=\"bar\" style=\"background: linear-gradient(to right, {})\"></span>", stops.join(", "))
}

fn stats(m: &EstimatorMaps) -> [String; 3] {
    let zs: Vec<f64> = m.z.iter().copied().filter(|z| !z.is_nan()).collect();
    let flagged = zs.iter().filter(|z| z.abs() > Z_FLAG).count();
    let share =
        if zs.is_empty() { "-".to_string() } else { format!("{}%", sig(100.0 * flagged as f64 / zs.len() as f64, 2)) };
    let max = zs.iter().fold(f64::NAN, |a: f64, z| a.max(z.abs()));
    let mut rel: Vec<f64> = m.rel.iter().copied().filter(|r| r.is_finite()).collect();
    rel.sort_by(f64::total_cmp);
    let median = if rel.is_empty() { f64::NAN } else { rel[rel.len() / 2] };
    [share, sig(max, 3), sig(median, 3)]
}

/// The HTML of one group's maps: the scales, then a table with a row per estimator (its name
/// through `label`).
pub fn render(g: &PixelGroup, label: &dyn Fn(&str) -> String) -> Result<String> {
    let range = rel_range(g);
    // About 160 pixels a side for an image, at most 360 wide for a strip of frames.
    let strip = g.frames * g.width + g.frames - 1;
    let zoom = (160 / g.width.max(g.height)).min(360 / strip).clamp(1, 16);
    let mut out = String::new();
    let frames =
        if g.frames > 1 { format!(" Each strip shows the {} frames left to right.", g.frames) } else { String::new() };
    let _ = writeln!(
        out,
        "<p class=\"muted\">At the largest budget, {} x {} pixels. z = (mean - reference) / sqrt(std_err² + reference_se²), \
         the channel of largest |z|; relative error = |mean - reference| / |reference| over the RGB channels.{frames}</p>",
        g.width, g.height
    );
    let _ = writeln!(
        out,
        "<p>z: -{Z_LIMIT}{}+{Z_LIMIT} (blue: below the reference, red: above) &nbsp; relative error: {}{}{} (log scale) \
         &nbsp; <span class=\"badge\">grey: undefined</span></p>",
        gradient(&z_scale(), -Z_LIMIT, Z_LIMIT),
        sig(10f64.powf(range.0), 2),
        gradient(&rel_scale(range), range.0, range.1),
        sig(10f64.powf(range.1), 2),
    );
    let mut rows = Vec::new();
    for m in &g.estimators {
        let (iw, ih) = ((g.frames * g.width + g.frames - 1) * zoom, g.height * zoom);
        let img = |values: &[f64], paint: &dyn Fn(f64) -> [u8; 3], what: &str| -> Result<String> {
            let uri = image(g, values, paint).data_uri()?;
            let alt = esc(&format!("{what} of {}", m.estimator));
            Ok(format!("<img class=\"px\" width=\"{iw}\" height=\"{ih}\" alt=\"{alt}\" src=\"{uri}\">"))
        };
        let [share, max, median] = stats(m);
        rows.push((
            String::new(),
            vec![
                Cell::text(&label(&m.estimator)),
                Cell::html(img(&m.z, &z_colour, "z map")?),
                Cell::html(img(&m.rel, &|v| rel_colour(v, range), "relative error map")?),
                Cell::num(&share),
                Cell::num(&max),
                Cell::num(&median),
            ],
        ));
    }
    let header = ["estimator", "z", "relative error", "|z| > 3 (0.27% by chance)", "max |z|", "median relative error"];
    out.push_str(&table(&header, rows));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(estimator: &str, integral: usize, w: usize, frames: usize, channel: usize, mean: f64) -> IntegralRow {
        let p = integral / frames;
        IntegralRow {
            testbed: "img".into(),
            variant: "v".into(),
            estimator: estimator.into(),
            integral,
            px: p % w,
            py: p / w,
            channel,
            reference: 1.0,
            reference_se: 0.0,
            mean,
            std_err: 0.1,
            geometry: Vec::new(),
            estimator_id: estimator.into(),
        }
    }

    #[test]
    fn maps_place_pixels_and_frames_and_take_the_largest_channel_z() {
        // 3 x 2 pixels, 2 frames; pixel (2, 1) of frame 1 is off by +0.5 in channel 1.
        let (w, frames) = (3, 2);
        let mut rows = Vec::new();
        for i in 0..w * 2 * frames {
            for c in 0..3 {
                let off = i == (w + 2) * frames + 1 && c == 1;
                rows.push(row("a", i, w, frames, c, if off { 1.5 } else { 1.0 }));
            }
        }
        let groups = pixel_maps(&rows);
        assert_eq!(groups.len(), 1);
        let g = &groups[0];
        assert_eq!((g.width, g.height, g.frames), (3, 2, 2));
        let m = &g.estimators[0];
        let k = w * 2 + w + 2; // frame 1, row 1, column 2
        assert!((m.z[k] - 5.0).abs() < 1e-12, "{:?}", m.z);
        assert!((m.rel[k] - 0.5 / 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(m.z.iter().filter(|z| **z != 0.0).count(), 1);
        let html = render(g, &|e| e.to_uppercase()).expect("renders");
        assert!(html.contains("<td>A</td>") && html.contains("src=\"data:image/png;base64,"), "{html}");
        assert!(html.contains("width=\"") && html.contains("the 2 frames"));
        assert_eq!(stats(m)[0], "8.3%", "1 of 12 pixels beyond |z| = 3");
    }

    #[test]
    fn lines_and_single_values_get_no_map_and_zero_spread_saturates() {
        let rows: Vec<IntegralRow> = (0..4).map(|i| row("a", i, 4, 1, 0, 1.0)).collect();
        assert!(pixel_maps(&rows).is_empty(), "a 4 x 1 line is not an image");
        let mut r = row("a", 0, 2, 1, 0, 2.0);
        r.std_err = 0.0;
        let m = maps_of("a", &[&&r], 2, 2, 1);
        assert_eq!(m.z[0], f64::INFINITY);
        assert!(m.z[1].is_nan() && m.rel[1].is_nan(), "pixels without rows are undefined");
        assert_eq!(z_colour(f64::INFINITY), z_colour(Z_LIMIT));
        assert_eq!(rel_colour(f64::NAN, (-3.0, 0.0)), [235, 235, 235]);
    }

    #[test]
    fn a_few_outliers_do_not_set_the_relative_error_scale() {
        let mut rel: Vec<f64> = (0..200).map(|i| 10f64.powf(-3.0 + 2.0 * i as f64 / 199.0)).collect();
        rel.push(1e3);
        let g = PixelGroup {
            testbed: "t".into(),
            variant: "v".into(),
            width: 201,
            height: 1,
            frames: 1,
            estimators: vec![EstimatorMaps { estimator: "a".into(), z: vec![0.0; 201], rel }],
        };
        let (lo, hi) = rel_range(&g);
        assert!((hi - -1.0).abs() < 0.05 && (lo - -3.0).abs() < 0.05, "({lo}, {hi})");
    }
}
