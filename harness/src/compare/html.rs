//! `compare.html`: one self-contained page (inline style, the report's inline table script that
//! sorts and filters the tables, no network) in the report's frame: what was compared and how, the
//! counts per verdict, the changed rows (regressed, then improved), and every row.

use super::change::{ChangeVerdict, Metric};
use super::write::describe;
use super::{Change, Comparison};
use crate::output::html::markup::{self, esc, Cell};

/// Colours of the comparison verdicts, beside the report's.
const STYLE: &str = "<style>.v-improved { background: #d8f0dc; color: #145a22; } \
.v-regressed { background: #f8d7d4; color: #8a1c12; } .v-no-change { background: #e4e8ee; color: #2b3444; }</style>\n";

fn rows(changes: &[&Change]) -> Vec<(String, Vec<Cell>)> {
    changes
        .iter()
        .map(|c| {
            let timing = if c.metric.timing() { " (CPU time)" } else { "" };
            (
                markup::verdict_class(c.verdict.word()),
                vec![
                    Cell::text(&c.experiment),
                    Cell::text(&format!("{}/{}", c.testbed, c.variant)),
                    Cell::text(&c.estimator),
                    Cell::num(&c.budget.map(|b| b.to_string()).unwrap_or_default()),
                    Cell::text(&format!("{}{timing}", c.metric.name())),
                    Cell::num(&number(c.a)),
                    Cell::num(&number(c.b)),
                    match c.metric {
                        Metric::Slope | Metric::Unbiasedness => Cell::num(&describe(c)),
                        _ => markup::interval_cell(&describe(c), Some([c.change_lo, c.change_hi])),
                    },
                    Cell::html(markup::badge(c.verdict.word())),
                    Cell::text(&crate::output::report::join_present(&[c.method.as_str(), c.note.as_str()])),
                ],
            )
        })
        .collect()
}

fn number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4e}")
    } else {
        String::new()
    }
}

const HEADER: [&str; 10] =
    ["experiment", "test bed", "estimator", "budget", "metric", "A", "B", "change [95%]", "verdict", "how"];

/// The page.
pub fn page(c: &Comparison) -> String {
    let mut body = String::from(STYLE);
    body.push_str(&format!("<h1>{} compared with {}</h1>\n", esc(&c.b), esc(&c.a)));
    body.push_str(&format!(
        "<p>A: <code>{}</code><br>B: <code>{}</code><br>Experiments: {}. No change: an RMSE ratio B / A whose 95% interval lies within [1/{:.3}, {:.3}] (efficiency and FoM ratios within the square of that band), a slope difference within ±{}. \
         Improved or regressed: the interval excludes no change and does not lie within that margin. \
         Rows marked CPU time depend on the machines and their load: their band is widened by the factor {:.3} for the drift of CPU time between runs.</p>\n",
        esc(&c.a_dir),
        esc(&c.b_dir),
        esc(&c.experiments.join(", ")),
        1.0 + c.margin,
        1.0 + c.margin,
        c.slope_margin,
        1.0 + c.time_margin
    ));
    let counts: Vec<(String, usize)> = c.counts().into_iter().map(|(v, n)| (v.word().to_string(), n)).collect();
    body.push_str(&format!("<p>{} rows: {}</p>\n", c.changes.len(), markup::count_badges(&counts)));
    if !c.notes.is_empty() {
        body.push_str("<ul>\n");
        for n in &c.notes {
            body.push_str(&format!("<li>{}</li>\n", esc(n)));
        }
        body.push_str("</ul>\n");
    }
    for (title, verdict) in [("Regressed", ChangeVerdict::Regressed), ("Improved", ChangeVerdict::Improved)] {
        let picked: Vec<&Change> = c.changes.iter().filter(|r| r.verdict == verdict).collect();
        if !picked.is_empty() {
            body.push_str(&format!("<h2>{title}</h2>\n"));
            body.push_str(&markup::table(&HEADER, rows(&picked)));
        }
    }
    body.push_str(&super::two_sample_html::section(c.two_sample.as_ref()));
    body.push_str("<h2>Every row</h2>\n");
    body.push_str(&markup::table(&HEADER, rows(&c.changes.iter().collect::<Vec<_>>())));
    markup::page(&format!("{} vs {}", c.b, c.a), &[], &body)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_page_is_self_contained_and_escapes_names() {
        let c = super::Comparison {
            a: "<old>".into(),
            a_dir: "r".into(),
            b: "new".into(),
            b_dir: "r2".into(),
            margin: 0.1,
            slope_margin: 0.1,
            time_margin: 0.25,
            experiments: vec!["x".into()],
            notes: vec!["a & b".into()],
            changes: vec![],
            two_sample: None,
        };
        let p = super::page(&c);
        assert!(p.contains("&lt;old&gt;") && p.contains("a &amp; b") && !p.contains("<old>"));
        assert!(!p.contains("http://") && !p.contains("https://"));
        let explore = crate::output::html::explore::SCRIPT_ID;
        assert_eq!(p.matches("<script").count(), 1, "only the table script");
        assert_eq!(p.matches(&format!("<script id=\"{explore}\">")).count(), 1, "the table script once");
    }
}
