//! The plots root's `index.html`: every experiment folder under the root with its headline
//! verdicts, read from the data block each experiment's page carries (an [`Overview`] as JSON in a
//! `<script type="application/json">` element, which a browser does not run), so a run of one
//! experiment keeps the others' rows and no extra file is written.

use super::estimators::EstimatorLine;
use super::markup::{badge, count_badges, esc, interval_cell, page, table, url, verdict_class, Cell};
use crate::error::{HarnessError, Result};
use crate::output::report::{digest, interval, opt, sig};
use crate::output::{Claim, RunReport, Verdict};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The opening tag of an experiment page's data block.
const OVERVIEW_TAG: &str = "<script type=\"application/json\" id=\"mcbench-overview\">";

/// Claims the root index lists per experiment (beyond it: the ones that need attention).
const ROOT_CLAIMS: usize = 30;

/// One claim as the root index shows it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClaimLine {
    /// Test bed it was checked on.
    pub testbed: String,
    /// The claim in words.
    pub claim: String,
    /// The paper's number.
    pub paper_value: Option<f64>,
    /// Our number.
    pub our_value: Option<f64>,
    /// 95% interval of ours.
    pub interval: Option<[f64; 2]>,
    /// The verdict.
    pub verdict: Verdict,
    /// The p-value of a claim judged by a test (absent in pages drawn before it).
    #[serde(default)]
    pub p_value: Option<f64>,
}

impl From<&Claim> for ClaimLine {
    fn from(c: &Claim) -> Self {
        ClaimLine {
            testbed: c.testbed.clone(),
            claim: c.claim.clone(),
            paper_value: c.paper_value,
            our_value: c.our_value,
            interval: c.interval,
            verdict: c.verdict(),
            p_value: c.p_value,
        }
    }
}

/// An experiment's headline (the data block of its page).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Overview {
    /// Experiment name.
    pub experiment: String,
    /// `quick` or `full`.
    pub mode: String,
    /// Seed.
    pub seed: u64,
    /// Git commit of the source.
    pub git_commit: String,
    /// Run id.
    pub run_id: String,
    /// Wall-clock seconds of the run (timing).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub wall_seconds: f64,
    /// Every claim.
    pub claims: Vec<ClaimLine>,
    /// Deciding test rows per verdict.
    pub tests: Vec<(String, usize)>,
    /// Deciding test rows against the estimator's claim.
    pub failing_tests: usize,
    /// Figures on the page.
    pub figures: usize,
    /// Per (test bed, variant) and estimator, its cell at the largest budget (for the estimator
    /// pages; empty in pages drawn before them).
    #[serde(default)]
    pub estimators: Vec<EstimatorLine>,
}

impl Overview {
    /// The headline of a run whose page shows `figures` figures.
    pub fn of(report: &RunReport, figures: usize) -> Overview {
        let m = &report.meta;
        let deciding = digest::deciding(&report.tests);
        Overview {
            experiment: m.experiment.clone(),
            mode: m.mode.clone(),
            seed: m.seed,
            git_commit: m.git_commit.clone(),
            run_id: m.run_id.clone(),
            wall_seconds: m.wall_seconds,
            claims: report.paper.iter().map(ClaimLine::from).collect(),
            tests: digest::tally(deciding.iter().map(|t| t.verdict.as_str()), &digest::TEST_VERDICTS),
            failing_tests: deciding.iter().filter(|t| digest::is_failing(t)).count(),
            figures,
            estimators: super::estimators::lines(report),
        }
    }
}

/// What the root index found in one folder.
enum Entry {
    Read(Box<Overview>),
    /// A folder with a page or report but no readable overview (drawn by an older mcbench).
    Bare {
        name: String,
        why: String,
    },
}

/// The data block of a page: `overview` as JSON with `<`, `>` and `&` escaped (`\u003c`, ...), so
/// no text of a claim can end the element.
pub fn embed(overview: &Overview) -> Result<String> {
    let json = serde_json::to_string(overview).map_err(|e| HarnessError::write("the page's data block", e))?;
    let json = json.replace('<', "\\u003c").replace('>', "\\u003e").replace('&', "\\u0026");
    Ok(format!("{OVERVIEW_TAG}{json}</script>\n"))
}

/// The [`Overview`] in a page's data block.
pub fn read_overview(page: &str) -> std::result::Result<Overview, String> {
    let start = page.find(OVERVIEW_TAG).ok_or("no data block")? + OVERVIEW_TAG.len();
    let end = page[start..].find("</script>").ok_or("an unterminated data block")? + start;
    serde_json::from_str(&page[start..end]).map_err(|e| e.to_string())
}

