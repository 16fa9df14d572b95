//! Rendering of one [`Figure`] on any plotters backend: a log-log chart on top and the legend in
//! its own strip below, so it never covers data.

use super::{Figure, Series, PLOT_SIZE};
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ops::Range;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

const FONT: &str = "sans-serif";
const MARGIN: u32 = 16;
const Y_LABEL_AREA: u32 = 80;
const X_LABEL_AREA: u32 = 50;
const LEGEND_ROW: u32 = 19;
const SWATCH: u32 = 30;

/// Renders `fig` as an SVG document into `out`.
pub(super) fn svg(out: &mut String, fig: &Figure) -> Result<(), String> {
    guarded(|| {
        let root = SVGBackend::with_string(out, PLOT_SIZE).into_drawing_area();
        render(&root, fig)
    })
}

/// Renders `fig` as a PNG file at `path` (whose extension must be `.png`).
pub(super) fn png(path: &Path, fig: &Figure) -> Result<(), String> {
    guarded(|| {
        let root = BitMapBackend::new(path, PLOT_SIZE).into_drawing_area();
        render(&root, fig)
    })
}

/// Turns a panic inside plotters into an error, so a bad plot never brings a run down.
fn guarded<F: FnOnce() -> Result<(), String>>(f: F) -> Result<(), String> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| Err("the plotting library panicked".to_string()))
}

/// The Palette99 colours that read well on white (the light ones are left out).
fn colour(style: usize) -> RGBColor {
    let dark: Vec<(u8, u8, u8)> = <Palette99 as Palette>::COLORS
        .iter()
        .copied()
        .filter(|&(r, g, b)| 0.2126 * f64::from(r) + 0.7152 * f64::from(g) + 0.0722 * f64::from(b) < 0.65 * 255.0)
        .collect();
    let (r, g, b) = dark[style % dark.len()];
    RGBColor(r, g, b)
}

/// Draws the marker of series style `style` centred at backend pixel `at`: circle, square,
/// triangle, diamond; filled for the first four styles, hollow for the next four, and so on.
fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    style: usize,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let c = colour(style);
    let hollow = (style / 4) % 2 == 1;
    let (x, y) = at;
    let shape: Vec<(i32, i32)> = match style % 4 {
        0 => {
            let st = if hollow { c.stroke_width(2) } else { c.filled() };
            return area.draw(&Circle::new(at, 4, st));
        }
        1 => vec![(x - 4, y - 4), (x + 4, y - 4), (x + 4, y + 4), (x - 4, y + 4)],
        2 => vec![(x, y - 6), (x + 5, y + 4), (x - 5, y + 4)],
        _ => vec![(x, y - 6), (x + 5, y), (x, y + 6), (x - 5, y)],
    };
    if hollow {
        let mut closed = shape.clone();
        closed.push(shape[0]);
        area.draw(&PathElement::new(closed, c.stroke_width(2)))
    } else {
        area.draw(&Polygon::new(shape, c.filled()))
    }
}

/// A log range over the positive values, padded by a tenth of a decade each side and at least
/// 0.6 decades wide (a single point or a flat series still gets a readable axis).
fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return 1.0..10.0;
    }
    let (lo, hi) = (lo.log10() - 0.1, hi.log10() + 0.1);
    let grow = (0.6 - (hi - lo)).max(0.0) / 2.0;
    10f64.powf(lo - grow)..10f64.powf(hi + grow)
}

/// Labelled (bold) and grid-only (light) ticks of a log axis: 1, 2, 5 x 10^k over narrow
/// ranges, powers of ten (every few decades on very wide ranges) otherwise; every integer
/// mantissa when that leaves fewer than two labels.
fn log_ticks(range: &Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.start, range.end);
    let span = (hi / lo).log10();
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let every = ((span / 8.0).ceil() as i32).max(1);
    let at = |mantissas: &[f64], step: i32| -> Vec<f64> {
        (k0..=k1)
            .filter(|k| k.rem_euclid(step) == 0)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let all = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
    let mut bold = if span <= 2.5 { at(&[1.0, 2.0, 5.0], 1) } else { at(&[1.0], every) };
    if bold.len() < 2 {
        bold = at(&all, 1);
    }
    let light = if span <= 6.0 { at(&all, 1) } else { at(&[1.0], 1) };
    let light = light.into_iter().filter(|v| !bold.iter().any(|b| (b / v - 1.0).abs() < 1e-9)).collect();
    (bold, light)
}

/// Tick label of m x 10^e (m an integer 1..9): plain for 1e-4..1e4, `me±e` otherwise.
fn tick(v: f64) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let e = (v.log10() + 1e-9).floor() as i32;
    let m = v / 10f64.powi(e);
    if (m - m.round()).abs() > 1e-6 * m {
        return format!("{v:.2e}");
    }
    let m = m.round();
    match e {
        0..=4 => format!("{}", m as i64 * 10i64.pow(e as u32)),
        -4..=-1 => format!("{:.*}", (-e) as usize, m * 10f64.powi(e)),
        _ => format!("{m}e{e}"),
    }
}

