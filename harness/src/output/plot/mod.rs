//! Plots of a run (book: outputs.md), written as SVG and PNG, atomically, in one style ([`style`]): per
//! (test bed, variant) one figure of log-log panels ([`testbed`]): RMSE against the budget with a
//! bootstrap band and a slope -1/2 guide, efficiency against the budget, RMSE against CPU time
//! and, with speed-ups, the speed-up against the cost of a ray ([`ray_cost`]); one series per
//! estimator under its display name ([`names`]) with its fitted convergence slope in the legend.
//! Experiments draw their own figures with [`write_figure`] and [`write_panels`], heat maps
//! ([`heatmap`]), per-pixel maps ([`maps`]) and claims across settings ([`claim_sweep`]).
//!
//! Text uses the DejaVu Sans font bundled in `assets/fonts` (no system fonts are needed).

pub mod claim_sweep;
mod draw;
pub mod figure;
pub mod heatmap;
pub mod maps;
pub mod names;
pub mod png;
pub mod ray_cost;
pub mod style;
pub mod testbed;
#[cfg(test)]
pub(crate) mod tests;
mod ticks;

pub use figure::{Figure, Guide, Key, Line, Panels, Series};
pub use names::DisplayNames;

use crate::error::{HarnessError, Result};
use crate::output::{write_atomic, RunReport};
use plotters::coord::Shift;
use plotters::drawing::{DrawingArea, IntoDrawingArea};
use plotters::prelude::SVGBackend;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// The figure a run draws per (test bed, variant).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotKind {
    /// RMSE, efficiency and RMSE against time (and the speed-up against the cost of a ray), one
    /// panel each.
    Convergence,
}

impl PlotKind {
    /// Every kind, in the order the figures are written.
    pub const ALL: [PlotKind; 1] = [PlotKind::Convergence];

    /// The file-name suffix (`convergence`).
    pub fn suffix(self) -> &'static str {
        match self {
            PlotKind::Convergence => "convergence",
        }
    }
}

/// Replaces every character other than ASCII letters, digits, `-` and `_` with `_`.
pub fn sanitize(name: &str) -> String {
    let s: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if s.is_empty() {
        "_".to_string()
    } else {
        s
    }
}

/// The file stem (no extension) of a plot: `<testbed>_<variant>_<kind>`, sanitised.
pub fn plot_stem(testbed: &str, variant: &str, kind: PlotKind) -> String {
    format!("{}_{}_{}", sanitize(testbed), sanitize(variant), kind.suffix())
}

/// The axis title for a budget kind (`samples`, `fetches`, `micros`).
pub fn budget_axis_label(kind: &str) -> String {
    match kind {
        "samples" => "samples per pixel (spp)".to_string(),
        "fetches" => "fetches per pixel".to_string(),
        "micros" => "microseconds".to_string(),
        other => other.to_string(),
    }
}

/// The paper label of an estimator (its name when the report has none).
pub fn label_of<'a>(report: &'a RunReport, estimator: &'a str) -> &'a str {
    report.labels.iter().find(|(n, _)| n == estimator).map(|(_, l)| l.as_str()).unwrap_or(estimator)
}

static FONT: Once = Once::new();
static FONT_OK: AtomicBool = AtomicBool::new(false);

fn ensure_font(dir: &Path) -> Result<()> {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
        let ok = plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, bytes).is_ok();
        FONT_OK.store(ok, Ordering::SeqCst);
    });
    if FONT_OK.load(Ordering::SeqCst) {
        Ok(())
    } else {
        Err(HarnessError::write(dir, "cannot load the bundled font DejaVuSans.ttf"))
    }
}

/// Draws every figure of `report` into `dir` with registered labels as names
/// ([`write_plots_named`] with [`DisplayNames::NONE`]).
pub fn write_plots(report: &RunReport, dir: &Path) -> Result<Vec<PathBuf>> {
    write_plots_named(report, dir, &DisplayNames::NONE)
}

