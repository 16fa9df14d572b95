//! The run's HTML report: `<plots>/<experiment>/index.html`, one self-contained page per
//! experiment (an inline style sheet, figures as `<img>` of the SVG files beside it, per-pixel
//! maps as inline PNG images, one inline script that makes the tables sortable and filterable
//! ([`explore`]); no font or file from the network), and
//! `<plots>/index.html`, which lists every experiment folder under the plots root with its
//! headline verdicts. Every run that draws plots writes both, and so does `mcbench plot`.
//!
//! The pages are built from what the harness knows of any run (claims, tests, fits, figure files,
//! result files, the per-integral rows of the largest budget); nothing in them is specific to
//! one experiment.

mod contents;
pub mod estimators;
pub mod explore;
mod groups;
pub mod index;
pub mod markup;
pub mod page;
pub mod pixel_maps;
pub mod png;
pub mod thumbs;

pub use index::{write_root_index, Overview};

use crate::error::{HarnessError, Result};
use crate::output::integrals::IntegralRow;
use crate::output::report::digest;
use crate::output::RunReport;
use crate::store::folder::OutputDir;
use std::path::Path;

/// The experiment page's file name.
pub const PAGE: &str = "index.html";

/// Writes an experiment's `index.html` through its plots folder's writer (atomically, recorded for
/// the folder's commit): `integrals` are the per-integral rows of the
/// largest budget (for the per-pixel maps; empty: no maps), `results_dir` the folder whose files
/// the page links to. Figures are the SVG and PNG files in the plots folder.
pub fn write_page(report: &RunReport, plots: &OutputDir, results_dir: &Path, integrals: &[IntegralRow]) -> Result<()> {
    let figures = digest::figures_in(plots.path());
    let maps = pixel_maps::pixel_maps(integrals);
    let ctx = page::Context { plots_dir: plots.path(), results_dir, figures: &figures, maps: &maps };
    let html = page::render(report, &ctx)?;
    plots.write(PAGE, html.as_bytes()).map(|_| ())
}

