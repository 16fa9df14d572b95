//! Rendering of a figure of panels ([`Panels`]) on any plotters backend: the title on top, the
//! log-log panels in one column (a single chart) or two, and the legend in its own strip below,
//! so it never covers data. Bands are drawn first, then guides, then lines and markers.

use super::figure::{Entry, Figure, Panels};
use super::style::{self, colour, marker, polyline, text, FONT, GUIDE, LEGEND_ROW, MARGIN, SWATCH, TITLE_H};
use super::ticks::{log_range, log_ticks, tick};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Width of a figure of one chart, and of a figure of two columns of panels.
const WIDTH: (u32, u32) = (900, 1400);
/// Height of the single chart, and of a panel of a figure of several.
const PANEL_H: (u32, u32) = (520, 450);
/// Space of a panel's chart for its margin, tick labels and axis titles.
const CHART_MARGIN: u32 = 10;
const X_LABEL_AREA: u32 = 46;
const Y_LABEL_AREA: u32 = 72;
/// A band's low edge is drawn no lower than this fraction of its point (a log axis cannot show 0).
const BAND_FLOOR: f64 = 0.05;

/// Columns of panels and the size of one panel.
fn grid(fig: &Panels) -> (u32, (u32, u32)) {
    if fig.panels.len() <= 1 {
        (1, (WIDTH.0, PANEL_H.0))
    } else {
        (2, (WIDTH.1 / 2, PANEL_H.1))
    }
}

/// Legend layout: rows per column (filled column by column), the left edge of each column and the
/// strip's height (with the note's line).
fn legend_layout(fig: &Panels, entries: &[Entry], width: u32) -> (u32, Vec<i32>, u32) {
    let font = (FONT, style::LEGEND_SIZE).into_font();
    let widths: Vec<u32> = entries.iter().map(|e| font.box_size(e.label()).map(|b| b.0).unwrap_or(0)).collect();
    let n = entries.len().max(1) as u32;
    let usable = width - 2 * MARGIN;
    let mut layout = (n, vec![MARGIN as i32]);
    for cols in (2..=4.min(n)).rev() {
        let rows = n.div_ceil(cols);
        let col_w: Vec<u32> =
            widths.chunks(rows as usize).map(|c| SWATCH + 8 + c.iter().max().copied().unwrap_or(0) + 24).collect();
        if col_w.iter().sum::<u32>() <= usable + 24 {
            let lefts = col_w.iter().scan(MARGIN as i32, |x, w| Some(std::mem::replace(x, *x + *w as i32))).collect();
            layout = (rows, lefts);
            break;
        }
    }
    let rows = if entries.is_empty() { 0 } else { layout.0 };
    let note = if fig.note.is_empty() { 0 } else { LEGEND_ROW };
    (layout.0, layout.1, rows * LEGEND_ROW + note + 10)
}

/// The size in pixels of `fig`.
pub(super) fn size(fig: &Panels) -> (u32, u32) {
    let (cols, (w, h)) = grid(fig);
    let rows = (fig.panels.len() as u32).div_ceil(cols).max(1);
    let legend = legend_layout(fig, &fig.legend(), cols * w).2;
    (cols * w, TITLE_H + rows * h + legend)
}

/// Renders `fig` on `root` (of [`size`]).
pub(super) fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &Panels) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let (cols, (pw, ph)) = grid(fig);
    let width = cols * pw;
    let title = text(style::TITLE_SIZE, BLACK).pos(Pos::new(HPos::Center, VPos::Top));
    root.draw(&Text::new(fig.title.clone(), (width as i32 / 2, 10), title)).map_err(err)?;
    for (k, panel) in fig.panels.iter().enumerate() {
        let (c, r) = (k as u32 % cols, k as u32 / cols);
        let (x0, y0) = ((c * pw) as i32, (TITLE_H + r * ph) as i32);
        let area = root.clone().shrink((x0, y0), (pw, ph));
        draw_panel(root, &area, panel, (pw, ph))?;
    }
    let rows = (fig.panels.len() as u32).div_ceil(cols).max(1);
    draw_legend(root, fig, TITLE_H + rows * ph, width)?;
    root.present().map_err(err)
}

