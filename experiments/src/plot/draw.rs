//! Rendering of one [`Figure`] on any plotters backend: a log-log chart on top and the legend in
//! its own strip below, so it never covers data.

use super::{Figure, Series, PLOT_SIZE};
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
const LEGEND_ROW: u32 = 21;
const SWATCH: u32 = 34;

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

/// A padded log range over the positive values, widened to contain a power of ten (so the axis
/// always has a labelled tick).
fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return 1.0..10.0;
    }
    let (mut lo, mut hi) = ((lo.log10() - 0.12).min(hi.log10() - 0.3), (hi.log10() + 0.12).max(lo.log10() + 0.3));
    if lo.ceil() > hi.floor() {
        // No power of ten inside: extend to the nearer decade boundary.
        if lo - lo.floor() <= hi.ceil() - hi {
            lo = lo.floor();
        } else {
            hi = hi.ceil();
        }
    }
    10f64.powf(lo)..10f64.powf(hi)
}

/// Tick label: only 1, 2 and 5 times a power of ten are labelled (the rest are grid lines).
fn tick(v: f64) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let e = (v.log10() + 1e-9).floor() as i32;
    let m = v / 10f64.powi(e);
    let mr = m.round();
    if (m - mr).abs() > 1e-6 * m || ![1.0, 2.0, 5.0].contains(&mr) {
        return String::new();
    }
    match e {
        0..=4 => format!("{}", mr as i64 * 10i64.pow(e as u32)),
        -4..=-1 => format!("{:.*}", (-e) as usize, mr * 10f64.powi(e)),
        _ => format!("{mr}e{e}"),
    }
}

/// Legend layout: columns, rows and the strip's height for these labels.
fn legend_layout<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    series: &[&Series],
    style: &TextStyle,
) -> Result<(u32, u32, u32), String> {
    let mut widest = 0;
    for s in series {
        widest = widest.max(root.estimate_text_size(&s.label, style).map_err(|e| e.to_string())?.0);
    }
    let col_w = SWATCH + 10 + widest + 28;
    let usable = PLOT_SIZE.0 - 2 * MARGIN;
    let n = series.len().max(1) as u32;
    let cols = (usable / col_w).clamp(1, 3).min(n);
    let rows = n.div_ceil(cols);
    Ok((cols, col_w, (rows * LEGEND_ROW + 14).min(PLOT_SIZE.1 / 2)))
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &Figure) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let drawn: Vec<&Series> = fig.series.iter().filter(|s| !s.points.is_empty()).collect();
    let legend_style = TextStyle::from((FONT, 14).into_font()).color(&BLACK);
    let (cols, col_w, legend_h) = legend_layout(root, &drawn, &legend_style)?;
    let (upper, lower) = root.split_vertically(PLOT_SIZE.1 - legend_h);

    let xr = log_range(drawn.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let yr = log_range(drawn.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(&upper)
        .caption(&fig.title, (FONT, 20))
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(xr.log_scale(), yr.log_scale())
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

    let rows = (drawn.len() as u32).div_ceil(cols.max(1)).max(1);
    let left = (MARGIN + Y_LABEL_AREA / 2) as i32;
    let text_pos = legend_style.pos(Pos::new(HPos::Left, VPos::Center));
    for (k, s) in drawn.iter().enumerate() {
        let (col, row) = (k as u32 / rows, k as u32 % rows);
        let x = left + (col * col_w) as i32;
        let y = (4 + row * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        let c = colour(s.style);
        lower.draw(&PathElement::new(vec![(x, y), (x + SWATCH as i32, y)], c.stroke_width(2))).map_err(err)?;
        marker(&lower, (x + SWATCH as i32 / 2, y), s.style).map_err(err)?;
        lower.draw(&Text::new(s.label.clone(), (x + SWATCH as i32 + 10, y), text_pos.clone())).map_err(err)?;
    }
    root.present().map_err(err)
}

#[cfg(test)]
mod tests {
    use super::{log_range, tick};

    #[test]
    fn log_ranges_always_hold_a_power_of_ten() {
        for (lo, hi) in [(0.3, 0.8), (4.0, 16384.0), (5.0, 5.0), (1e-9, 2e-9), (0.0, f64::NAN)] {
            let r = log_range([lo, hi].into_iter());
            assert!(r.start > 0.0 && r.end > r.start, "{r:?}");
            assert!(r.start.log10().ceil() <= r.end.log10().floor(), "{r:?}");
        }
    }

    #[test]
    fn ticks_label_one_two_five() {
        assert_eq!(tick(100.0), "100");
        assert_eq!(tick(0.02), "0.02");
        assert_eq!(tick(5e-7), "5e-7");
        assert_eq!(tick(3.0), "");
        assert_eq!(tick(f64::NAN), "");
    }
}
