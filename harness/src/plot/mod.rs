//! Log-log plots of a run (SPEC §8): per (test bed, variant), RMSE and efficiency against the
//! budget and RMSE against time, one series per estimator with its paper label and (RMSE plots)
//! its fitted convergence slope in the legend; with speed-ups, the speed-up against the cost of a
//! ray ([`ray_cost`]). Each plot is written as SVG and PNG, atomically.
//!
//! Text uses the DejaVu Sans font bundled in `assets/fonts` (no system fonts are needed).

pub mod claim_sweep;
mod draw;
pub mod heatmap;
pub mod maps;
pub mod ray_cost;
#[cfg(test)]
pub(crate) mod tests;

use crate::error::{HarnessError, Result};
use crate::metrics::SummaryRow;
use crate::output::{write_atomic, RunReport};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Once;

/// Width and height in pixels of every plot (PNG and SVG).
pub const PLOT_SIZE: (u32, u32) = (900, 650);

/// The quantity a plot shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotKind {
    /// RMSE against the budget.
    Rmse,
    /// Efficiency 1 / (variance x CPU seconds) against the budget.
    Efficiency,
    /// RMSE against CPU seconds per estimate.
    RmseVsTime,
}

impl PlotKind {
    /// Every kind, in the order the plots are written.
    pub const ALL: [PlotKind; 3] = [PlotKind::Rmse, PlotKind::Efficiency, PlotKind::RmseVsTime];

    /// The file-name suffix (`rmse`, `efficiency`, `rmse_vs_time`).
    pub fn suffix(self) -> &'static str {
        match self {
            PlotKind::Rmse => "rmse",
            PlotKind::Efficiency => "efficiency",
            PlotKind::RmseVsTime => "rmse_vs_time",
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

/// One series of a figure: legend text, style index (colour and marker) and points.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Style index: the same index gives the same colour and marker in every figure.
    pub style: usize,
    /// The points (x, y), both positive on log axes.
    pub points: Vec<(f64, f64)>,
}

/// Everything needed to draw one plot.
pub struct Figure {
    /// Title.
    pub title: String,
    /// x-axis title.
    pub x_desc: String,
    /// y-axis title.
    pub y_desc: String,
    /// The series.
    pub series: Vec<Series>,
}

static FONT: Once = Once::new();
static FONT_OK: AtomicBool = AtomicBool::new(false);
static TMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

fn ensure_font(dir: &Path) -> Result<()> {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        let ok = plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, bytes).is_ok();
        FONT_OK.store(ok, Ordering::SeqCst);
    });
    if FONT_OK.load(Ordering::SeqCst) {
        Ok(())
    } else {
        Err(HarnessError::write(dir, "cannot load the bundled font DejaVuSans.ttf"))
    }
}

/// Draws every plot of `report` into `dir` (created if needed) and returns the files written
/// (an SVG and a PNG per plot; plots in which no series has two drawable points are left out).
pub fn write_plots(report: &RunReport, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    if report.rows.is_empty() {
        return Ok(Vec::new());
    }
    ensure_font(dir)?;
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
        let rows: Vec<&SummaryRow> =
            report.rows.iter().filter(|r| r.testbed == testbed && r.variant == variant).collect();
        for kind in PlotKind::ALL {
            let fig = figure(report, testbed, variant, &rows, &estimators, kind);
            // A log-log plot against the budget needs two budgets: a single-budget sweep (e.g.
            // canonical-sweep, which draws heat maps instead) gets no line plots.
            if fig.series.iter().all(|s| s.points.len() < 2) {
                continue;
            }
            let mut stem = plot_stem(testbed, variant, kind);
            if stems.contains(&stem) {
                let n = (2..).find(|n| !stems.contains(&format!("{stem}-{n}"))).unwrap_or(2);
                stem = format!("{stem}-{n}");
            }
            stems.push(stem.clone());
            let svg = dir.join(format!("{stem}.svg"));
            write_svg(&svg, &fig)?;
            written.push(svg);
            let png = dir.join(format!("{stem}.png"));
            write_png(&png, &fig)?;
            written.push(png);
        }
    }
    for (stem, fig) in ray_cost::figures(report) {
        written.extend(write_figure(dir, &stem, &fig)?);
    }
    Ok(written)
}

