//! What a run prints: one line per experiment (its claims and unbiasedness decisions counted by
//! verdict, and its time), then the claims that did not hold, the decisions that contradict an
//! estimator's registered claim, what the verdict words mean and where the report is. The full
//! tables (fits, tests, claims, skipped pairs) are printed with `--verbose`, fitted to the
//! terminal's width; `report.md` holds them either way.

pub mod tally;

use crate::output::query::Query;
use crate::output::report::sig;
use crate::output::RunReport;
use crate::registry::Registry;
use comfy_table::{presets::UTF8_FULL_CONDENSED, ColumnConstraint, ContentArrangement, Table};
pub use tally::Tally;

/// Width of the experiment-name column of the one-line summaries.
const NAME_WIDTH: usize = 15;
/// The claims that did not hold listed at the end of a run; the rest are counted.
const MOST_CLAIMS: usize = 30;
/// The contradicting unbiasedness decisions listed at the end of a run; the rest are counted.
const MOST_CONTRADICTING: usize = 5;

/// The width lines are cut to and tables fitted to: the terminal's, else `COLUMNS`, else (output
/// to a file or a pipe) [`OFF_TERMINAL_WIDTH`].
pub fn terminal_width() -> usize {
    let term = console::Term::stdout();
    term.size_checked()
        .map(|(_, w)| w as usize)
        .or_else(|| std::env::var("COLUMNS").ok().and_then(|c| c.parse().ok()))
        .filter(|w| *w >= 40)
        .unwrap_or(OFF_TERMINAL_WIDTH)
}

/// The width off a terminal: wide enough that a log keeps whole claim lines.
pub const OFF_TERMINAL_WIDTH: usize = 200;

/// Prints one experiment's run that took `seconds`: its line, and with `verbose` its tables
/// first. Returns what was counted, for [`print_totals`].
pub fn print_experiment(r: &RunReport, seconds: f64, verbose: bool, registry: &Registry) -> Tally {
    let tally = Tally::of(r, seconds, registry);
    if verbose {
        print!("{}", tables(r, seconds, terminal_width()));
    }
    println!("{}", tally.line(NAME_WIDTH));
    tally
}

/// Prints the end of a run: the totals over `tallies` (when more than one), the claims that did
/// not hold, the decisions that contradict a registered claim, what "inconclusive" means, and
/// where the report is (`report`, when plots were written).
pub fn print_totals(tallies: &[Tally], wall_seconds: f64, cpu_seconds: f64, report: Option<&std::path::Path>) {
    print!("{}", totals(tallies, wall_seconds, cpu_seconds, terminal_width()));
    match report {
        Some(index) => println!("HTML report (open in a browser): {}", index.display()),
        None => println!("report: report.md in each experiment's results folder"),
    }
}

/// The text of [`print_totals`] without the report line, each line cut to `width`.
pub fn totals(tallies: &[Tally], wall_seconds: f64, cpu_seconds: f64, width: usize) -> String {
    let mut out = String::new();
    let n = tallies.len();
    let mut all = Tally { experiment: format!("{n} experiment{}", if n == 1 { "" } else { "s" }), ..Tally::default() };
    tallies.iter().for_each(|t| all.add(t));
    let line = format!("{} in {wall_seconds:.1} s ({cpu_seconds:.1} CPU-s): ", all.experiment);
    out.push_str(&format!("\n{}\n", cut(&(line + &all.claims_text() + "; " + &all.tests_text()), width)));
    let list = |out: &mut String, title: &str, lines: Vec<&String>, most: usize, rest: &str| {
        if !lines.is_empty() {
            out.push_str(&format!("{title} ({}):\n", lines.len()));
            for l in lines.iter().take(most) {
                out.push_str(&format!("  {}\n", cut(l, width.saturating_sub(2))));
            }
            if lines.len() > most {
                out.push_str(&format!("  ... and {} more {rest}\n", lines.len() - most));
            }
        }
    };
    let not_held = tallies.iter().flat_map(|t| &t.not_held).collect();
    list(&mut out, "claims that did not hold", not_held, MOST_CLAIMS, "(claims.csv)");
    list(
        &mut out,
        "unbiasedness decisions that contradict the estimator's registered claim",
        tallies.iter().flat_map(|t| &t.contradicting).collect(),
        MOST_CONTRADICTING,
        "(tests.csv: the combined rows with agrees = false and verdict pass or biased)",
    );
    if all.inconclusive > 0 {
        out.push_str(&cut(
            "inconclusive test: the repetitions could neither flag a bias nor rule out one as large as \
             the tolerance (tests.csv: reps_needed says how many would decide)",
            width,
        ));
        out.push('\n');
    }
    if all.claims[2] > 0 {
        out.push_str(&cut(
            "inconclusive claim: the interval does not decide it (claims.csv: reason says what would)",
            width,
        ));
        out.push('\n');
    }
    out
}

/// `text` cut to `width` characters, with an ellipsis when cut.
fn cut(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        return text.to_string();
    }
    let mut s: String = text.chars().take(width.saturating_sub(1)).collect();
    s.push('…');
    s
}

/// A table of `header` and `rows` fitted to `width`: the columns `whole` (ids, numbers) keep
/// their width, the others wrap.
fn table(header: &[&str], rows: Vec<Vec<String>>, whole: &[usize], width: usize) -> String {
    let mut t = Table::new();
    t.load_style(UTF8_FULL_CONDENSED)
        .set_content_arrangement(ContentArrangement::Dynamic)
        .set_width(width.min(u16::MAX as usize) as u16)
        .set_header(header.to_vec());
    for r in rows {
        t.add_row(r);
    }
    for &c in whole {
        if let Some(column) = t.column_mut(c) {
            column.set_constraint(ColumnConstraint::ContentWidth);
        }
    }
    format!("{t}\n")
}