/// Draws one chart into `area` (elements placed in pixels are drawn on `root`).
fn draw_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    (w, h): (u32, u32),
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let drawn: Vec<_> = fig.series.iter().filter(|s| !s.points.is_empty()).collect();
    let band = |&(x, lo, hi): &(f64, f64, f64), y: f64| (x, lo.max(y * BAND_FLOOR), hi);
    let y_of = |s: &super::Series, x: f64| s.points.iter().find(|p| p.0 == x).map_or(0.0, |p| p.1);
    let bands: Vec<Vec<(f64, f64, f64)>> = drawn
        .iter()
        .map(|s| s.band.iter().map(|b| band(b, y_of(s, b.0))).filter(|b| b.1 > 0.0 && b.2 >= b.1).collect())
        .collect();
    let xs = drawn.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let xs = xs.chain(fig.guides.iter().flat_map(|g| g.points.iter().map(|p| p.0)));
    let ys = drawn.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let ys = ys.chain(bands.iter().flatten().flat_map(|b| [b.1, b.2]));
    let ys = ys.chain(fig.guides.iter().flat_map(|g| g.points.iter().map(|p| p.1)));
    let (xr, yr) = (log_range(xs), log_range(ys));
    let caption = if fig.title.is_empty() { 0 } else { style::PANEL_TITLE_SIZE + 12 };
    let x_px = f64::from(w.saturating_sub(2 * CHART_MARGIN + Y_LABEL_AREA));
    let y_px = f64::from(h.saturating_sub(2 * CHART_MARGIN + X_LABEL_AREA + caption));
    let ((xb, xl), (yb, yl)) = (log_ticks(&xr, x_px, false), log_ticks(&yr, y_px, true));
    let mut builder = ChartBuilder::on(area);
    builder.margin(CHART_MARGIN).x_label_area_size(X_LABEL_AREA).y_label_area_size(Y_LABEL_AREA);
    if !fig.title.is_empty() {
        builder.caption(&fig.title, (FONT, style::PANEL_TITLE_SIZE));
    }
    let mut chart = builder
        .build_cartesian_2d(
            xr.log_scale().with_key_points(xb).with_light_points(xl),
            yr.log_scale().with_key_points(yb).with_light_points(yl),
        )
        .map_err(err)?;
    let fmt = |v: &f64| tick(*v);
    chart
        .configure_mesh()
        .x_desc(fig.x_desc.as_str())
        .y_desc(fig.y_desc.as_str())
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style((FONT, style::TICK_SIZE))
        .axis_desc_style((FONT, style::AXIS_SIZE))
        .bold_line_style(style::GRID_BOLD)
        .light_line_style(style::GRID)
        .draw()
        .map_err(err)?;
    let px = |p: &(f64, f64)| chart.backend_coord(p);
    for (s, b) in drawn.iter().zip(&bands).filter(|(_, b)| b.len() >= 2) {
        let mut outline: Vec<(i32, i32)> = b.iter().map(|&(x, lo, _)| px(&(x, lo))).collect();
        outline.extend(b.iter().rev().map(|&(x, _, hi)| px(&(x, hi))));
        root.draw(&Polygon::new(outline, colour(s.style).mix(style::BAND_ALPHA).filled())).map_err(err)?;
    }
    for g in &fig.guides {
        let pts: Vec<(i32, i32)> = g.points.iter().map(px).collect();
        polyline(root, &pts, g.style.map_or(GUIDE, colour), 2, g.line).map_err(err)?;
    }
    for s in &drawn {
        let pts: Vec<(i32, i32)> = s.points.iter().map(px).collect();
        polyline(root, &pts, colour(s.style), 2, s.line).map_err(err)?;
        if s.markers {
            for p in &pts {
                marker(root, *p, s.style).map_err(err)?;
            }
        }
    }
    Ok(())
}

/// Draws the legend strip from `top` down, and the note under it.
fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Panels,
    top: u32,
    width: u32,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let entries = fig.legend();
    let (rows, lefts, height) = legend_layout(fig, &entries, width);
    let label = text(style::LEGEND_SIZE, BLACK).pos(Pos::new(HPos::Left, VPos::Center));
    let sw = SWATCH as i32;
    for (k, e) in entries.iter().enumerate() {
        let (col, row) = (k / rows.max(1) as usize, k as u32 % rows.max(1));
        let x = lefts.get(col).copied().unwrap_or(MARGIN as i32);
        let y = (top + 4 + row * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        let line = [(x, y), (x + sw, y)];
        match e {
            Entry::Series(_, s, l, markers, band) => {
                if *band {
                    let shade = colour(*s).mix(style::BAND_ALPHA).filled();
                    root.draw(&Rectangle::new([(x, y - 7), (x + sw, y + 7)], shade)).map_err(err)?;
                }
                polyline(root, &line, colour(*s), 2, *l).map_err(err)?;
                if *markers {
                    marker(root, (x + sw / 2, y), *s).map_err(err)?;
                }
            }
            Entry::Guide(_, s, l) => polyline(root, &line, s.map_or(GUIDE, colour), 2, *l).map_err(err)?,
            Entry::Key(key) => {
                polyline(root, &line, BLACK, 2, key.line).map_err(err)?;
                if key.marker {
                    root.draw(&Circle::new((x + sw / 2, y), 4, BLACK.filled())).map_err(err)?;
                }
            }
        }
        root.draw(&Text::new(e.label().to_string(), (x + sw + 8, y), label.clone())).map_err(err)?;
    }
    if !fig.note.is_empty() {
        let y = (top + height - 6 - LEGEND_ROW / 2) as i32;
        let note = text(style::LEGEND_SIZE, RGBColor(80, 80, 80)).pos(Pos::new(HPos::Left, VPos::Center));
        root.draw(&Text::new(fig.note.clone(), (MARGIN as i32, y), note)).map_err(err)?;
    }
    Ok(())
}