/// Writes one figure as `<stem>.svg` and `<stem>.png` in `dir` (for experiments' own plots).
pub fn write_figure(dir: &Path, stem: &str, fig: &Figure) -> Result<Vec<PathBuf>> {
    let _phase = crate::phases::enter(crate::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    ensure_font(dir)?;
    let (svg, png) = (dir.join(format!("{stem}.svg")), dir.join(format!("{stem}.png")));
    write_svg(&svg, fig)?;
    write_png(&png, fig)?;
    Ok(vec![svg, png])
}

fn positive(x: f64, y: f64) -> Option<(f64, f64)> {
    (x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()).then_some((x, y))
}

fn figure(
    report: &RunReport,
    testbed: &str,
    variant: &str,
    rows: &[&SummaryRow],
    estimators: &[&str],
    kind: PlotKind,
) -> Figure {
    let budget_kind = rows.first().map(|r| r.budget_kind.as_str()).unwrap_or("samples");
    let (what, x_desc, y_desc) = match kind {
        PlotKind::Rmse => ("RMSE vs budget", budget_axis_label(budget_kind), "RMSE"),
        PlotKind::Efficiency => {
            ("efficiency vs budget", budget_axis_label(budget_kind), "efficiency 1/(variance × CPU seconds)")
        }
        PlotKind::RmseVsTime => ("RMSE vs time", "CPU seconds per estimate".to_string(), "RMSE"),
    };
    let mut series = Vec::new();
    for (style, name) in estimators.iter().enumerate() {
        let mine: Vec<&&SummaryRow> = rows.iter().filter(|r| r.estimator == *name).collect();
        if mine.is_empty() {
            continue;
        }
        let mut points: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|r| match kind {
                PlotKind::Rmse => positive(r.budget as f64, r.rmse),
                PlotKind::Efficiency => r.efficiency.and_then(|e| positive(r.budget as f64, e)),
                PlotKind::RmseVsTime => positive(r.metric_seconds(), r.rmse),
            })
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut label = label_of(report, name).to_string();
        // Parametrised runs of one id share its label: keep their parameters in the legend.
        if let Some(params) = name.find('[').map(|i| &name[i..]).filter(|p| !label.ends_with(p)) {
            label = format!("{label} {params}");
        }
        if kind == PlotKind::Rmse {
            let fit = report.fits.iter().find(|f| f.testbed == testbed && f.variant == variant && f.estimator == *name);
            if let Some(f) = fit.filter(|f| f.slope.is_finite()) {
                label.push_str(&format!("  slope {:.2} [{:.2}, {:.2}]", f.slope, f.slope_ci_low, f.slope_ci_high));
                if f.slope_right.is_finite() {
                    label.push_str(&format!(
                        ", right end {:.2} [{:.2}, {:.2}]",
                        f.slope_right, f.slope_right_ci_low, f.slope_right_ci_high
                    ));
                }
            }
        }
        series.push(Series { label, style, points });
    }
    Figure {
        title: format!("{}: {what} — {testbed} / {variant}", report.meta.experiment),
        x_desc,
        y_desc: y_desc.to_string(),
        series,
    }
}

fn write_svg(path: &Path, fig: &Figure) -> Result<()> {
    let mut text = String::new();
    draw::svg(&mut text, fig).map_err(|e| HarnessError::write(path, e))?;
    write_atomic(path, text.as_bytes())
}

fn write_png(path: &Path, fig: &Figure) -> Result<()> {
    write_png_with(path, |tmp| draw::png(tmp, fig))
}

/// Writes a PNG atomically: `draw` renders to a temporary path (ending in `.png`, since the
/// bitmap encoder picks the format from the extension), which is then renamed to `path`.
pub fn write_png_with(path: &Path, draw: impl FnOnce(&Path) -> std::result::Result<(), String>) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("plot.png");
    let n = TMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.tmp-{}-{n}.png", std::process::id()));
    let result = draw(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        HarnessError::write(path, e)
    })
}
