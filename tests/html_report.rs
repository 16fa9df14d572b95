//! The HTML report without a browser (scripts/browser_check.py opens the same pages in headless
//! Chromium in CI): a small run writes an experiment page and the plots root's index, every
//! relative link and image source on them resolves, nothing comes from the network, each page
//! runs its one table script only, the figures come before the long tables, the estimator pages
//! resolve too, the pages and the summary stay small, a second experiment keeps the first one's
//! row in the root index, and `mcbench plot` redraws the pages (with the per-pixel maps) from the
//! results folder alone.

use std::path::Path;
use std::process::{Command, Output};

const CONFIG: &str = include_str!("../scripts/browser_check.toml");

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let o = mcbench(dir, args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The values of every `href="..."` and `src="..."` attribute of a page.
fn references(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attr in [" href=\"", " src=\""] {
        for part in html.split(attr).skip(1) {
            out.push(part.split('"').next().expect("closing quote").replace("&amp;", "&"));
        }
    }
    out
}

/// Every reference of the page at `page` resolves: a relative path to a file or folder that
/// exists, an in-page anchor to an id on the page, or inline data; nothing names another site.
fn assert_resolves(page: &Path) {
    let html = read(page);
    for r in references(&html) {
        assert!(!r.contains("://") && !r.starts_with("//"), "{}: {r} reaches the network", page.display());
        if r.starts_with("data:image/png;base64,") {
            continue;
        }
        if let Some(anchor) = r.strip_prefix('#') {
            assert!(html.contains(&format!("id=\"{anchor}\"")), "{}: no element with id {anchor}", page.display());
            continue;
        }
        let path = r.split('#').next().expect("path").replace("%20", " ");
        let target = page.parent().expect("folder").join(&path);
        assert!(target.exists(), "{}: {r} does not resolve ({} is missing)", page.display(), target.display());
    }
    let scripts = html.matches("<script").count();
    let data = html.matches("<script type=\"application/json\"").count();
    let tables = html.matches("<script id=\"mcbench-explore\">").count();
    assert_eq!(tables, 1, "{}: the table script once", page.display());
    assert_eq!(scripts, data + 1, "{}: no script but the table script (and a data block)", page.display());
}

#[test]
fn a_run_writes_pages_whose_links_resolve_and_the_root_keeps_every_experiment() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("check.toml"), CONFIG).expect("config");
    let out = ok(d, &["run", "--config", "check.toml", "--threads", "2"]);
    assert!(out.contains("HTML report (open in a browser): plots/index.html"), "{out}");

    let (page, root) = (d.join("plots/browser-check/index.html"), d.join("plots/index.html"));
    for p in [&page, &root] {
        assert_resolves(p);
        let bytes = std::fs::metadata(p).expect("page").len();
        assert!(bytes < 2_000_000, "{} is {bytes} bytes", p.display());
    }
    let html = read(&page);
    for needle in [
        "<h2 id=\"claims\">Claims</h2>",
        "class=\"badge v-inconclusive\"",
        "Per-pixel z-scores and relative errors",
        "src=\"data:image/png;base64,",
        "src=\"gradient-plane_glossy_convergence.svg\"",
        "href=\"../../results/browser-check/tests.csv\"",
        "href=\"../../results/browser-check/claims.csv\"",
        "href=\"../../results/browser-check/summary.json\"",
    ] {
        assert!(html.contains(needle), "the page lacks {needle}");
    }
    // The figures come before the long tables; estimator names link to the estimator pages the root
    // index wrote, and the root shows a thumbnail of the experiment's first figure.
    assert!(html.find("<h2 id=\"figures\"").expect("figures") < html.find("<h2 id=\"claims\"").expect("claims"));
    assert!(html.contains("href=\"../estimators/is1_cv2.html\""), "estimator names link to their pages");
    for id in ["is0_cv0", "is1_cv2"] {
        let estimator = d.join(format!("plots/estimators/{id}.html"));
        assert_resolves(&estimator);
        assert!(read(&estimator).contains("href=\"../browser-check/index.html\""), "{id}'s page lists the run");
    }
    assert!(read(&root).contains("<img class=\"thumb\" src=\"browser-check/"), "the root shows a thumbnail");
    let md = read(&d.join("plots/browser-check/report.md"));
    assert!(md.len() < 100_000 && md.contains("[index.html](index.html)"));
    // The long tables are result files, listed in the folder's commit.
    let commit = read(&d.join("results/browser-check/commit.json"));
    assert!(commit.contains("\"tests.csv\"") && commit.contains("\"claims.csv\""), "{commit}");
    let plots_commit = read(&d.join("plots/browser-check/commit.json"));
    assert!(plots_commit.contains("\"index.html\"") && plots_commit.contains("\"report.md\""));

    // A second experiment into the same plots root: the root lists both.
    std::fs::write(d.join("other.toml"), CONFIG.replace("name = \"browser-check\"", "name = \"other\""))
        .expect("config");
    ok(d, &["run", "--config", "other.toml", "--threads", "2"]);
    let index = read(&root);
    for name in ["browser-check", "other"] {
        assert!(index.contains(&format!("href=\"{name}/index.html\"")), "the root lost {name}");
    }
    assert!(index.contains("independent MC converges at -1/2"), "the root shows the claims");

    // `mcbench plot` redraws both pages from the results folder, maps included.
    std::fs::remove_dir_all(d.join("plots")).expect("rm");
    ok(d, &["plot", "results/browser-check"]);
    assert_resolves(&page);
    assert!(read(&page).contains("src=\"data:image/png;base64,"), "the maps come from integrals.csv");
    assert!(read(&root).contains("href=\"browser-check/index.html\""));
}
