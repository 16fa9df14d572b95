//! The figures of an experiment's page and a section per (test bed, variant): its figures (the
//! plots folder's files whose names start with the test bed and variant), its per-pixel maps
//! ([`super::pixel_maps`]) and its cells at the largest budget.

use super::markup::{esc, table, url, Cell};
use super::page::{label, Context};
use super::pixel_maps;
use crate::output::plot::sanitize;
use crate::output::report::digest::{self, FigureFiles};
use crate::output::report::{count, opt, relative_path, sig};
use crate::output::RunReport;
use std::fmt::Write as _;

/// Figures wider than this (in SVG pixels) take a whole row of the page.
const WIDE: f64 = 1000.0;

/// The width in pixels an SVG file declares on its root element, read from its first bytes.
fn svg_width(path: &std::path::Path) -> Option<f64> {
    use std::io::Read as _;
    let mut head = [0u8; 512];
    let n = std::fs::File::open(path).and_then(|mut f| f.read(&mut head)).ok()?;
    let text = String::from_utf8_lossy(&head[..n]);
    let svg = &text[text.find("<svg")?..];
    let value = svg[svg.find(" width=\"")? + 8..].split('"').next()?;
    value.trim_end_matches("px").parse().ok()
}

/// One figure, its image linking to the SVG (figures wider than [`WIDE`] pixels take a whole row).
fn figure(f: &FigureFiles, ctx: &Context<'_>) -> String {
    let href = |p: &std::path::Path| url(&relative_path(ctx.plots_dir, p));
    let links: Vec<String> = [(&f.svg, "SVG"), (&f.png, "PNG")]
        .into_iter()
        .filter_map(|(p, kind)| p.as_ref().map(|p| format!("<a href=\"{}\">{kind}</a>", href(p))))
        .collect();
    let wide = f.svg.as_deref().and_then(svg_width).is_some_and(|w| w > WIDE);
    format!(
        "<figure{}><a href=\"{src}\"><img src=\"{src}\" alt=\"{stem}\"></a><figcaption>{stem} &nbsp; {}</figcaption></figure>\n",
        if wide { " class=\"wide\"" } else { "" },
        links.join(" "),
        src = href(f.shown()),
        stem = esc(&f.stem),
    )
}

/// The figures and per-test-bed sections; returns the navigation links of the sections.
pub(super) fn figures(
    b: &mut String,
    report: &RunReport,
    ctx: &Context<'_>,
) -> crate::error::Result<Vec<(String, String)>> {
    let mut groups = digest::groups(report);
    for g in ctx.maps {
        if !groups.iter().any(|(t, v)| *t == g.testbed && *v == g.variant) {
            groups.push((g.testbed.clone(), g.variant.clone()));
        }
    }
    let (by_group, rest) = digest::figures_by_group(ctx.figures, &groups);
    let _ = writeln!(
        b,
        "<h2 id=\"figures\">Figures</h2>\n<p class=\"muted\">{} figures (SVG, with the PNG beside it).</p>",
        ctx.figures.len()
    );
    if !rest.is_empty() {
        b.push_str("<div class=\"figs\">\n");
        rest.iter().for_each(|f| b.push_str(&figure(f, ctx)));
        b.push_str("</div>\n");
    }
    let mut nav = Vec::new();
    for ((t, v), figs) in groups.iter().zip(&by_group) {
        let id = format!("g-{}-{}", sanitize(t), sanitize(v));
        let _ = writeln!(b, "<h2 id=\"{}\">{} / {}</h2>", esc(&id), esc(t), esc(v));
        nav.push((format!("#{}", url(&id)), format!("{t} / {v}")));
        if !figs.is_empty() {
            b.push_str("<div class=\"figs\">\n");
            figs.iter().for_each(|f| b.push_str(&figure(f, ctx)));
            b.push_str("</div>\n");
        }
        if let Some(g) = ctx.maps.iter().find(|g| g.testbed == *t && g.variant == *v) {
            b.push_str("<h3>Per-pixel z-scores and relative errors</h3>\n");
            b.push_str(&pixel_maps::render(g, &|e| label(report, e))?);
        }
        cells(b, report, t, v);
    }
    Ok(nav)
}

/// The cells of one group at its largest budget.
fn cells(b: &mut String, report: &RunReport, testbed: &str, variant: &str) {
    let on_bed = report.query().testbed(testbed).variant(variant);
    let (Some(first), Some(last)) = (on_bed.first(), on_bed.largest_budget()) else { return };
    let last_rows: Vec<_> = on_bed.at(last).iter().collect();
    let _ = writeln!(
        b,
        "<details><summary>The {} cells at the largest budget ({last} {}); every budget in summary.csv</summary>",
        last_rows.len(),
        esc(&first.budget_kind)
    );
    let table_rows = last_rows
        .iter()
        .map(|r| {
            let cells = vec![
                super::page::estimator_cell(report, &r.estimator),
                Cell::num(&sig(r.rmse, 4)),
                Cell::num(&format!("{} ± {}", sig(r.bias, 3), sig(r.bias_se, 3))),
                Cell::num(&sig(r.variance, 4)),
                Cell::num(&count(r.samples)),
                Cell::num(&count(r.fetches)),
                Cell::num(&sig(r.cpu_seconds, 4)),
                Cell::num(&opt(r.efficiency)),
                Cell::num(&opt(r.efficiency_mse)),
            ];
            (String::new(), cells)
        })
        .collect();
    let header = [
        "estimator",
        "rmse",
        "bias ± se",
        "variance",
        "samples",
        "fetches",
        "CPU s per estimate",
        "efficiency 1/(variance × CPU s)",
        "efficiency 1/(MSE × CPU s)",
    ];
    b.push_str(&table(&header, table_rows));
    b.push_str("</details>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_declared_svg_width_is_read() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("f.svg");
        std::fs::write(&path, "<?xml version=\"1.0\"?>\n<svg width=\"1396\" height=\"636\" viewBox=\"0 0 1396 636\">")
            .expect("svg");
        assert_eq!(svg_width(&path), Some(1396.0));
        std::fs::write(&path, "<svg viewBox=\"0 0 10 10\">").expect("svg");
        assert_eq!(svg_width(&path), None);
        assert_eq!(svg_width(&dir.path().join("missing.svg")), None);
    }
}
