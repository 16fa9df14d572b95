//! What a line figure is made of: series (points, an optional shaded interval band, line style
//! and markers), guide lines (reference slopes, break-even, a paper's number), panels (one log-log
//! chart each) and a figure of panels with one legend below them.

pub use super::style::Line;

/// One series of a panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text; empty keeps the series out of the legend (e.g. the dashed twin of a solid
    /// series whose style a [`Key`] explains).
    pub label: String,
    /// Style index: the same index gives the same colour and marker in every figure.
    pub style: usize,
    /// The points (x, y), both positive on log axes.
    pub points: Vec<(f64, f64)>,
    /// A shaded interval (x, low, high) around the points (empty: none).
    pub band: Vec<(f64, f64, f64)>,
    /// How the line is drawn.
    pub line: Line,
    /// Whether each point gets the style's marker.
    pub markers: bool,
}

impl Series {
    /// A solid series with markers.
    pub fn new(label: impl Into<String>, style: usize, points: Vec<(f64, f64)>) -> Series {
        Series { label: label.into(), style, points, band: Vec::new(), line: Line::Solid, markers: true }
    }

    /// The same series drawn with `line`.
    pub fn with_line(mut self, line: Line) -> Series {
        self.line = line;
        self
    }

    /// The same series without markers.
    pub fn without_markers(mut self) -> Series {
        self.markers = false;
        self
    }

    /// The same series with a shaded band (x, low, high).
    pub fn with_band(mut self, band: Vec<(f64, f64, f64)>) -> Series {
        self.band = band;
        self
    }
}

/// A reference line drawn behind the series, with its own legend entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Guide {
    /// Legend text.
    pub label: String,
    /// The line's points.
    pub points: Vec<(f64, f64)>,
    /// Colour: a series style index, or `None` for the guide grey.
    pub style: Option<usize>,
    /// Dashed or dotted.
    pub line: Line,
}

impl Guide {
    /// A grey dashed guide.
    pub fn grey(label: impl Into<String>, points: Vec<(f64, f64)>) -> Guide {
        Guide { label: label.into(), points, style: None, line: Line::Dashed }
    }
}

/// A legend entry explaining a line style (drawn in black): "solid: measured".
#[derive(Clone, Debug, PartialEq)]
pub struct Key {
    /// Legend text.
    pub label: String,
    /// The line style it explains.
    pub line: Line,
    /// Whether the entry shows a marker.
    pub marker: bool,
}

/// One log-log chart: everything needed to draw a plot, or one panel of a figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Title (the figure's title when drawn alone, the panel's title in [`Panels`]).
    pub title: String,
    /// x-axis title.
    pub x_desc: String,
    /// y-axis title.
    pub y_desc: String,
    /// The series.
    pub series: Vec<Series>,
    /// Guide lines.
    pub guides: Vec<Guide>,
}

impl Figure {
    /// A chart of `series`, without guides.
    pub fn new(
        title: impl Into<String>,
        x_desc: impl Into<String>,
        y_desc: impl Into<String>,
        series: Vec<Series>,
    ) -> Figure {
        Figure { title: title.into(), x_desc: x_desc.into(), y_desc: y_desc.into(), series, guides: Vec::new() }
    }

    /// Whether some series has two points to draw a line through.
    pub fn has_line(&self) -> bool {
        self.series.iter().any(|s| s.points.len() >= 2)
    }
}

/// A figure of panels (two columns when there are several) sharing one legend: a series named
/// alike in several panels (same label, style and line) has one entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Panels {
    /// Figure title.
    pub title: String,
    /// The panels, row by row.
    pub panels: Vec<Figure>,
    /// Legend entries for line styles, after the series and guides.
    pub keys: Vec<Key>,
    /// A line of text under the legend (empty: none).
    pub note: String,
}

impl Panels {
    /// A figure of one chart, titled with the chart's title.
    pub fn single(fig: &Figure) -> Panels {
        let panel = Figure { title: String::new(), ..fig.clone() };
        Panels { title: fig.title.clone(), panels: vec![panel], keys: Vec::new(), note: String::new() }
    }
}

/// One entry of a figure's legend.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Entry {
    /// A series: label, style, line, markers, band.
    Series(String, usize, Line, bool, bool),
    /// A guide: label, colour style, line.
    Guide(String, Option<usize>, Line),
    /// A key.
    Key(Key),
}

impl Entry {
    /// Its text.
    pub(super) fn label(&self) -> &str {
        match self {
            Entry::Series(l, ..) | Entry::Guide(l, ..) => l,
            Entry::Key(k) => &k.label,
        }
    }
}

impl Panels {
    /// The legend: series in order of first appearance (drawn ones with a label; one entry per
    /// label, style and line), then guides, then keys, each once.
    pub(super) fn legend(&self) -> Vec<Entry> {
        let mut out: Vec<Entry> = Vec::new();
        for s in self.panels.iter().flat_map(|p| &p.series).filter(|s| !s.label.is_empty() && !s.points.is_empty()) {
            let alike = |e: &&mut Entry| matches!(e, Entry::Series(l, st, li, ..) if *l == s.label && *st == s.style && *li == s.line);
            match out.iter_mut().find(alike) {
                // Drawn with markers or a band in one panel and without in another: the entry
                // shows them.
                Some(Entry::Series(.., markers, band)) => {
                    *markers |= s.markers;
                    *band |= !s.band.is_empty();
                }
                _ => out.push(Entry::Series(s.label.clone(), s.style, s.line, s.markers, !s.band.is_empty())),
            }
        }
        let guides = self.panels.iter().flat_map(|p| &p.guides).filter(|g| !g.points.is_empty());
        let rest = guides
            .map(|g| Entry::Guide(g.label.clone(), g.style, g.line))
            .chain(self.keys.iter().cloned().map(Entry::Key));
        for e in rest {
            if !out.contains(&e) {
                out.push(e);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_series_named_alike_in_several_panels_has_one_legend_entry() {
        let a = Series::new("A", 0, vec![(1.0, 1.0), (2.0, 0.5)]).with_band(vec![(1.0, 0.9, 1.1)]);
        let b = Series::new("A", 0, vec![(1.0, 3.0)]).without_markers();
        let hidden = Series::new("", 0, vec![(1.0, 2.0)]).with_line(Line::Dashed);
        let mut p1 = Figure::new("one", "x", "y", vec![b, hidden]);
        p1.guides.push(Guide::grey("slope -1/2", vec![(1.0, 1.0), (4.0, 0.5)]));
        let p2 = Figure::new("two", "x", "y", vec![a]);
        let fig = Panels {
            title: "t".into(),
            panels: vec![p1, p2],
            keys: vec![Key { label: "dashed: predicted".into(), line: Line::Dashed, marker: false }],
            note: String::new(),
        };
        let labels: Vec<String> = fig.legend().iter().map(|e| e.label().to_string()).collect();
        assert_eq!(labels, ["A", "slope -1/2", "dashed: predicted"]);
        assert!(matches!(fig.legend()[0], Entry::Series(_, 0, Line::Solid, true, true)), "the band is shown");
    }
}
