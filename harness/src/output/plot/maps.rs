//! Per-pixel maps drawn as images (paper 003 Fig. 4 and Fig. 7: weight maps, images and
//! variance images): rows of grey-scale panels, each with its label and value range, written
//! as SVG and PNG in the figures' style ([`super::style`]). Bright means a high value; non-finite
//! values are drawn in red. A map with a heading starts a new row under that heading, so one
//! figure holds the maps of several variants.

use super::style::{self, text, MARGIN};
use crate::error::{HarnessError, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// Panel side in pixels (the image is scaled by a whole factor to fit it).
const PANEL: u32 = 240;
const GAP: u32 = 20;
const TITLE_H: u32 = 44;
const HEADING: u32 = 28;
const LABEL_H: u32 = 40;
const PER_ROW: usize = 4;

/// How values map to grey levels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// `lo` black, `hi` white, linear between.
    Linear(f64, f64),
    /// `lo` black, `hi` white, linear in `log10` between (values <= 0 are black).
    Log(f64, f64),
}

impl Scale {
    /// A log scale over the positive finite values of every slice.
    pub fn log_of<'a>(values: impl IntoIterator<Item = &'a [f64]>) -> Scale {
        let (lo, hi) = finite_range(values.into_iter().flatten().copied().filter(|v| *v > 0.0));
        if lo.is_finite() && hi > lo {
            Scale::Log(lo, hi)
        } else {
            Scale::Log(1e-3, 1.0)
        }
    }
    fn grey(self, v: f64) -> Option<u8> {
        if !v.is_finite() {
            return None;
        }
        let t = match self {
            Scale::Linear(lo, hi) => (v - lo) / (hi - lo),
            Scale::Log(lo, hi) if v > 0.0 => (v / lo).log10() / (hi / lo).log10(),
            Scale::Log(..) => 0.0,
        };
        Some((t.clamp(0.0, 1.0) * 255.0).round() as u8)
    }
    fn describe(self) -> String {
        match self {
            Scale::Linear(lo, hi) => format!("black {} .. white {}", short(lo), short(hi)),
            Scale::Log(lo, hi) => format!("log: black {} .. white {}", short(lo), short(hi)),
        }
    }
}

fn short(v: f64) -> String {
    if v == 0.0 || (1e-2..1e4).contains(&v.abs()) {
        format!("{}", (v * 1000.0).round() / 1000.0)
    } else {
        format!("{v:.2e}")
    }
}

fn finite_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
}

/// One panel: a `width x height` map in row-major order (row 0 at the top).
pub struct Map {
    /// A heading: when not empty the map starts a new row, under this text.
    pub heading: String,
    /// The panel's label.
    pub label: String,
    /// Map width.
    pub width: usize,
    /// Map height.
    pub height: usize,
    /// `width x height` values.
    pub values: Vec<f64>,
    /// Grey scale.
    pub scale: Scale,
}

/// Panel origins (left, top), headings (top, text) and the figure size.
type Layout = (Vec<(u32, u32)>, Vec<(u32, String)>, (u32, u32));

/// Panel origins (left, top), headings (top, text) and the figure size: maps flow left to right,
/// [`PER_ROW`] to a row, and a heading starts a new row.
fn layout(maps: &[Map]) -> Layout {
    let row_h = PANEL + LABEL_H + GAP;
    let (mut col, mut y, mut cols) = (0usize, TITLE_H, 1usize);
    let (mut at, mut headings) = (Vec::new(), Vec::new());
    for (k, m) in maps.iter().enumerate() {
        if k > 0 && (col == PER_ROW || !m.heading.is_empty()) {
            col = 0;
            y += row_h;
        }
        if !m.heading.is_empty() {
            headings.push((y, m.heading.clone()));
            y += HEADING;
        }
        at.push((GAP + col as u32 * (PANEL + GAP), y));
        col += 1;
        cols = cols.max(col);
    }
    (at, headings, (GAP + cols as u32 * (PANEL + GAP), y + row_h))
}

/// The colour of a map value on its scale (red where not finite).
fn rgb(m: &Map, v: f64) -> RGBColor {
    m.scale.grey(v).map_or(RGBColor(220, 30, 30), |g| RGBColor(g, g, g))
}

