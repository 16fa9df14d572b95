//! Heat maps: panels of coloured cells (one panel per estimator, rows and columns two swept
//! parameters), each cell annotated, with a colour bar (sequential or diverging scale) or a legend
//! of categories. Panels flow left to right; a panel with a heading starts a new row under that
//! heading, so one figure holds a grid of sections (e.g. one per profile) on one scale. Written as
//! SVG and PNG like the line plots, in the same style ([`super::style`]).

use super::style::{self, text, FONT, MARGIN};
use crate::error::{HarnessError, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

const CELL: (i32, i32) = (50, 24);
const ROW_LABELS: i32 = 44;
const PANEL_TITLE: i32 = 20;
const COL_LABELS: i32 = 18;
const GAP: (i32, i32) = (22, 16);
const HEADING: i32 = 28;
const TITLE: i32 = 48;
const LEGEND: i32 = 64;
const MAX_WIDTH: i32 = 1500;
/// Size of the text inside cells (smaller than the other text: it annotates a 50 x 24 cell).
const CELL_TEXT: u32 = 10;

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
    /// A heading: when not empty the panel starts a new row of panels, under this text.
    pub heading: String,
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

/// Panel origins (left, top), the headings (top, text) and the figure size.
type Layout = (Vec<(i32, i32)>, Vec<(i32, String)>, (u32, u32));

/// Panels flow left to right and wrap at [`MAX_WIDTH`]; a heading starts a new row.
fn layout(fig: &HeatFigure) -> Layout {
    let rows = fig.rows.len() as i32;
    let panel_h = PANEL_TITLE + rows * CELL.1 + COL_LABELS;
    let (mut x, mut y, mut width) = (MARGIN as i32, MARGIN as i32 + TITLE, 0);
    let (mut at, mut headings) = (Vec::new(), Vec::new());
    for (k, p) in fig.panels.iter().enumerate() {
        let w = ROW_LABELS + p.columns.len() as i32 * CELL.0;
        if k > 0 && (!p.heading.is_empty() || x + w > MAX_WIDTH - MARGIN as i32) {
            x = MARGIN as i32;
            y += panel_h + GAP.1;
        }
        if !p.heading.is_empty() {
            headings.push((y, p.heading.clone()));
            y += HEADING;
        }
        at.push((x, y));
        x += w + GAP.0;
        width = width.max(x - GAP.0 + MARGIN as i32);
    }
    let height = y + panel_h + GAP.1 + LEGEND;
    (at, headings, (width.max(900) as u32, height as u32))
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &HeatFigure) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let (at, headings, size) = layout(fig);
    let centre = Pos::new(HPos::Center, VPos::Center);
    let left = Pos::new(HPos::Left, VPos::Center);
    let right = Pos::new(HPos::Right, VPos::Center);
    let grey = RGBColor(80, 80, 80);
    let title = text(style::TITLE_SIZE, BLACK).pos(Pos::new(HPos::Center, VPos::Top));
    root.draw(&Text::new(fig.title.clone(), (size.0 as i32 / 2, 10), title)).map_err(err)?;
    let axes = text(style::LEGEND_SIZE, grey).pos(left);
    root.draw(&Text::new(fig.axes.clone(), (MARGIN as i32, MARGIN as i32 + 28), axes)).map_err(err)?;
    for (y, heading) in &headings {
        let t = text(style::PANEL_TITLE_SIZE, BLACK).pos(left);
        root.draw(&Text::new(heading.clone(), (MARGIN as i32, y + HEADING / 2), t)).map_err(err)?;
    }
    let small = |c: RGBColor, pos: Pos| text(CELL_TEXT, c).pos(pos);
    for (p, &(x, y)) in fig.panels.iter().zip(&at) {
        let x0 = x + ROW_LABELS;
        let t = text(style::LEGEND_SIZE, BLACK).pos(left);
        root.draw(&Text::new(p.title.clone(), (x0, y + PANEL_TITLE / 2), t)).map_err(err)?;
        let top = y + PANEL_TITLE;
        for (r, label) in fig.rows.iter().enumerate() {
            let cy = top + r as i32 * CELL.1 + CELL.1 / 2;
            root.draw(&Text::new(label.clone(), (x0 - 4, cy), small(BLACK, right))).map_err(err)?;
            for (c, cell) in p.cells.get(r).into_iter().flatten().enumerate() {
                let cx = x0 + c as i32 * CELL.0;
                let fill = colour(&cell.fill, &fig.scale);
                let (a, b) = ((cx, top + r as i32 * CELL.1), (cx + CELL.0 - 1, top + (r as i32 + 1) * CELL.1 - 1));
                root.draw(&Rectangle::new([a, b], fill.filled())).map_err(err)?;
                let t = Text::new(cell.text.clone(), (cx + CELL.0 / 2, cy), small(text_colour(fill), centre));
                root.draw(&t).map_err(err)?;
            }
        }
        let ly = top + fig.rows.len() as i32 * CELL.1 + COL_LABELS / 2;
        for (c, label) in p.columns.iter().enumerate() {
            let t = Text::new(label.clone(), (x0 + c as i32 * CELL.0 + CELL.0 / 2, ly), small(BLACK, centre));
            root.draw(&t).map_err(err)?;
        }
    }
    draw_scale(root, fig, size.1 as i32 - LEGEND + 8, size.0 as i32)?;
    root.present().map_err(err)
}

