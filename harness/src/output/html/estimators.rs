//! A page per estimator, `<plots>/estimators/<estimator>.html`: every experiment and (test bed,
//! variant) under the plots root where the estimator ran, with its RMSE, both efficiencies and its
//! deciding unbiasedness verdict at the largest budget. The rows come from the data block of each
//! experiment's page ([`EstimatorLine`]s of its [`super::Overview`]), so the root index writes
//! these pages with its own and no result file is read.

use super::markup::{badge, esc, page, table, url, Cell};
use crate::error::Result;
use crate::output::plot::sanitize;
use crate::output::report::{digest, opt, sig};
use crate::output::RunReport;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// The folder of the estimator pages under the plots root.
pub const FOLDER: &str = "estimators";

/// One (test bed, variant) where an estimator ran, at the largest budget of that group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EstimatorLine {
    /// Estimator id.
    pub estimator: String,
    /// The estimator's id with its paper label.
    pub label: String,
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// The largest budget of the group.
    pub budget: u64,
    /// RMSE at that budget.
    pub rmse: Option<f64>,
    /// 1 / (variance x CPU seconds per estimate).
    pub efficiency: Option<f64>,
    /// 1 / (MSE x CPU seconds per estimate).
    pub efficiency_mse: Option<f64>,
    /// The deciding unbiasedness verdict of the pair (empty: not tested).
    pub verdict: String,
    /// Its p-value.
    pub p_value: Option<f64>,
}

/// The lines of a run: per (test bed, variant) and estimator, its cell at the group's largest budget.
pub fn lines(report: &RunReport) -> Vec<EstimatorLine> {
    let finite = |x: f64| x.is_finite().then_some(x);
    let deciding = digest::deciding(&report.tests);
    let mut out = Vec::new();
    for (t, v) in digest::groups(report) {
        let on_bed = report.query().testbed(&t).variant(&v);
        let Some(last) = on_bed.largest_budget() else { continue };
        for r in on_bed.at(last).iter() {
            let test = deciding
                .iter()
                .filter(|x| (&x.testbed, &x.variant, &x.estimator) == (&t, &v, &r.estimator))
                .max_by_key(|x| x.budget);
            out.push(EstimatorLine {
                estimator: r.estimator.clone(),
                label: super::page::label(report, &r.estimator),
                testbed: t.clone(),
                variant: v.clone(),
                budget: last,
                rmse: finite(r.rmse),
                efficiency: r.efficiency,
                efficiency_mse: r.efficiency_mse,
                verdict: test.map(|x| x.verdict.clone()).unwrap_or_default(),
                p_value: test.and_then(|x| finite(x.p_value)),
            });
        }
    }
    out
}

/// The file name of an estimator's page.
pub fn file_name(estimator: &str) -> String {
    format!("{}.html", sanitize(estimator))
}

/// The link from an experiment page (one folder below the root) to an estimator's page.
pub fn link_from_experiment(estimator: &str, text: &str) -> String {
    format!("<a href=\"../{FOLDER}/{}\">{}</a>", url(&file_name(estimator)), esc(text))
}