/// The full tables of one experiment's run (`--verbose`): fits with their unbiasedness
/// decisions, the claims, and the skipped pairs counted by reason.
pub fn tables(r: &RunReport, seconds: f64, width: usize) -> String {
    let mut out = format!(
        "\n== {} ({} mode, seed {}, {} reps, {:.1} s) ==\n",
        r.meta.experiment, r.meta.mode, r.meta.seed, r.meta.reps, seconds
    );
    let fits: Vec<Vec<String>> = r
        .fits
        .iter()
        .map(|f| {
            let decision = Query::new(&r.tests)
                .bed((&f.testbed, &f.variant))
                .estimator(&f.estimator)
                .iter()
                .find(|t| t.test == "combined");
            vec![
                format!("{}/{}", f.testbed, f.variant),
                f.estimator.clone(),
                f.describe(crate::analysis::SlopeRange::Whole),
                f.describe(crate::analysis::SlopeRange::Right),
                decision.filter(|t| !t.p_value.is_nan()).map(|t| sig(t.p_value, 3)).unwrap_or_else(|| "-".into()),
                decision.map(|t| format!("{} ({})", t.verdict, t.claim)).unwrap_or_else(|| "-".into()),
            ]
        })
        .collect();
    if !fits.is_empty() {
        let header = ["test bed", "estimator", "slope [95% CI]", "right-end slope", "p", "test (claim)"];
        out.push_str(&table(&header, fits, &[0, 1, 4], width));
    }
    let claims: Vec<Vec<String>> = r
        .paper
        .iter()
        .map(|c| {
            vec![
                c.claim.clone(),
                c.paper_value.map(|v| sig(v, 3)).unwrap_or_default(),
                match (c.our_value, c.interval) {
                    (Some(v), Some([lo, hi])) => format!("{} [{}, {}]", sig(v, 3), sig(lo, 3), sig(hi, 3)),
                    (Some(v), None) => sig(v, 3),
                    (None, _) => "-".into(),
                },
                c.verdict().as_str().into(),
            ]
        })
        .collect();
    if !claims.is_empty() {
        out.push_str(&table(&["paper claim", "paper", "ours", "verdict"], claims, &[1, 3], width));
    }
    if !r.unavailable.is_empty() {
        out.push_str(&format!("not available yet: {}\n", r.unavailable.join(", ")));
    }
    let mut reasons: Vec<(&str, usize)> = Vec::new();
    for s in &r.skipped {
        match reasons.iter_mut().find(|(reason, _)| *reason == s.reason) {
            Some((_, n)) => *n += 1,
            None => reasons.push((&s.reason, 1)),
        }
    }
    for (reason, n) in reasons {
        out.push_str(&cut(&format!("skipped {n} pair{}: {reason}", if n == 1 { "" } else { "s" }), width));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tables_fit_the_width_and_skipped_pairs_are_counted() {
        let mut r = crate::output::plot::tests::synthetic_report();
        r.paper[0].claim = "a long claim ".repeat(20);
        let skip = |estimator: &str| crate::plan::Skipped {
            testbed: "bed".into(),
            variant: "v".into(),
            estimator: estimator.into(),
            reason: "invalid sigma_samp".into(),
        };
        r.skipped = vec![skip("a"), skip("b"), skip("c")];
        for width in [80, 120] {
            let text = tables(&r, 1.0, width);
            let widest = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
            assert!(widest <= width, "width {width}: a line of {widest}\n{text}");
            assert_eq!(text.matches("skipped").count(), 1, "{text}");
            assert!(text.contains("skipped 3 pairs: invalid sigma_samp"), "{text}");
            assert!(text.contains("gradient-plane/default") && text.contains("is1_cv2"), "ids never wrap\n{text}");
        }
    }

    #[test]
    fn totals_list_what_did_not_hold_and_explain_inconclusive() {
        let mut r = crate::output::plot::tests::synthetic_report();
        r.paper[0].verdict = Some(crate::verdict::Verdict::NotHeld);
        r.tests[0].test = "combined".into();
        r.tests[0].verdict = "inconclusive".into();
        let t = Tally::of(&r, 2.0, &Registry::empty());
        let text = totals(&[t.clone(), t], 4.0, 3.5, 80);
        assert!(text.contains("2 experiments in 4.0 s (3.5 CPU-s): claims 2 not held; tests 0 pass"), "{text}");
        let wide = totals(&[Tally::of(&r, 2.0, &Registry::empty())], 2.0, 1.0, 200);
        assert!(wide.contains("(paper -0.940, ours -0.900)"), "{wide}");
        assert!(text.contains("claims that did not hold (2):"), "{text}");
        assert!(text.contains("inconclusive test: "), "{text}");
        assert!(text.lines().all(|l| l.chars().count() <= 80), "{text}");
        let mut many = Tally::of(&r, 1.0, &Registry::empty());
        many.contradicting = (0..9).map(|i| format!("row {i}")).collect();
        let text = totals(&[many], 1.0, 1.0, 200);
        assert!(text.contains("(9):\n  row 0\n") && text.contains("  ... and 4 more (tests.csv"), "{text}");
        assert!(!text.contains("row 5"), "{text}");
        let quiet = totals(&[], 0.0, 0.0, 80);
        assert_eq!(quiet.lines().filter(|l| !l.is_empty()).count(), 1, "nothing to list: one line\n{quiet}");
    }
}
