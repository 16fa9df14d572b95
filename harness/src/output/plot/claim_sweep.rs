//! A claim judged across the settings of one parameter: the claim's value at every setting with
//! its interval, the paper's number as a horizontal line, and the verdict as the marker (filled
//! green circle held, red cross not held, hollow grey circle inconclusive or reported) and, where
//! the scene bounds the claim, its ceiling (orange triangle); a legend strip below says so. The x
//! axis is categorical (one slot per setting, labelled with the setting), so numeric and named
//! settings (a variant, a rule) plot alike; the y axis is logarithmic when every value is positive
//! and they span more than a decade. Drawn in the figures' style ([`super::style`]).

use super::style::{self, named, text, FONT, LEGEND_ROW, MARGIN, TITLE_H};
use crate::error::{HarnessError, Result};
use crate::verdict::Verdict;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// Width and height of the chart; the legend strip adds [`LEGEND_H`].
const SIZE: (u32, u32) = (900, 520);
const LEGEND_H: u32 = 2 * LEGEND_ROW + 10;

/// One setting of the swept parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct SettingPoint {
    /// The setting as shown under the axis (`0.5`, `diffuse`); a trailing `*` marks our
    /// default and `(paper)` the paper-like setting, as the caller writes them.
    pub label: String,
    /// The claim's value there.
    pub value: Option<f64>,
    /// Its interval.
    pub interval: Option<[f64; 2]>,
    /// The verdict there.
    pub verdict: Verdict,
    /// The scene's ceiling of the claim there, drawn as an orange triangle.
    pub ceiling: Option<f64>,
}

/// A claim against a parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ClaimSweepFigure {
    /// Title.
    pub title: String,
    /// x-axis title (the parameter).
    pub x_desc: String,
    /// y-axis title (the claim's quantity).
    pub y_desc: String,
    /// The settings, in order.
    pub points: Vec<SettingPoint>,
    /// The paper's number.
    pub paper: Option<f64>,
}

impl ClaimSweepFigure {
    /// The y range (padded) and whether it is logarithmic; `None` when nothing can be drawn.
    fn y_range(&self) -> Option<(f64, f64, bool)> {
        let mut ys: Vec<f64> = self.points.iter().filter_map(|p| p.value).filter(|v| v.is_finite()).collect();
        for p in &self.points {
            ys.extend(p.interval.into_iter().flatten().filter(|v| v.is_finite()));
            ys.extend(p.ceiling.filter(|v| v.is_finite()));
        }
        ys.extend(self.paper.filter(|v| v.is_finite()));
        let (lo, hi) = ys.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| (a.min(y), b.max(y)));
        if !lo.is_finite() || !hi.is_finite() {
            return None;
        }
        if lo > 0.0 && hi / lo > 10.0 {
            return Some((lo / 1.3, hi * 1.3, true));
        }
        let pad = ((hi - lo) * 0.08).max(hi.abs().max(lo.abs()) * 0.05).max(1e-12);
        Some((lo - pad, hi + pad, false))
    }
}

/// Writes `fig` as `<stem>.svg` and `<stem>.png` in `dir` (created if needed); nothing when no
/// setting has a finite value.
pub fn write_claim_sweep(dir: &Path, stem: &str, fig: &ClaimSweepFigure) -> Result<Vec<PathBuf>> {
    let Some(range) = fig.y_range() else { return Ok(Vec::new()) };
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    let (svg, png) = (dir.join(format!("{stem}.svg")), dir.join(format!("{stem}.png")));
    let size = (SIZE.0, TITLE_H + SIZE.1 + LEGEND_H);
    super::write_svg(&svg, size, |root| render(&root, fig, range))?;
    super::png::write_png(&png, size, |root| render(&root, fig, range))?;
    Ok(vec![svg, png])
}

const GREEN: RGBColor = named::GREEN;
const RED: RGBColor = named::RED;
const GREY: RGBColor = style::GUIDE;
const PAPER: RGBColor = named::BLUE;
const CEILING: RGBColor = named::ORANGE;

fn render<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &ClaimSweepFigure,
    (lo, hi, log): (f64, f64, bool),
) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let title = text(style::TITLE_SIZE, BLACK).pos(Pos::new(HPos::Center, VPos::Top));
    root.draw(&Text::new(fig.title.clone(), (SIZE.0 as i32 / 2, 10), title)).map_err(e)?;
    let chart_area = root.clone().shrink((0, TITLE_H), SIZE);
    let n = fig.points.len().max(1);
    let mut builder = ChartBuilder::on(&chart_area);
    builder.margin(10).x_label_area_size(46).y_label_area_size(72);
    let x_range = -0.5..(n as f64 - 0.5);
    if log {
        // The log axis labels its ticks like the line figures' ([`super::ticks`]).
        let (bold, light) = super::ticks::log_ticks(&(lo..hi), f64::from(SIZE.1 - 20 - 46), true);
        let y = (lo..hi).log_scale().with_key_points(bold).with_light_points(light);
        let mut chart = builder.build_cartesian_2d(x_range, y).map_err(e)?;
        draw_chart(&mut chart, fig, Some(&|v: &f64| super::ticks::tick(*v))).map_err(e)?;
    } else {
        let mut chart = builder.build_cartesian_2d(x_range, lo..hi).map_err(e)?;
        draw_chart(&mut chart, fig, None).map_err(e)?;
    }
    draw_legend(root, TITLE_H + SIZE.1).map_err(e)?;
    root.present().map_err(e)
}

