//! Heat maps: panels of coloured cells (one panel per estimator, rows and columns two swept
//! parameters), each cell annotated, with a colour bar (sequential or diverging scale) or a legend
//! of categories. Written as SVG and PNG like the line plots, with the bundled font.

use super::{ensure_font, write_png_with};
use crate::error::{HarnessError, Result};
use crate::output::write_atomic;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

const FONT: &str = "sans-serif";
const CELL: (i32, i32) = (50, 24);
const ROW_LABELS: i32 = 40;
const PANEL_TITLE: i32 = 20;
const COL_LABELS: i32 = 18;
const GAP: (i32, i32) = (22, 16);
const MARGIN: i32 = 16;
const TITLE: i32 = 34;
const LEGEND: i32 = 64;
const MAX_WIDTH: i32 = 1500;

/// What fills a cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Fill {
    /// A value on the figure's scale.
    Value(f64),
    /// A category (index into [`Scale::Categories`]).
    Category(usize),
    /// Nothing measured (light grey).
    Empty,
}

/// One annotated cell.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatCell {
    /// Its colour.
    pub fill: Fill,
    /// Its annotation.
    pub text: String,
}

/// One panel: a title, column labels and `rows x columns` cells.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Panel title.
    pub title: String,
    /// Column labels (left to right).
    pub columns: Vec<String>,
    /// `cells[row][column]`.
    pub cells: Vec<Vec<HeatCell>>,
}

/// How values map to colours.
#[derive(Clone, Debug, PartialEq)]
pub enum Scale {
    /// Viridis from `lo` (dark) to `hi` (yellow); values outside are clamped.
    Sequential {
        /// Value of the dark end.
        lo: f64,
        /// Value of the bright end.
        hi: f64,
        /// What the colour means (legend).
        label: String,
    },
    /// Blue (`-limit`) to white (0) to red (`+limit`), clamped.
    Diverging {
        /// Value of the saturated ends.
        limit: f64,
        /// What the colour means (legend).
        label: String,
    },
    /// Named categories.
    Categories(Vec<String>),
}

/// A heat-map figure: panels sharing the row labels and the scale.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatFigure {
    /// Figure title.
    pub title: String,
    /// Row labels (top to bottom).
    pub rows: Vec<String>,
    /// What rows and columns are (shown under the title).
    pub axes: String,
    /// The panels, left to right.
    pub panels: Vec<Panel>,
    /// The colour scale shared by the panels.
    pub scale: Scale,
}

const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Light, distinct fills for categories (black text stays readable on every one).
const CATEGORY: [(u8, u8, u8); 12] = [
    (141, 211, 199),
    (255, 255, 179),
    (190, 186, 218),
    (251, 128, 114),
    (128, 177, 211),
    (253, 180, 98),
    (179, 222, 105),
    (252, 205, 229),
    (217, 217, 217),
    (188, 128, 189),
    (204, 235, 197),
    (255, 237, 111),
];

fn lerp(a: (u8, u8, u8), b: (u8, u8, u8), t: f64) -> RGBColor {
    let m = |x: u8, y: u8| (f64::from(x) + (f64::from(y) - f64::from(x)) * t).round() as u8;
    RGBColor(m(a.0, b.0), m(a.1, b.1), m(a.2, b.2))
}