/// The colour bar (ends and middle labelled) or the legend of categories, from `y` down.
fn draw_scale<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &HeatFigure,
    y: i32,
    width: i32,
) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let label = |pos: HPos| text(style::LEGEND_SIZE, BLACK).pos(Pos::new(pos, VPos::Center));
    let m = MARGIN as i32;
    if let Scale::Categories(names) = &fig.scale {
        let font = (FONT, style::LEGEND_SIZE).into_font();
        let mut x = m;
        for (k, name) in names.iter().enumerate() {
            let w = 18 + font.box_size(name).map(|b| b.0 as i32).unwrap_or(8 * name.len() as i32);
            if x + w > width - m {
                break;
            }
            let c = colour(&Fill::Category(k), &fig.scale);
            root.draw(&Rectangle::new([(x, y), (x + 13, y + 13)], c.filled())).map_err(err)?;
            root.draw(&Text::new(name.clone(), (x + 18, y + 7), label(HPos::Left))).map_err(err)?;
            x += w + 20;
        }
        return Ok(());
    }
    let (lo, hi, what) = match &fig.scale {
        Scale::Sequential { lo, hi, label } => (*lo, *hi, label),
        Scale::Diverging { limit, label } => (-limit, *limit, label),
        Scale::Categories(_) => return Ok(()),
    };
    let (w, steps) = (360, 90);
    for k in 0..steps {
        let v = lo + (hi - lo) * (k as f64 + 0.5) / steps as f64;
        let x = m + k * w / steps;
        let c = colour(&Fill::Value(v), &fig.scale);
        root.draw(&Rectangle::new([(x, y), (x + w / steps + 1, y + 14)], c.filled())).map_err(err)?;
    }
    let end = |v: f64| crate::output::report::sig(v, 3);
    root.draw(&Text::new(end(lo), (m, y + 25), label(HPos::Left))).map_err(err)?;
    root.draw(&Text::new(end((lo + hi) / 2.0), (m + w / 2, y + 25), label(HPos::Center))).map_err(err)?;
    root.draw(&Text::new(end(hi), (m + w, y + 25), label(HPos::Right))).map_err(err)?;
    root.draw(&Text::new(what.clone(), (m + w + 16, y + 7), label(HPos::Left))).map_err(err)?;
    Ok(())
}

/// Writes `fig` as `<stem>.svg` and `<stem>.png` in `dir`.
pub fn write_heatmap(dir: &Path, stem: &str, fig: &HeatFigure) -> Result<Vec<PathBuf>> {
    let _phase = crate::run::phases::enter(crate::run::phases::Phase::Output);
    std::fs::create_dir_all(dir).map_err(|e| HarnessError::write(dir, e))?;
    let size = layout(fig).2;
    let (svg, png) = (dir.join(format!("{stem}.svg")), dir.join(format!("{stem}.png")));
    super::write_svg(&svg, size, |root| render(&root, fig))?;
    super::png::write_png(&png, size, |root| render(&root, fig))?;
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
                    heading: String::new(),
                    title: "p".into(),
                    columns: vec!["1".into(), "2".into()],
                    cells: vec![vec![cell(0.0), cell(1.0)], vec![cell(2.0), cell(f64::NAN)]],
                },
                Panel {
                    heading: "second row".into(),
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
        assert!(svg.contains("<svg") && svg.contains("own") && svg.contains("second row"));
        let (at, headings, _) = layout(&fig);
        assert!(at[1].1 > at[0].1, "a heading starts a new row: {at:?}");
        assert_eq!(headings.len(), 1);
        assert!(std::fs::metadata(&files[1]).unwrap().len() > 1000);
    }
}