/// The legend strip: what the markers and lines mean.
fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    top: u32,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let label = text(style::LEGEND_SIZE, BLACK).pos(Pos::new(HPos::Left, VPos::Center));
    let entries = ["held", "not held", "inconclusive or reported", "scene's ceiling", "paper's number", "interval"];
    let font = (FONT, style::LEGEND_SIZE).into_font();
    let (mut x, y) = (MARGIN as i32, (top + 4 + LEGEND_ROW / 2) as i32);
    for (k, name) in entries.iter().enumerate() {
        let c = (x + 15, y);
        match k {
            0 => root.draw(&Circle::new(c, 6, GREEN.filled()))?,
            1 => root.draw(&Cross::new(c, 7, RED.stroke_width(3)))?,
            2 => root.draw(&Circle::new(c, 6, GREY.stroke_width(2)))?,
            3 => root.draw(&TriangleMarker::new(c, 7, CEILING.filled()))?,
            4 => root.draw(&PathElement::new(vec![(x, y), (x + 30, y)], PAPER.stroke_width(2)))?,
            _ => root.draw(&PathElement::new(vec![(x + 15, y - 8), (x + 15, y + 8)], GREY.stroke_width(2)))?,
        }
        root.draw(&Text::new(name.to_string(), (x + 38, y), label.clone()))?;
        x += 38 + font.box_size(name).map(|b| b.0 as i32).unwrap_or(80) + 24;
    }
    Ok(())
}

/// The mesh (one x label per setting), the paper's line and the points, on either y axis.
fn draw_chart<DB: DrawingBackend, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    fig: &ClaimSweepFigure,
    y_fmt: Option<&dyn Fn(&f64) -> String>,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let n = fig.points.len().max(1);
    let x_fmt = |x: &f64| {
        let i = x.round();
        if (x - i).abs() < 1e-6 && i >= 0.0 {
            fig.points.get(i as usize).map(|p| p.label.clone()).unwrap_or_default()
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(n)
        .x_label_formatter(&x_fmt)
        .x_desc(&fig.x_desc)
        .y_desc(&fig.y_desc)
        .label_style((FONT, style::TICK_SIZE))
        .axis_desc_style((FONT, style::AXIS_SIZE))
        .bold_line_style(style::GRID_BOLD)
        .light_line_style(style::GRID);
    if let Some(f) = y_fmt {
        mesh.y_label_formatter(f);
    }
    mesh.draw()?;
    if let Some(p) = fig.paper {
        chart.draw_series(LineSeries::new(vec![(-0.5, p), (n as f64 - 0.5, p)], PAPER.stroke_width(2)))?;
    }
    draw_points(chart, fig)
}

fn draw_points<DB: DrawingBackend, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    fig: &ClaimSweepFigure,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (i, p) in fig.points.iter().enumerate() {
        let x = i as f64;
        if let Some([a, b]) = p.interval.filter(|[a, b]| a.is_finite() && b.is_finite()) {
            chart.draw_series(std::iter::once(PathElement::new(vec![(x, a), (x, b)], GREY.stroke_width(2))))?;
            for y in [a, b] {
                chart.draw_series(std::iter::once(PathElement::new(vec![(x - 0.08, y), (x + 0.08, y)], GREY)))?;
            }
        }
        if let Some(c) = p.ceiling.filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(TriangleMarker::new((x, c), 7, CEILING.filled())))?;
        }
        let Some(y) = p.value.filter(|v| v.is_finite()) else { continue };
        match p.verdict {
            Verdict::Held => chart.draw_series(std::iter::once(Circle::new((x, y), 6, GREEN.filled())))?,
            Verdict::NotHeld => chart.draw_series(std::iter::once(Cross::new((x, y), 7, RED.stroke_width(3))))?,
            _ => chart.draw_series(std::iter::once(Circle::new((x, y), 6, GREY.stroke_width(2))))?,
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(label: &str, value: f64, verdict: Verdict) -> SettingPoint {
        SettingPoint {
            label: label.into(),
            value: Some(value),
            interval: Some([value * 0.9, value * 1.1]),
            verdict,
            ceiling: Some(value * 2.0),
        }
    }

    #[test]
    fn a_claim_sweep_is_drawn_on_log_and_linear_axes_and_nothing_without_values() {
        let dir = std::env::temp_dir().join(format!("mcbench-claim-sweep-{}", std::process::id()));
        let mut fig = ClaimSweepFigure {
            title: "15.3x against sigma_t".into(),
            x_desc: "sigma_t".into(),
            y_desc: "speed-up".into(),
            points: vec![
                point("0.125", 9.0, Verdict::NotHeld),
                point("2*", 0.75, Verdict::NotHeld),
                point("0.5 (paper)", 3.0, Verdict::Held),
            ],
            paper: Some(15.3),
        };
        assert_eq!(fig.y_range().map(|r| r.2), Some(true));
        let files = write_claim_sweep(&dir, "log", &fig).unwrap();
        assert_eq!(files.len(), 2);
        assert!(std::fs::read_to_string(&files[0]).unwrap().contains("sigma_t"));
        fig.points = vec![point("a", -0.6, Verdict::Held), point("b", -0.5, Verdict::Inconclusive)];
        fig.paper = Some(-0.62);
        assert_eq!(fig.y_range().map(|r| r.2), Some(false));
        assert_eq!(write_claim_sweep(&dir, "linear", &fig).unwrap().len(), 2);
        fig.points.iter_mut().for_each(|p| (p.value, p.interval, p.ceiling) = (None, None, None));
        fig.paper = None;
        assert!(write_claim_sweep(&dir, "empty", &fig).unwrap().is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