/// Legend layout: rows per column (filled column by column), the left edge of each column and
/// the strip's height; as many columns (up to 3) as fit the labels' widths.
fn legend_layout<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    series: &[&Series],
    style: &TextStyle,
) -> Result<(u32, Vec<i32>, u32), String> {
    let mut widths = Vec::with_capacity(series.len());
    for s in series {
        widths.push(root.estimate_text_size(&s.label, style).map_err(|e| e.to_string())?.0);
    }
    let n = series.len().max(1) as u32;
    let usable = PLOT_SIZE.0 - 2 * MARGIN;
    let mut layout = (n, vec![MARGIN as i32]);
    for cols in (2..=3.min(n)).rev() {
        let rows = n.div_ceil(cols);
        let col_w: Vec<u32> =
            widths.chunks(rows as usize).map(|c| SWATCH + 8 + c.iter().max().copied().unwrap_or(0) + 18).collect();
        if col_w.iter().sum::<u32>() <= usable + 18 {
            let lefts = col_w.iter().scan(MARGIN as i32, |x, w| Some(std::mem::replace(x, *x + *w as i32))).collect();
            layout = (rows, lefts);
            break;
        }
    }
    Ok((layout.0, layout.1, (layout.0 * LEGEND_ROW + 14).min(PLOT_SIZE.1 / 2)))
}

fn log_axis(range: Range<f64>) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_ticks(&range);
    range.log_scale().with_key_points(bold).with_light_points(light)
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &Figure) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let drawn: Vec<&Series> = fig.series.iter().filter(|s| !s.points.is_empty()).collect();
    let legend_style = TextStyle::from((FONT, 13).into_font()).color(&BLACK);
    let (rows, lefts, legend_h) = legend_layout(root, &drawn, &legend_style)?;
    let (upper, lower) = root.split_vertically(PLOT_SIZE.1 - legend_h);

    let xr = log_range(drawn.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let yr = log_range(drawn.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(&upper)
        .caption(&fig.title, (FONT, 20))
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(log_axis(xr), log_axis(yr))
        .map_err(err)?;
    let fmt = |v: &f64| tick(*v);
    chart
        .configure_mesh()
        .x_desc(fig.x_desc.as_str())
        .y_desc(fig.y_desc.as_str())
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .bold_line_style(RGBColor(200, 200, 200))
        .light_line_style(RGBColor(236, 236, 236))
        .draw()
        .map_err(err)?;
    for s in &drawn {
        let c = colour(s.style);
        chart.draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2))).map_err(err)?;
        for p in &s.points {
            marker(root, chart.backend_coord(p), s.style).map_err(err)?;
        }
    }

    let text_pos = legend_style.pos(Pos::new(HPos::Left, VPos::Center));
    for (k, s) in drawn.iter().enumerate() {
        let (col, row) = (k / rows.max(1) as usize, k as u32 % rows.max(1));
        let x = lefts.get(col).copied().unwrap_or(MARGIN as i32);
        let y = (4 + row * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        let c = colour(s.style);
        lower.draw(&PathElement::new(vec![(x, y), (x + SWATCH as i32, y)], c.stroke_width(2))).map_err(err)?;
        marker(&lower, (x + SWATCH as i32 / 2, y), s.style).map_err(err)?;
        lower.draw(&Text::new(s.label.clone(), (x + SWATCH as i32 + 8, y), text_pos.clone())).map_err(err)?;
    }
    root.present().map_err(err)
}

#[cfg(test)]
mod tests {
    use super::{log_range, log_ticks, tick};

    #[test]
    fn log_axes_always_have_labelled_ticks() {
        for (lo, hi) in [(0.3, 0.8), (4.0, 16384.0), (5.0, 5.0), (1e-9, 2e-9), (0.0, f64::NAN), (1e-30, 1e30)] {
            let r = log_range([lo, hi].into_iter());
            assert!(r.start > 0.0 && r.end > r.start, "{r:?}");
            let (bold, light) = log_ticks(&r);
            assert!(bold.len() >= 2 && bold.len() <= 12, "{r:?}: {bold:?}");
            assert!(bold.iter().chain(&light).all(|v| *v >= r.start * 0.999 && *v <= r.end * 1.001), "{r:?}");
        }
        assert_eq!(log_ticks(&(0.5..30.0)).0, vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        assert_eq!(log_ticks(&(3.0..20000.0)).0, vec![10.0, 100.0, 1000.0, 10000.0]);
    }

    #[test]
    fn ticks_are_readable() {
        assert_eq!(tick(100.0), "100");
        assert_eq!(tick(0.02), "0.02");
        assert_eq!(tick(3.0 * 0.1), "0.3");
        assert_eq!(tick(5e-7), "5e-7");
        assert_eq!(tick(2e7), "2e7");
        assert_eq!(tick(f64::NAN), "");
    }
}