/// The colour of `fill` on `scale`.
pub fn colour(fill: &Fill, scale: &Scale) -> RGBColor {
    match (fill, scale) {
        (Fill::Value(v), Scale::Sequential { lo, hi, .. }) if v.is_finite() => {
            let t = if hi > lo { ((v - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.5 };
            let x = t * (VIRIDIS.len() - 1) as f64;
            let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
            lerp(VIRIDIS[k], VIRIDIS[k + 1], x - k as f64)
        }
        (Fill::Value(v), Scale::Diverging { limit, .. }) if v.is_finite() => {
            let t = (v / limit.max(f64::MIN_POSITIVE)).clamp(-1.0, 1.0);
            if t < 0.0 {
                lerp((255, 255, 255), (33, 102, 172), -t)
            } else {
                lerp((255, 255, 255), (178, 24, 43), t)
            }
        }
        (Fill::Category(k), _) => {
            let c = CATEGORY[k % CATEGORY.len()];
            RGBColor(c.0, c.1, c.2)
        }
        _ => RGBColor(235, 235, 235),
    }
}

fn text_colour(c: RGBColor) -> RGBColor {
    let l = 0.2126 * f64::from(c.0) + 0.7152 * f64::from(c.1) + 0.0722 * f64::from(c.2);
    if l < 110.0 {
        WHITE
    } else {
        BLACK
    }
}

/// Panel origins (left, top) and the figure size, panels flowing left to right.
fn layout(fig: &HeatFigure) -> (Vec<(i32, i32)>, (u32, u32)) {
    let rows = fig.rows.len() as i32;
    let panel_h = PANEL_TITLE + rows * CELL.1 + COL_LABELS;
    let (mut x, mut y, mut width) = (MARGIN, MARGIN + TITLE, 0);
    let mut at = Vec::new();
    for p in &fig.panels {
        let w = ROW_LABELS + p.columns.len() as i32 * CELL.0;
        if x > MARGIN && x + w > MAX_WIDTH - MARGIN {
            x = MARGIN;
            y += panel_h + GAP.1;
        }
        at.push((x, y));
        x += w + GAP.0;
        width = width.max(x - GAP.0 + MARGIN);
    }
    let height = y + panel_h + GAP.1 + LEGEND;
    (at, (width.max(600) as u32, height as u32))
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &HeatFigure) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let centre = Pos::new(HPos::Center, VPos::Center);
    let left = Pos::new(HPos::Left, VPos::Center);
    let right = Pos::new(HPos::Right, VPos::Center);
    let style = |size: u32, c: RGBColor, pos: Pos| TextStyle {
        font: (FONT, size).into_font(),
        color: c.to_backend_color(),
        pos,
    };
    root.draw(&Text::new(fig.title.clone(), (MARGIN, MARGIN + 8), style(18, BLACK, left))).map_err(err)?;
    root.draw(&Text::new(fig.axes.clone(), (MARGIN, MARGIN + 28), style(12, RGBColor(80, 80, 80), left)))
        .map_err(err)?;
    let (at, size) = layout(fig);
    for (p, &(x, y)) in fig.panels.iter().zip(&at) {
        let x0 = x + ROW_LABELS;
        root.draw(&Text::new(p.title.clone(), (x0, y + PANEL_TITLE / 2), style(13, BLACK, left))).map_err(err)?;
        let top = y + PANEL_TITLE;
        for (r, label) in fig.rows.iter().enumerate() {
            let cy = top + r as i32 * CELL.1 + CELL.1 / 2;
            root.draw(&Text::new(label.clone(), (x0 - 4, cy), style(11, BLACK, right))).map_err(err)?;
            for (c, cell) in p.cells.get(r).into_iter().flatten().enumerate() {
                let cx = x0 + c as i32 * CELL.0;
                let fill = colour(&cell.fill, &fig.scale);
                let (a, b) = ((cx, top + r as i32 * CELL.1), (cx + CELL.0 - 1, top + (r as i32 + 1) * CELL.1 - 1));
                root.draw(&Rectangle::new([a, b], fill.filled())).map_err(err)?;
                let t = Text::new(cell.text.clone(), (cx + CELL.0 / 2, cy), style(10, text_colour(fill), centre));
                root.draw(&t).map_err(err)?;
            }
        }
        let ly = top + fig.rows.len() as i32 * CELL.1 + COL_LABELS / 2;
        for (c, label) in p.columns.iter().enumerate() {
            let t = Text::new(label.clone(), (x0 + c as i32 * CELL.0 + CELL.0 / 2, ly), style(10, BLACK, centre));
            root.draw(&t).map_err(err)?;
        }
    }
    let y = size.1 as i32 - LEGEND + 8;
    let bar = match &fig.scale {
        Scale::Sequential { lo, hi, label } => Some((*lo, *hi, label)),
        Scale::Diverging { limit, label } => Some((-limit, *limit, label)),
        Scale::Categories(_) => None,
    };
    if let Scale::Categories(names) = &fig.scale {
        let mut x = MARGIN;
        for (k, name) in names.iter().enumerate() {
            let w = 14 + 7 * name.chars().count() as i32;
            if x + w > size.0 as i32 - MARGIN {
                break;
            }
            let c = colour(&Fill::Category(k), &fig.scale);
            root.draw(&Rectangle::new([(x, y), (x + 12, y + 12)], c.filled())).map_err(err)?;
            root.draw(&Text::new(name.clone(), (x + 16, y + 6), style(11, BLACK, left))).map_err(err)?;
            x += w + 20;
        }
    }
    if let Some((lo, hi, label)) = bar {
        let (w, steps) = (360, 90);
        for k in 0..steps {
            let v = lo + (hi - lo) * (k as f64 + 0.5) / steps as f64;
            let x = MARGIN + k * w / steps;
            let c = colour(&Fill::Value(v), &fig.scale);
            root.draw(&Rectangle::new([(x, y), (x + w / steps + 1, y + 14)], c.filled())).map_err(err)?;
        }
        let end = |v: f64| format!("{v:.3}");
        root.draw(&Text::new(end(lo), (MARGIN, y + 24), style(11, BLACK, left))).map_err(err)?;
        root.draw(&Text::new(end(hi), (MARGIN + w, y + 24), style(11, BLACK, right))).map_err(err)?;
        root.draw(&Text::new(label.clone(), (MARGIN + w + 16, y + 7), style(12, BLACK, left))).map_err(err)?;
    }
    root.present().map_err(err)
}

fn guarded(f: impl FnOnce() -> std::result::Result<(), String>) -> std::result::Result<(), String> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| Err("the plotting library panicked".to_string()))
}