fn entries(root: &Path) -> Vec<(String, Entry)> {
    let Ok(dirs) = std::fs::read_dir(root) else { return Vec::new() };
    let mut names: Vec<String> = dirs
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
        .filter_map(|e| e.file_name().to_str().map(String::from))
        .filter(|n| !n.starts_with('.'))
        .collect();
    names.sort();
    names
        .into_iter()
        .filter_map(|name| {
            let dir = root.join(&name);
            let read = std::fs::read_to_string(dir.join("index.html")).map_err(|e| e.to_string());
            match read.and_then(|page| read_overview(&page)) {
                Ok(o) => Some((name, Entry::Read(Box::new(o)))),
                Err(why) if dir.join("index.html").is_file() || dir.join("report.md").is_file() => {
                    Some((name.clone(), Entry::Bare { name, why: format!("no headline verdicts ({why})") }))
                }
                Err(_) => None,
            }
        })
        .collect()
}

fn page_link(name: &str, dir: &Path) -> String {
    let target = if dir.join("index.html").is_file() { "index.html" } else { "report.md" };
    format!("<a href=\"{}\">{}</a>", url(&format!("{name}/{target}")), esc(name))
}

fn claims_table(o: &Overview) -> String {
    let all = o.claims.len() <= ROOT_CLAIMS;
    let attention = |c: &&ClaimLine| c.verdict.needs_attention();
    let shown: Vec<&ClaimLine> =
        if all { o.claims.iter().collect() } else { o.claims.iter().filter(attention).take(ROOT_CLAIMS).collect() };
    let rows = shown
        .iter()
        .map(|c| {
            let value = if c.p_value.is_some() && c.our_value == c.p_value { None } else { c.our_value };
            let ours = format!("{} {}", opt(value), interval(c.interval));
            let cells = vec![
                Cell::text(&c.claim),
                Cell::text(&c.testbed),
                Cell::num(&opt(c.paper_value)),
                interval_cell(ours.trim(), c.interval),
                Cell::num(&c.p_value.map_or_else(|| "-".to_string(), |p| format!("{p:.2e}"))),
                Cell::html(badge(c.verdict.as_str())),
            ];
            (verdict_class(c.verdict.as_str()), cells)
        })
        .collect();
    let mut out = String::new();
    if !all {
        let _ = writeln!(
            out,
            "<p class=\"muted\">{} claims; the ones that did not hold or are inconclusive are listed (up to {ROOT_CLAIMS}), \
             every claim is on the experiment's page.</p>",
            o.claims.len()
        );
    }
    if !shown.is_empty() {
        out.push_str(&table(&["claim", "testbed", "paper", "ours (95% interval)", "p-value", "verdict"], rows));
    }
    out
}

/// The root index's HTML for the experiment folders under `root`.
pub fn render_root(root: &Path) -> String {
    let found = entries(root);
    let mut body = String::from("<h1>mcbench results</h1>\n");
    let _ = writeln!(
        body,
        "<p class=\"muted\">{} experiment folder{}. Each links to its page: every figure, per-pixel error maps of \
         image test beds, the claims, the tests and the result files.</p>",
        found.len(),
        if found.len() == 1 { "" } else { "s" }
    );
    let rows = found
        .iter()
        .map(|(name, e)| {
            let dir = root.join(name);
            match e {
                Entry::Read(o) => {
                    let claims = count_badges(&digest::tally(
                        o.claims.iter().map(|c| c.verdict.as_str()),
                        &digest::CLAIM_VERDICTS,
                    ));
                    let mut tests = count_badges(&o.tests);
                    if o.failing_tests > 0 {
                        let _ =
                            write!(tests, " <span class=\"badge v-fail\">{} against the claim</span>", o.failing_tests);
                    }
                    let commit: String = o.git_commit.chars().take(10).collect();
                    let thumb = super::thumbs::thumbnail(root, name, &format!("{name}/index.html"));
                    let cells = vec![
                        Cell::html(page_link(name, &dir)),
                        Cell::html(thumb.unwrap_or_default()),
                        Cell::text(&o.mode),
                        Cell::num(&o.seed.to_string()),
                        Cell::text(&commit),
                        Cell::html(claims),
                        Cell::html(tests),
                        Cell::num(&o.figures.to_string()),
                        Cell::num(&format!("{} s", sig(o.wall_seconds, 3))),
                    ];
                    (String::new(), cells)
                }
                Entry::Bare { name, why } => {
                    let mut cells = vec![
                        Cell::html(page_link(name, &dir)),
                        Cell::html(format!("<span class=\"muted\">{}</span>", esc(why))),
                    ];
                    cells.extend((0..7).map(|_| Cell::text("")));
                    (String::new(), cells)
                }
            }
        })
        .collect();
    let header = [
        "experiment",
        "first figure",
        "mode",
        "seed",
        "commit",
        "claims",
        "tests (deciding rows)",
        "figures",
        "wall time",
    ];
    body.push_str(&table(&header, rows));
    for (name, e) in &found {
        if let Entry::Read(o) = e {
            let _ = writeln!(body, "<h2 id=\"{}\">{}</h2>", esc(name), page_link(name, &root.join(name)));
            let claims = claims_table(o);
            body.push_str(if claims.is_empty() { "<p class=\"muted\">No claims.</p>\n" } else { &claims });
        }
    }
    let mut estimators: Vec<(&str, &str)> = found
        .iter()
        .filter_map(|(_, e)| if let Entry::Read(o) = e { Some(&o.estimators) } else { None })
        .flatten()
        .map(|l| (l.estimator.as_str(), l.label.as_str()))
        .collect();
    estimators.sort();
    estimators.dedup_by(|a, b| a.0 == b.0);
    if !estimators.is_empty() {
        let _ = writeln!(
            body,
            "<h2 id=\"estimators\">Estimators</h2>\n<p class=\"muted\">A page per estimator: every experiment and test \
             bed where it ran, its RMSE, efficiencies and unbiasedness verdict.</p>\n<p>{}</p>",
            estimators
                .iter()
                .map(|(id, label)| format!(
                    "<a href=\"{}/{}\">{}</a>",
                    super::estimators::FOLDER,
                    url(&super::estimators::file_name(id)),
                    esc(label)
                ))
                .collect::<Vec<_>>()
                .join(" &middot; ")
        );
    }
    let mut nav: Vec<(String, String)> = found.iter().map(|(n, _)| (format!("#{}", url(n)), n.clone())).collect();
    if !estimators.is_empty() {
        nav.push(("#estimators".into(), "estimators".into()));
    }
    page("mcbench results", &nav, &body)
}

