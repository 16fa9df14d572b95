//! Per-pixel maps drawn as images (paper 003 Fig. 4 and Fig. 7: weight maps, images and
//! variance images): a row of grey-scale panels, each with its label and value range, written
//! as SVG and PNG like every other plot. Bright means a high value; non-finite values are
//! drawn in red.

use super::{ensure_font, write_atomic, TMP_COUNTER};
use crate::error::{HarnessError, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

const FONT: &str = "sans-serif";
/// Panel side in pixels (the image is scaled by a whole factor to fit it).
const PANEL: u32 = 240;
const GAP: u32 = 20;
const TITLE_H: u32 = 44;
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

fn size(maps: &[Map]) -> (u32, u32) {
    let cols = maps.len().clamp(1, PER_ROW) as u32;
    let rows = maps.len().div_ceil(PER_ROW).max(1) as u32;
    (GAP + cols * (PANEL + GAP), TITLE_H + rows * (PANEL + LABEL_H + GAP))
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, maps: &[Map]) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let centre = Pos::new(HPos::Center, VPos::Top);
    let (w, _) = size(maps);
    let title_style = TextStyle::from((FONT, 18).into_font()).color(&BLACK).pos(centre);
    root.draw(&Text::new(title.to_string(), (w as i32 / 2, 12), title_style)).map_err(err)?;
    let label_style = TextStyle::from((FONT, 13).into_font()).color(&BLACK).pos(centre);
    for (k, m) in maps.iter().enumerate() {
        let (col, row) = ((k % PER_ROW) as u32, (k / PER_ROW) as u32);
        let x0 = (GAP + col * (PANEL + GAP)) as i32;
        let y0 = (TITLE_H + row * (PANEL + LABEL_H + GAP)) as i32;
        let cell = (PANEL / m.width.max(m.height).max(1) as u32).max(1) as i32;
        for (i, &v) in m.values.iter().enumerate().take(m.width * m.height) {
            let (px, py) = ((i % m.width) as i32, (i / m.width) as i32);
            let colour = m.scale.grey(v).map_or(RGBColor(220, 30, 30), |g| RGBColor(g, g, g));
            let a = (x0 + px * cell, y0 + py * cell);
            root.draw(&Rectangle::new([a, (a.0 + cell, a.1 + cell)], colour.filled())).map_err(err)?;
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
pub fn write_maps(dir: &Path, stem: &str, title: &str, maps: &[Map]) -> Result<Vec<PathBuf>> {
    let _phase = crate::phases::enter(crate::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    ensure_font(dir)?;
    let dims = size(maps);
    let svg = dir.join(format!("{stem}.svg"));
    let mut text = String::new();
    guarded(|| render(&SVGBackend::with_string(&mut text, dims).into_drawing_area(), title, maps))
        .map_err(|e| HarnessError::write(&svg, e))?;
    write_atomic(&svg, text.as_bytes())?;
    let png = dir.join(format!("{stem}.png"));
    let n = TMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(".{stem}.png.tmp-{}-{n}.png", std::process::id()));
    let result = guarded(|| render(&BitMapBackend::new(&tmp, dims).into_drawing_area(), title, maps))
        .and_then(|()| std::fs::rename(&tmp, &png).map_err(|e| e.to_string()));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        HarnessError::write(&png, e)
    })?;
    Ok(vec![svg, png])
}

fn guarded<F: FnOnce() -> Result<(), String>>(f: F) -> Result<(), String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))
        .unwrap_or_else(|_| Err("the plotting library panicked".to_string()))
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
            Map { label: "linear".into(), width: 4, height: 4, values: values.clone(), scale: lin },
            Map { label: "log".into(), width: 4, height: 4, values, scale: log },
        ];
        let files = write_maps(dir.path(), "maps", "test maps", &maps).expect("written");
        assert_eq!(files.len(), 2);
        let svg = std::fs::read_to_string(&files[0]).expect("svg");
        assert!(svg.contains("test maps") && svg.contains("log: black 1 .. white 15"));
        assert!(std::fs::metadata(&files[1]).expect("png").len() > 100);
    }
}