/// Writes `fig` as `<stem>.svg` and `<stem>.png` in `dir`.
pub fn write_heatmap(dir: &Path, stem: &str, fig: &HeatFigure) -> Result<Vec<PathBuf>> {
    let _phase = crate::phases::enter(crate::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    ensure_font(dir)?;
    let size = layout(fig).1;
    let svg = dir.join(format!("{stem}.svg"));
    let mut text = String::new();
    guarded(|| render(&SVGBackend::with_string(&mut text, size).into_drawing_area(), fig))
        .map_err(|e| HarnessError::write(&svg, e))?;
    write_atomic(&svg, text.as_bytes())?;
    let png = dir.join(format!("{stem}.png"));
    write_png_with(&png, |tmp| guarded(|| render(&BitMapBackend::new(tmp, size).into_drawing_area(), fig)))?;
    Ok(vec![svg, png])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_map_to_their_ends_and_clamp() {
        let s = Scale::Sequential { lo: -2.0, hi: 2.0, label: String::new() };
        assert_eq!(colour(&Fill::Value(-5.0), &s), RGBColor(68, 1, 84));
        assert_eq!(colour(&Fill::Value(2.0), &s), RGBColor(253, 231, 37));
        let d = Scale::Diverging { limit: 3.0, label: String::new() };
        assert_eq!(colour(&Fill::Value(0.0), &d), WHITE);
        assert_eq!(colour(&Fill::Value(9.0), &d), RGBColor(178, 24, 43));
        assert_eq!(colour(&Fill::Value(f64::NAN), &d), colour(&Fill::Empty, &d));
    }

    #[test]
    fn a_heat_map_is_written_as_svg_and_png() {
        let dir = tempfile::tempdir().unwrap();
        let cell = |v: f64| HeatCell { fill: Fill::Value(v), text: format!("{v}") };
        let fig = HeatFigure {
            title: "test".into(),
            rows: vec!["a".into(), "b".into()],
            axes: "rows: a/b; columns: x".into(),
            panels: vec![
                Panel {
                    title: "p".into(),
                    columns: vec!["1".into(), "2".into()],
                    cells: vec![vec![cell(0.0), cell(1.0)], vec![cell(2.0), cell(f64::NAN)]],
                },
                Panel {
                    title: "q".into(),
                    columns: vec!["own".into()],
                    cells: vec![vec![cell(1.5)], vec![HeatCell { fill: Fill::Empty, text: "-".into() }]],
                },
            ],
            scale: Scale::Sequential { lo: 0.0, hi: 2.0, label: "log10".into() },
        };
        let files = write_heatmap(dir.path(), "h", &fig).unwrap();
        assert_eq!(files.len(), 2);
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        assert!(svg.contains("<svg") && svg.contains("own"));
        assert!(std::fs::metadata(&files[1]).unwrap().len() > 1000);
    }
}
