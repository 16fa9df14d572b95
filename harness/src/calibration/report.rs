//! `calibration.md` and the experiment's claims, from the table's rows ([`super::table`]).

use super::size;
use super::table::{frac, wilson, Row, MIN_POWER, SIZE_BAND};
use crate::output::Claim;

fn pct(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{:.1}", 100.0 * x)
    }
}

fn mark(x: Option<bool>) -> &'static str {
    match x {
        Some(true) => "yes",
        Some(false) => "NO",
        None => "-",
    }
}

/// `calibration.md`: the table with the checks (names escaped, [`md_text`](crate::output::report::md_text)).
pub fn markdown(rows: &[Row], header: &str) -> String {
    use crate::output::report::md_text;
    let mut s = format!("# calibration\n\n{}\n\n", md_text(header));
    s.push_str("| test bed | estimator | claim | reps | seeds | tested % | false flags % at 5% [95% CI] | flagged % | pass % | power 1% | power 1% on pass | power 3% | detectable % | measured 80% point % | firefly bias % / flagged % | p below alpha / 1% / 5% of seeds (planted below alpha) | checks | note |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let checks = format!(
            "size at alpha {} (planted {}) / size 5% {} / detectable {} / power {} / control {}",
            mark(r.ok_size),
            mark(r.planted_ok_size),
            mark(r.ok_false_flag),
            mark(r.ok_detectable),
            mark(r.ok_power),
            mark(r.ok_control)
        );
        s.push_str(&format!(
            "| {}/{} | {} | {} | {} | {} | {} | {} [{}, {}] | {} | {} | {} | {} | {} | {} | {} | {} / {} | {} | {} | {} |\n",
            md_text(&r.testbed),
            md_text(&r.variant),
            md_text(&r.estimator),
            md_text(&r.claim),
            r.reps,
            r.seeds,
            pct(r.tested_fraction),
            pct(r.false_flag_rate),
            pct(r.false_flag_lo),
            pct(r.false_flag_hi),
            pct(r.flag_rate),
            pct(r.pass_rate),
            pct(r.power_1pct),
            pct(r.power_1pct_on_pass),
            pct(r.power_3pct),
            pct(r.detectable),
            pct(r.measured_80),
            pct(r.firefly_rel_bias),
            pct(r.firefly_flag_rate),
            if r.size_seeds == 0 {
                "-".to_string()
            } else {
                format!(
                    "{} / {} / {} of {} ({})",
                    r.below_alpha, r.below_1pct, r.below_5pct, r.size_seeds, r.planted_below_alpha
                )
            },
            checks,
            md_text(&r.note)
        ));
    }
    s
}

/// The pooled checks over every family they apply to: the false-flag rate over all tested seeds
/// of unbiased families (point estimate inside [`SIZE_BAND`]) and the power at 1% over all passing
/// seeds (point estimate at least [`MIN_POWER`]).
fn pooled_claims(rows: &[Row]) -> Vec<Claim> {
    let count = |x: f64, n: f64| (x * n).round() as usize;
    let (mut ff, mut tested, mut flagged, mut passing) = (0, 0, 0, 0);
    for r in rows.iter().filter(|r| r.claim == "unbiased") {
        let t = count(r.tested_fraction, r.seeds as f64);
        if r.ok_false_flag.is_some() {
            ff += count(r.false_flag_rate, t as f64);
            tested += t;
        }
        let p = count(r.pass_rate, r.seeds as f64);
        if p > 0 {
            flagged += count(r.power_1pct_on_pass, p as f64);
            passing += p;
        }
    }
    let claim = |text: &str, k: usize, n: usize, held: bool, what: &str| {
        let (lo, hi) = wilson(k, n);
        Claim {
            testbed: "all".into(),
            claim: format!("harness: {text}"),
            paper_value: None,
            our_value: (n > 0).then(|| k as f64 / n as f64),
            held: (n > 0).then_some(held),
            note: format!("{k} of {n} {what}: {:.1}% [{:.1}, {:.1}]", 100.0 * frac(k, n), 100.0 * lo, 100.0 * hi),
            ..Default::default()
        }
    };
    let rate = frac(ff, tested);
    vec![
        claim(
            "false-flag rate pooled over the unbiased families within 1.5x of the nominal 5%",
            ff,
            tested,
            (SIZE_BAND.0..=SIZE_BAND.1).contains(&rate),
            "tested seeds flagged",
        ),
        claim(
            "a 1% bias flagged in at least 80% of all passing seeds",
            flagged,
            passing,
            frac(flagged, passing) >= MIN_POWER,
            "passing seeds flag +1%",
        ),
    ]
}

/// The claims: one per check over every family it applies to, and the pooled checks.
pub fn claims(rows: &[Row]) -> Vec<Claim> {
    type Check = fn(&Row) -> Option<bool>;
    let checks: [(&str, Check); 4] = [
        (
            "false-flag rate consistent with 1.5x of the nominal 5% on every unbiased family whose pooled test runs",
            |r| r.ok_false_flag,
        ),
        ("reported detectable bias within 25% of the measured 80% point on every resolved family", |r| r.ok_detectable),
        ("a 1% bias flagged in at least 80% of the seeds of every row that passes at 1% (within its interval)", |r| {
            r.ok_power
        }),
        ("every control flagged in at least 99% of seeds", |r| r.ok_control),
    ];
    checks
        .iter()
        .map(|(text, check)| {
            let judged: Vec<&Row> = rows.iter().filter(|r| check(r).is_some()).collect();
            let failed: Vec<String> = judged
                .iter()
                .filter(|r| check(r) == Some(false))
                .map(|r| format!("{} on {}/{}", r.estimator, r.testbed, r.variant))
                .collect();
            Claim {
                testbed: "all".into(),
                claim: format!("harness: {text}"),
                paper_value: None,
                our_value: Some((judged.len() - failed.len()) as f64),
                held: (!judged.is_empty()).then_some(failed.is_empty()),
                note: if judged.is_empty() {
                    "no family this check applies to".into()
                } else if failed.is_empty() {
                    format!("holds on all {} families it applies to", judged.len())
                } else {
                    format!("fails on {} of {}: {}", failed.len(), judged.len(), failed.join(", "))
                },
                ..Default::default()
            }
        })
        .chain(pooled_claims(rows))
        .chain(size::claims(rows))
        .collect()
}