/// Draws the figure of every (test bed, variant) of `report` into `dir` (created if needed) and
/// returns the files written (an SVG and a PNG each; a (test bed, variant) in which no series
/// has two budgets is left out). `names` gives the legends' and titles' names.
pub fn write_plots_named(report: &RunReport, dir: &Path, names: &DisplayNames) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    if report.rows.is_empty() {
        return Ok(Vec::new());
    }
    let mut estimators: Vec<&str> = Vec::new();
    let mut groups: Vec<(&str, &str)> = Vec::new();
    for r in &report.rows {
        if !estimators.contains(&r.estimator.as_str()) {
            estimators.push(&r.estimator);
        }
        if !groups.contains(&(r.testbed.as_str(), r.variant.as_str())) {
            groups.push((&r.testbed, &r.variant));
        }
    }
    let mut written = Vec::new();
    let mut stems: Vec<String> = Vec::new();
    for (testbed, variant) in groups {
        for kind in PlotKind::ALL {
            let Some(fig) = testbed::figure(report, testbed, variant, &estimators, names) else { continue };
            let mut stem = plot_stem(testbed, variant, kind);
            if stems.contains(&stem) {
                let n = (2..).find(|n| !stems.contains(&format!("{stem}-{n}"))).unwrap_or(2);
                stem = format!("{stem}-{n}");
            }
            stems.push(stem.clone());
            written.extend(write_panels(dir, &stem, &fig)?);
        }
    }
    Ok(written)
}

/// Writes one chart as `<stem>.svg` and `<stem>.png` in `dir` (for experiments' own plots).
pub fn write_figure(dir: &Path, stem: &str, fig: &Figure) -> Result<Vec<PathBuf>> {
    write_panels(dir, stem, &Panels::single(fig))
}

/// Writes a figure of panels as `<stem>.svg` and `<stem>.png` in `dir`.
pub fn write_panels(dir: &Path, stem: &str, fig: &Panels) -> Result<Vec<PathBuf>> {
    let _phase = crate::run::phases::enter(crate::run::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    ensure_font(dir)?;
    let size = draw::size(fig);
    let (svg, png) = (dir.join(format!("{stem}.svg")), dir.join(format!("{stem}.png")));
    write_svg(&svg, size, |root| draw::render(&root, fig))?;
    png::write_png(&png, size, |root| draw::render(&root, fig))?;
    Ok(vec![svg, png])
}

/// A figure of `size` pixels rendered by `draw` (given an SVG drawing area) as SVG text.
pub(crate) fn svg_text(
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> std::result::Result<(), String>,
) -> std::result::Result<String, String> {
    let mut text = String::new();
    style::guarded(|| draw(SVGBackend::with_string(&mut text, size).into_drawing_area()))?;
    Ok(compact_svg(&text))
}

/// The same SVG, shorter: without the default `opacity="1"` plotters writes on every element and
/// with font sizes to two decimals (a third of a heat map's bytes).
fn compact_svg(text: &str) -> String {
    let text = text.replace(" opacity=\"1\"", "");
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    const KEY: &str = "font-size=\"";
    while let Some(i) = rest.find(KEY) {
        let (head, tail) = rest.split_at(i + KEY.len());
        out.push_str(head);
        let end = tail.find('"').unwrap_or(tail.len());
        let value = &tail[..end];
        match value.parse::<f64>() {
            Ok(v) => out.push_str(&format!("{}", (v * 100.0).round() / 100.0)),
            Err(_) => out.push_str(value),
        }
        rest = &tail[end..];
    }
    out.push_str(rest);
    out
}

/// Renders a figure of `size` pixels with `draw` (given an SVG drawing area) and writes it to
/// `path`, atomically.
pub fn write_svg(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> std::result::Result<(), String>,
) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    ensure_font(dir)?;
    let text = svg_text(size, draw).map_err(|e| HarnessError::write(path, e))?;
    write_atomic(path, text.as_bytes())
}
