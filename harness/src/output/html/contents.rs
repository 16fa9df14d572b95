//! The table of contents at the top of an experiment's page: each section with what it holds in
//! a few words, so the verdicts read at a glance before the figures.

use super::markup::{count_badges, esc};
use crate::output::report::digest;
use crate::output::RunReport;
use std::fmt::Write as _;

/// The table of contents: each section with what it holds in a few words (the verdict counts of
/// the claims and tests, the number of figures, fits and skipped pairs).
pub(super) fn render(report: &RunReport, figures: usize, sections: &[(String, String)]) -> String {
    let mut toc = String::from("<div class=\"toc\" id=\"contents\"><b>Contents</b>\n<ol>\n");
    let beds: Vec<String> = sections.iter().map(|(h, t)| format!("<a href=\"{h}\">{}</a>", esc(t))).collect();
    let _ = writeln!(
        toc,
        "<li><a href=\"#figures\">Figures</a> ({}){}</li>",
        figures,
        if beds.is_empty() { String::new() } else { format!(": {}", beds.join(", ")) }
    );
    let claims = count_badges(&digest::claim_counts(&report.paper));
    let _ = writeln!(toc, "<li><a href=\"#claims\">Claims</a> {claims}</li>");
    let _ = writeln!(
        toc,
        "<li><a href=\"#fits\">Convergence fits and speed-ups</a> ({} fits, {} speed-ups)</li>",
        report.fits.len(),
        report.speedups.len()
    );
    let deciding = digest::deciding(&report.tests);
    let tests = count_badges(&digest::tally(deciding.iter().map(|t| t.verdict.as_str()), &digest::TEST_VERDICTS));
    let _ = writeln!(toc, "<li><a href=\"#tests\">Unbiasedness tests</a> {tests}</li>");
    let _ =
        writeln!(toc, "<li><a href=\"#skipped\">What did not run</a> ({} pairs skipped)</li>", report.skipped.len());
    toc.push_str("<li><a href=\"#files\">Files</a></li>\n</ol></div>\n");
    toc
}