/// Writes `<root>/index.html` and the estimator pages under `<root>/estimators/` (atomically),
/// holding the root's lock meanwhile so that runs of two experiments into the same root write them
/// one after the other.
pub fn write_root_index(root: &Path) -> Result<PathBuf> {
    let _lock = crate::store::folder::FolderLock::acquire(root, true, &[])?;
    let path = root.join("index.html");
    let found = entries(root);
    let lines: Vec<(&str, &[EstimatorLine])> = found
        .iter()
        .filter_map(|(n, e)| if let Entry::Read(o) = e { Some((n.as_str(), o.estimators.as_slice())) } else { None })
        .collect();
    super::estimators::write_pages(root, &lines)?;
    crate::output::write_atomic(&path, render_root(root).as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::tests::synthetic_report;

    #[test]
    fn the_root_lists_every_experiment_folder_with_its_verdicts() {
        let dir = tempfile::tempdir().expect("tempdir");
        let root = dir.path();
        let mut report = synthetic_report();
        report.paper.push(Claim {
            verdict: Some(Verdict::Inconclusive),
            claim: "a <second> claim".into(),
            ..report.paper[0].clone()
        });
        std::fs::create_dir_all(root.join("surface-smc")).expect("folder");
        let page = format!("<p>x</p>{}", embed(&Overview::of(&report, 4)).expect("data"));
        std::fs::write(root.join("surface-smc/index.html"), page).expect("page");
        std::fs::write(root.join("surface-smc/fig.svg"), "<svg width=\"200\" height=\"100\">").expect("figure");
        std::fs::create_dir_all(root.join("old")).expect("old");
        std::fs::write(root.join("old/report.md"), "x").expect("report");
        std::fs::create_dir_all(root.join("unrelated")).expect("other");
        let path = write_root_index(root).expect("written");
        let html = std::fs::read_to_string(path).expect("read");
        assert!(html.contains("<a href=\"surface-smc/index.html\">surface-smc</a>"), "{html}");
        assert!(
            html.contains("<a href=\"old/report.md\">old</a>") && html.contains("no headline verdicts (No such file"),
            "{html}"
        );
        assert!(!html.contains("unrelated"), "a folder without a page is not an experiment");
        assert!(html.contains("1 held</span> <span class=\"badge v-inconclusive\">1 inconclusive"));
        assert!(html.contains("a &lt;second&gt; claim") && html.contains("1 against the claim"));
        assert!(html.contains("2 experiment folders"));
        assert!(html.contains("<a href=\"surface-smc/index.html\"><img class=\"thumb\" src=\"surface-smc/fig.svg\" width=\"160\" height=\"80\""), "{html}");
    }

    #[test]
    fn the_data_block_reads_back_and_claim_text_cannot_end_it() {
        let mut report = synthetic_report();
        report.paper[0].claim = "a </script><b> & c".into();
        let block = embed(&Overview::of(&report, 2)).expect("data");
        assert_eq!(block.matches("</script>").count(), 1, "{block}");
        let back = read_overview(&format!("<html>{block}</html>")).expect("reads back");
        assert_eq!(back, Overview::of(&report, 2));
        assert!(read_overview("<html></html>").is_err());
    }

    #[test]
    fn long_claim_lists_keep_the_ones_that_need_attention() {
        let mut report = synthetic_report();
        let c = report.paper[0].clone();
        report.paper = (0..100).map(|i| Claim { claim: format!("c{i}."), held: Some(i != 42), ..c.clone() }).collect();
        let html = claims_table(&Overview::of(&report, 0));
        assert!(html.contains("c42.") && !html.contains("c41."), "{html}");
        assert!(html.contains("100 claims"));
    }
}