/// The per-integral rows of a results folder's `integrals.csv` or `integrals.csv.gz` (the columns the maps use; the
/// others are left empty), or none when the folder has no such file.
pub fn read_integrals(results_dir: &Path) -> Result<Vec<IntegralRow>> {
    let Some(text) = crate::output::integrals::read_text(results_dir)? else { return Ok(Vec::new()) };
    let path = results_dir.join(crate::output::integrals::GZ);
    let bad = |why: String| HarnessError::bad_file(&path, why);
    let mut rd = csv::Reader::from_reader(text.as_bytes());
    let header = rd.headers().map_err(|e| bad(e.to_string()))?.clone();
    let col = |name: &str| header.iter().position(|h| h == name).ok_or_else(|| bad(format!("no column {name}")));
    let names = crate::output::integrals::COLUMNS;
    let idx: Vec<usize> = names.iter().map(|n| col(n)).collect::<Result<_>>()?;
    let mut out = Vec::new();
    for (line, rec) in rd.records().enumerate() {
        let rec = rec.map_err(|e| bad(e.to_string()))?;
        let text = |k: usize| rec.get(idx[k]).unwrap_or("").to_string();
        let field = |k: usize| bad(format!("row {}: {} is not a number", line + 2, names[k]));
        let int = |k: usize| rec.get(idx[k]).and_then(|s| s.parse::<usize>().ok()).ok_or_else(|| field(k));
        let num = |k: usize| rec.get(idx[k]).and_then(|s| s.parse::<f64>().ok()).ok_or_else(|| field(k));
        out.push(IntegralRow {
            testbed: text(0),
            variant: text(1),
            estimator: text(2),
            integral: int(3)?,
            px: int(4)?,
            py: int(5)?,
            channel: int(6)?,
            reference: num(7)?,
            reference_se: num(8)?,
            mean: num(9)?,
            std_err: num(10)?,
            geometry: Vec::new(),
            estimator_id: String::new(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::tests::synthetic_report;

    fn integral(i: usize, mean: f64) -> IntegralRow {
        IntegralRow {
            testbed: "gradient-plane".into(),
            variant: "default".into(),
            estimator: "is1_cv2".into(),
            integral: i,
            px: i % 2,
            py: i / 2,
            channel: 0,
            reference: 1.0,
            reference_se: 0.0,
            mean,
            std_err: 0.01,
            geometry: vec![("x", 0.5)],
            estimator_id: "is1_cv2".into(),
        }
    }

    #[test]
    fn a_page_links_only_files_that_exist_and_shows_every_figure_and_map() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (plots_dir, results_dir) = (dir.path().join("plots/surface-smc"), dir.path().join("results/surface-smc"));
        let report = synthetic_report();
        let figures = crate::output::plot::write_plots(&report, &plots_dir).expect("plots");
        std::fs::write(plots_dir.join("extra_figure.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\"/>").expect("svg");
        let results = OutputDir::new(&results_dir);
        crate::output::write_summary_csv(&results, &report.rows).expect("csv");
        crate::output::report::write_tables(&results, &report).expect("tables");
        let rows: Vec<IntegralRow> = (0..4).map(|i| integral(i, 1.0 + 0.01 * i as f64)).collect();
        crate::output::integrals::write(&results, &rows, crate::output::integrals::IntegralsFormat::Gz)
            .expect("integrals");
        let plots = OutputDir::new(&plots_dir);
        crate::output::report::write_report(&report, &figures, &plots_dir, &results_dir).expect("report.md");
        write_page(&report, &plots, &results_dir, &read_integrals(&results_dir).expect("read back")).expect("page");
        write_root_index(&dir.path().join("plots")).expect("root index and estimator pages");
        let html = std::fs::read_to_string(plots_dir.join(PAGE)).expect("page");
        assert!(html.contains("href=\"../estimators/is1_cv2.html\""), "estimator names link to their pages");
        for f in &figures {
            let name = f.file_name().and_then(|n| n.to_str()).expect("name");
            assert!(!name.ends_with(".svg") || html.contains(&format!("src=\"{name}\"")), "{name} not shown");
        }
        assert!(html.contains("src=\"extra_figure.svg\""), "a figure the harness did not draw is shown too");
        assert!(html.contains("Per-pixel z-scores") && html.contains("data:image/png;base64,"));
        for needle in [
            "../../results/surface-smc/tests.csv",
            "../../results/surface-smc/claims.csv",
            "../../results/surface-smc/summary.csv",
        ] {
            assert!(html.contains(&format!("href=\"{needle}\"")), "missing link {needle}");
        }
        // Every relative href and src resolves to a file or folder.
        for attr in ["href=\"", "src=\""] {
            for part in html.split(attr).skip(1) {
                let target = part.split('"').next().expect("value");
                if target.starts_with('#') || target.starts_with("data:") {
                    continue;
                }
                assert!(!target.contains("://"), "no network: {target}");
                let path = plots_dir.join(target.split('#').next().expect("path"));
                assert!(path.exists(), "{target} does not resolve");
            }
        }
        let at = |needle: &str| html.find(needle).unwrap_or_else(|| panic!("the page lacks {needle}"));
        assert!(at("id=\"contents\"") < at("<h2 id=\"figures\""), "the contents come first");
        assert!(at("<img src=") < at("<h2 id=\"claims\""), "figures before the long tables");
        assert!(at("<h2 id=\"claims\"") < at("<h2 id=\"tests\""));
        let script = format!("<script id=\"{}\">", explore::SCRIPT_ID);
        assert_eq!(html.matches(&script).count(), 1, "the table script once");
        let overview = index::read_overview(&html).expect("the page carries its headline");
        assert_eq!((overview.experiment.as_str(), overview.figures), ("surface-smc", figures.len() / 2 + 1));
    }

    #[test]
    fn p_values_have_their_own_column_and_wide_intervals_are_marked() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut report = synthetic_report();
        let base = report.paper[0].clone();
        report.paper.push(crate::output::Claim {
            claim: "a control is flagged".into(),
            our_value: Some(3.1e-7),
            p_value: Some(3.1e-7),
            ..base.clone()
        });
        report.paper.push(crate::output::Claim {
            claim: "a ratio".into(),
            our_value: Some(20.0),
            interval: Some([3.58, 116.0]),
            ..base.clone()
        });
        report.paper.push(crate::output::Claim {
            claim: "a narrow ratio".into(),
            our_value: Some(1.5),
            interval: Some([1.0, 2.0]),
            ..base
        });
        let ctx = page::Context { plots_dir: dir.path(), results_dir: dir.path(), figures: &[], maps: &[] };
        let html = page::render(&report, &ctx).expect("page");
        let claims =
            &html[html.find("<h2 id=\"claims\"").expect("claims")..html.find("<h2 id=\"fits\"").expect("fits")];
        let row = |text: &str| {
            let at = claims.find(text).unwrap_or_else(|| panic!("no row {text}"));
            claims[at..].split("</tr>").next().expect("row").to_string()
        };
        assert!(claims.contains("<th>ours</th><th>95% interval</th><th>p-value</th>"), "{claims}");
        let control = row("a control is flagged");
        assert_eq!(control.matches("3.10e-7").count(), 1, "the p-value once, in its column: {control}");
        assert!(
            control.contains("<td class=\"num\">-</td><td class=\"num\"></td><td class=\"num\">3.10e-7</td>"),
            "{control}"
        );
        assert!(row("a ratio").contains("[3.580, 116.0] <span class=\"wide\" title=\""), "{}", row("a ratio"));
        assert!(!row("a narrow ratio").contains("wide"), "{}", row("a narrow ratio"));
    }

    #[test]
    fn a_malformed_integrals_file_is_refused_naming_the_field() {
        let dir = tempfile::tempdir().expect("tempdir");
        assert!(read_integrals(dir.path()).expect("absent is fine").is_empty());
        let header = "testbed,variant,estimator,integral,px,py,channel,reference,reference_se,mean,std_err";
        std::fs::write(dir.path().join("integrals.csv"), format!("{header}\nt,v,e,0,0,0,0,1,0,x,0.1\n")).expect("csv");
        let e = read_integrals(dir.path()).expect_err("malformed");
        assert!(e.to_string().contains("row 2: mean is not a number") && e.exit_code() == 2, "{e}");
    }
}
