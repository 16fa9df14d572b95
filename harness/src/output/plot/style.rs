//! The one figure style of every plot: palette, font sizes, margins, legend rows, markers and
//! line dashes. Line plots, heat maps, maps and claim sweeps all draw with these, so a figure of
//! one experiment reads like a figure of any other.

use plotters::coord::Shift;
use plotters::prelude::*;

/// The font family (DejaVu Sans, bundled and registered under this name).
pub const FONT: &str = "sans-serif";
/// Figure title size (px).
pub const TITLE_SIZE: u32 = 20;
/// Panel title size (px).
pub const PANEL_TITLE_SIZE: u32 = 15;
/// Axis title size (px).
pub const AXIS_SIZE: u32 = 14;
/// Tick label size (px).
pub const TICK_SIZE: u32 = 13;
/// Legend and note text size (px).
pub const LEGEND_SIZE: u32 = 13;
/// Outer margin of a figure (px).
pub const MARGIN: u32 = 16;
/// Height of the figure title strip (px).
pub const TITLE_H: u32 = 36;
/// Height of one legend row (px).
pub const LEGEND_ROW: u32 = 19;
/// Length of the line drawn in a legend entry (px).
pub const SWATCH: u32 = 30;
/// Light grey of grid lines.
pub const GRID: RGBColor = RGBColor(232, 232, 232);
/// Grey of the labelled grid lines.
pub const GRID_BOLD: RGBColor = RGBColor(200, 200, 200);
/// Grey of guide lines (reference slopes, break-even).
pub const GUIDE: RGBColor = RGBColor(110, 110, 110);
/// Opacity of a shaded interval band.
pub const BAND_ALPHA: f64 = 0.16;

/// The palette: the Tableau 10 colours less their grey (kept for guides), in order.
pub const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Named palette colours for figures whose colours mean something (verdicts, the paper's value).
pub mod named {
    use super::PALETTE;
    use plotters::style::RGBColor;
    /// Blue: the paper's number.
    pub const BLUE: RGBColor = PALETTE[0];
    /// Orange: a ceiling or limit.
    pub const ORANGE: RGBColor = PALETTE[1];
    /// Green: held.
    pub const GREEN: RGBColor = PALETTE[2];
    /// Red: not held.
    pub const RED: RGBColor = PALETTE[3];
}

/// The colour of series style `style` (cycling through [`PALETTE`]).
pub fn colour(style: usize) -> RGBColor {
    PALETTE[style % PALETTE.len()]
}

/// How a line is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Line {
    /// Solid.
    #[default]
    Solid,
    /// Dashed (8 px on, 5 px off).
    Dashed,
    /// Dotted (2 px on, 4 px off).
    Dotted,
}

impl Line {
    /// On and off lengths in pixels; `None` for a solid line.
    fn pattern(self) -> Option<(f64, f64)> {
        match self {
            Line::Solid => None,
            Line::Dashed => Some((8.0, 5.0)),
            Line::Dotted => Some((2.0, 4.0)),
        }
    }
}

/// Draws a polyline given in backend pixels with `line`'s pattern (the pattern runs on across
/// vertices, so dashes stay even along a curve).
pub fn polyline<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[(i32, i32)],
    colour: RGBColor,
    width: u32,
    line: Line,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let style = colour.stroke_width(width);
    let Some((on, off)) = line.pattern() else {
        return area.draw(&PathElement::new(points.to_vec(), style));
    };
    let mut phase = 0.0; // distance into the current on+off period
    for w in points.windows(2) {
        let (a, b) = ((f64::from(w[0].0), f64::from(w[0].1)), (f64::from(w[1].0), f64::from(w[1].1)));
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let mut t = 0.0;
        while t < len {
            let in_on = phase < on;
            let step = if in_on { on - phase } else { on + off - phase }.min(len - t);
            if in_on {
                let at = |s: f64| {
                    ((a.0 + (b.0 - a.0) * s / len).round() as i32, (a.1 + (b.1 - a.1) * s / len).round() as i32)
                };
                area.draw(&PathElement::new(vec![at(t), at(t + step)], style))?;
            }
            t += step;
            phase = (phase + step) % (on + off);
        }
    }
    Ok(())
}

/// Draws the marker of series style `style` centred at backend pixel `at`: circle, square,
/// triangle, diamond; filled for the first four shapes of a colour cycle, hollow for the next.
pub fn marker<DB: DrawingBackend>(
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

/// A text style of `size` px in `colour`.
pub fn text(size: u32, colour: RGBColor) -> TextStyle<'static> {
    TextStyle {
        font: (FONT, size).into_font(),
        color: colour.to_backend_color(),
        pos: plotters::style::text_anchor::Pos::default(),
    }
}

/// Turns a panic inside plotters into an error, so a bad plot never brings a run down.
pub fn guarded<F: FnOnce() -> Result<(), String>>(f: F) -> Result<(), String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))
        .unwrap_or_else(|_| Err("the plotting library panicked".to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn styles_cycle_through_distinct_colour_and_marker_pairs() {
        let pairs: Vec<(RGBColor, usize)> = (0..36).map(|s| (colour(s), s % 4)).collect();
        for (i, p) in pairs.iter().enumerate() {
            assert!(!pairs[..i].contains(p), "style {i} repeats an earlier colour and marker");
        }
    }

    #[test]
    fn dashes_follow_the_pattern_across_vertices() {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (100, 20)).into_drawing_area();
            polyline(&root, &[(0, 10), (20, 10), (39, 10)], BLACK, 1, Line::Dashed).unwrap();
            root.present().unwrap();
        }
        // 39 px at 8 on / 5 off: dashes start at 0, 13 and 26 (the second spans the vertex).
        assert_eq!(svg.matches("<polyline").count() + svg.matches("<path").count(), 4, "{svg}");
    }
}