fn render(estimator: &str, rows: &[(&str, &EstimatorLine)]) -> String {
    let label = rows.first().map_or(estimator, |(_, l)| l.label.as_str());
    let mut body = format!("<h1>{}</h1>\n", esc(label));
    let experiments: std::collections::BTreeSet<&str> = rows.iter().map(|(e, _)| *e).collect();
    let _ = writeln!(
        body,
        "<p class=\"muted\">Where {} ran under this plots root: {} (test bed, variant) {} in {} experiment{}, each at \
         its largest budget (every budget is in the experiment's summary.csv).</p>",
        esc(estimator),
        rows.len(),
        if rows.len() == 1 { "pair" } else { "pairs" },
        experiments.len(),
        if experiments.len() == 1 { "" } else { "s" }
    );
    let cells = rows
        .iter()
        .map(|(exp, l)| {
            let page = format!("../{exp}/index.html");
            let group =
                format!("{}#{}", url(&page), url(&format!("g-{}-{}", sanitize(&l.testbed), sanitize(&l.variant))));
            let cells = vec![
                Cell::html(format!("<a href=\"{}\">{}</a>", url(&page), esc(exp))),
                Cell::html(format!("<a href=\"{group}\">{} / {}</a>", esc(&l.testbed), esc(&l.variant))),
                Cell::num(&l.budget.to_string()),
                Cell::num(&l.rmse.map_or_else(|| "-".into(), |x| sig(x, 4))),
                Cell::num(&opt(l.efficiency)),
                Cell::num(&opt(l.efficiency_mse)),
                if l.verdict.is_empty() { Cell::text("-") } else { Cell::html(badge(&l.verdict)) },
                Cell::num(&l.p_value.map_or_else(|| "-".into(), |p| format!("{p:.2e}"))),
            ];
            (String::new(), cells)
        })
        .collect();
    let header = [
        "experiment",
        "test bed / variant",
        "budget",
        "rmse",
        "efficiency 1/(variance × CPU s)",
        "efficiency 1/(MSE × CPU s)",
        "unbiasedness (deciding test)",
        "p-value",
    ];
    body.push_str(&table(&header, cells));
    page(&format!("mcbench: {estimator}"), &[("../index.html".into(), "all experiments".into())], &body)
}

/// Writes a page per estimator found in `experiments` (name and lines) into `<root>/estimators/`
/// (atomically); returns the estimator ids with their labels, sorted, for the root index.
pub fn write_pages(root: &Path, experiments: &[(&str, &[EstimatorLine])]) -> Result<Vec<(String, String)>> {
    let mut by: BTreeMap<&str, Vec<(&str, &EstimatorLine)>> = BTreeMap::new();
    for (exp, lines) in experiments {
        for l in lines.iter() {
            by.entry(l.estimator.as_str()).or_default().push((exp, l));
        }
    }
    if by.is_empty() {
        return Ok(Vec::new());
    }
    let dir = root.join(FOLDER);
    std::fs::create_dir_all(&dir).map_err(|e| crate::error::HarnessError::write(dir.clone(), e))?;
    let mut out = Vec::new();
    for (estimator, rows) in &by {
        crate::output::write_atomic(&dir.join(file_name(estimator)), render(estimator, rows).as_bytes())?;
        out.push((estimator.to_string(), rows[0].1.label.clone()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::tests::synthetic_report;

    #[test]
    fn each_estimator_gets_a_page_with_its_rows_from_every_experiment() {
        let dir = tempfile::tempdir().expect("tempdir");
        let report = synthetic_report();
        let mine = lines(&report);
        assert!(!mine.is_empty());
        let biased = mine.iter().find(|l| l.estimator == "is1_cv2").expect("is1_cv2 ran");
        assert_eq!((biased.verdict.as_str(), biased.p_value), ("biased", Some(3.1e-7)), "{biased:?}");
        let written = write_pages(dir.path(), &[("exp-a", &mine), ("exp b", &mine)]).expect("pages");
        assert!(written.iter().any(|(id, _)| id == "is1_cv2"));
        let html = std::fs::read_to_string(dir.path().join("estimators/is1_cv2.html")).expect("page");
        assert!(html.contains("href=\"../exp-a/index.html\"") && html.contains("href=\"../exp%20b/index.html\""));
        assert!(html.contains("href=\"../exp-a/index.html#g-gradient-plane-default\""), "{html}");
        assert!(html.contains("3.10e-7") && html.contains("class=\"badge v-biased\""), "{html}");
        assert!(html.contains("efficiency 1/(MSE × CPU s)"));
        assert!(write_pages(dir.path(), &[]).expect("nothing").is_empty());
    }
}
