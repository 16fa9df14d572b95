//! The two-sample test in the comparison's page (a section with one row per shared cell) and on
//! the console (one line per verdict).

use super::two_sample::{TwoSample, TwoSampleVerdict, ALPHA, SAME_WITHIN};
use crate::output::html::markup::{self, esc, Cell};
use crate::output::report::sig;

const HEADER: [&str; 11] = [
    "test bed",
    "budget",
    "reps A / B",
    "integrals",
    "relative difference",
    "detectable",
    "p (sums)",
    "p (Holm)",
    "pooled p",
    "verdict",
    "p histogram (10 bins)",
];

fn badge(v: TwoSampleVerdict) -> String {
    let word = match v {
        TwoSampleVerdict::Same => "pass",
        TwoSampleVerdict::Differ => "biased",
        TwoSampleVerdict::Inconclusive => "inconclusive",
    };
    format!("<span class=\"badge {}\">{}</span>", markup::verdict_class(word), esc(v.word()))
}

/// The section of `compare.html` (empty without a two-sample test).
pub fn section(t: Option<&TwoSample>) -> String {
    let Some(t) = t else { return String::new() };
    let num = |x: f64| if x.is_nan() { String::new() } else { sig(x, 3) };
    let rows: Vec<(String, Vec<Cell>)> = t
        .rows
        .iter()
        .map(|r| {
            let hist: Vec<String> = r.p_histogram.iter().map(u64::to_string).collect();
            (
                markup::verdict_class(r.verdict.word()),
                vec![
                    Cell::text(&format!("{}/{}", r.testbed, r.variant)),
                    Cell::num(&format!("{} {}", r.budget, r.budget_kind)),
                    Cell::num(&format!("{} / {}", r.reps_a, r.reps_b)),
                    Cell::num(&r.integrals.to_string()),
                    Cell::num(&num(r.rel_diff)),
                    Cell::num(&num(r.detectable_rel_diff)),
                    Cell::num(&num(r.p_sum)),
                    Cell::num(&num(r.p_holm)),
                    Cell::num(&num(r.pooled_p)),
                    Cell::html(badge(r.verdict)),
                    Cell::text(&hist.join(" ")),
                ],
            )
        })
        .collect();
    format!(
        "<h2>{} (A) against {} (B), without a reference</h2>\n<p>Per integral and channel a Welch test of the two means; \
         pooled: the Welch test of the per-repetition sums (80% of the level) and Holm over the integrals (20%). \
         Differ: pooled p below {ALPHA}; same: not, and a relative difference of {} of the sums would be found with 80% power; \
         otherwise inconclusive. Per-integral p-values: two_sample_integrals.csv; 8 x 8 tiles: two_sample_tiles.csv.</p>\n{}{}",
        esc(&t.estimator_a),
        esc(&t.estimator_b),
        sig(SAME_WITHIN, 2),
        markup::table(&HEADER, rows),
        maps(t)
    )
}

/// The per-pixel maps of the rows whose integrals are pixels: A's mean against B's, the z being
/// the Welch t of each pixel.
fn maps(t: &TwoSample) -> String {
    let mut out = String::new();
    for (k, g) in super::two_sample_maps::maps(t) {
        let r = &t.rows[k];
        let label = |e: &str| format!("{e}, {}/{}, budget {}", r.testbed, r.variant, r.budget);
        if let Ok(html) = crate::output::html::pixel_maps::render(&g, &label) {
            out.push_str(&format!(
                "<h3>{}/{} at {} {}: per pixel, A against B</h3>\n<p class=\"muted\">Below, \"mean\" is A's mean and \"reference\" B's mean with its standard error: z is the Welch t of the pixel, the relative error |A - B| / |B|.</p>\n{html}",
                esc(&r.testbed),
                esc(&r.variant),
                r.budget,
                esc(&r.budget_kind)
            ));
        }
    }
    out
}

/// The console lines: one per verdict with its count.
pub fn console(t: &TwoSample) -> String {
    let count = |v: TwoSampleVerdict| t.rows.iter().filter(|r| r.verdict == v).count();
    format!(
        "two-sample {} (A) vs {} (B): {} cells: {} same, {} differ, {} inconclusive\n",
        t.estimator_a,
        t.estimator_b,
        t.rows.len(),
        count(TwoSampleVerdict::Same),
        count(TwoSampleVerdict::Differ),
        count(TwoSampleVerdict::Inconclusive)
    )
}