/// Draws the title, headings, frames and labels, and the maps' pixels when `pixels` (the SVG
/// embeds each map as an image instead: [`images`]).
fn render<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    maps: &[Map],
    pixels: bool,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let (at, headings, (w, _)) = layout(maps);
    let centre = Pos::new(HPos::Center, VPos::Top);
    let title_style = text(style::TITLE_SIZE, BLACK).pos(centre);
    root.draw(&Text::new(title.to_string(), (w as i32 / 2, 10), title_style)).map_err(err)?;
    for (y, heading) in &headings {
        let t = text(style::PANEL_TITLE_SIZE, BLACK).pos(Pos::new(HPos::Left, VPos::Center));
        root.draw(&Text::new(heading.clone(), (MARGIN as i32, (y + HEADING / 2) as i32), t)).map_err(err)?;
    }
    let label_style = text(style::LEGEND_SIZE, BLACK).pos(centre);
    for (m, &(x0, y0)) in maps.iter().zip(&at) {
        let (x0, y0) = (x0 as i32, y0 as i32);
        let cell = (PANEL / m.width.max(m.height).max(1) as u32).max(1) as i32;
        for (i, &v) in m.values.iter().enumerate().take(m.width * m.height).filter(|_| pixels) {
            let (px, py) = ((i % m.width) as i32, (i / m.width) as i32);
            let a = (x0 + px * cell, y0 + py * cell);
            root.draw(&Rectangle::new([a, (a.0 + cell, a.1 + cell)], rgb(m, v).filled())).map_err(err)?;
        }
        let frame = [(x0 - 1, y0 - 1), (x0 + cell * m.width as i32, y0 + cell * m.height as i32)];
        root.draw(&Rectangle::new(frame, RGBColor(120, 120, 120).stroke_width(1))).map_err(err)?;
        let lx = x0 + PANEL as i32 / 2;
        let ly = y0 + cell * m.height as i32 + 5;
        root.draw(&Text::new(m.label.clone(), (lx, ly), label_style.clone())).map_err(err)?;
        root.draw(&Text::new(m.scale.describe(), (lx, ly + 17), label_style.clone())).map_err(err)?;
    }
    root.present().map_err(err)
}

/// Writes the maps as `<stem>.svg` and `<stem>.png` in `dir`.
pub fn write_maps(dir: &Path, stem: &str, title: &str, maps: &[Map]) -> crate::error::Result<Vec<PathBuf>> {
    let _phase = crate::run::phases::enter(crate::run::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    let size = layout(maps).2;
    let (svg, png) = (dir.join(format!("{stem}.svg")), dir.join(format!("{stem}.png")));
    let mut text = super::svg_text(size, |root| render(&root, title, maps, false))
        .and_then(|t| images(maps).map(|i| (t, i)))
        .map(|(t, i)| {
            let end = t.rfind("</svg>").unwrap_or(t.len());
            format!("{}{i}{}", &t[..end], &t[end..])
        })
        .map_err(|e| HarnessError::write(&svg, e))?;
    text.shrink_to_fit();
    crate::output::write_atomic(&svg, text.as_bytes())?;
    super::png::write_png(&png, size, |root| render(&root, title, maps, true))?;
    Ok(vec![svg, png])
}

/// Each map as an `<image>` element holding a PNG of its pixels, scaled without smoothing: far
/// smaller than a rectangle per pixel.
fn images(maps: &[Map]) -> Result<String, String> {
    let mut out = String::new();
    for (m, &(x0, y0)) in maps.iter().zip(&layout(maps).0) {
        if m.width == 0 || m.height == 0 {
            continue;
        }
        let mut rgb_pixels = Vec::with_capacity(m.width * m.height * 3);
        for i in 0..m.width * m.height {
            let c = rgb(m, m.values.get(i).copied().unwrap_or(f64::NAN));
            rgb_pixels.extend_from_slice(&[c.0, c.1, c.2]);
        }
        let png = super::png::encode(&rgb_pixels, (m.width as u32, m.height as u32))?;
        let cell = (PANEL / m.width.max(m.height) as u32).max(1);
        out.push_str(&format!(
            "<image x=\"{x0}\" y=\"{y0}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" href=\"{}\"/>\n",
            cell * m.width as u32,
            cell * m.height as u32,
            super::png::data_uri(&png)
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_are_written_and_scales_handle_zeros_and_non_finite_values() {
        let dir = tempfile::tempdir().expect("tempdir");
        let values: Vec<f64> = (0..16).map(|i| if i == 5 { f64::NAN } else { i as f64 }).collect();
        let log = Scale::log_of([values.as_slice()]);
        assert_eq!(log, Scale::Log(1.0, 15.0));
        assert_eq!(log.grey(0.0), Some(0));
        assert_eq!(log.grey(15.0), Some(255));
        assert_eq!(log.grey(f64::NAN), None);
        let lin = Scale::Linear(0.0, 15.0);
        assert_eq!((lin.grey(7.5), lin.grey(-1.0), lin.grey(99.0)), (Some(128), Some(0), Some(255)));
        let maps = vec![
            Map {
                heading: String::new(),
                label: "linear".into(),
                width: 4,
                height: 4,
                values: values.clone(),
                scale: lin,
            },
            Map { heading: "below".into(), label: "log".into(), width: 4, height: 4, values, scale: log },
        ];
        let files = write_maps(dir.path(), "maps", "test maps", &maps).expect("written");
        assert_eq!(files.len(), 2);
        let svg = std::fs::read_to_string(&files[0]).expect("svg");
        assert!(svg.contains("test maps") && svg.contains("log: black 1 .. white 15") && svg.contains("below"));
        assert_eq!(svg.matches("<image ").count(), 2, "each map one embedded image");
        let (at, headings, _) = layout(&maps);
        assert!(at[1].1 > at[0].1 && headings.len() == 1, "a heading starts a new row: {at:?}");
        assert!(std::fs::metadata(&files[1]).expect("png").len() > 100);
    }
}
