//! Log axes: the range of the data, and the labelled ticks chosen for the axis's length in pixels:
//! powers of ten (every few decades when even they would touch), then as many of 2 and 5, 3, and
//! the other mantissas as fit without touching, with labels like `2e-7`, `0.01`, `10`, `5e5`.

use std::ops::Range;

/// Mantissas added after the powers of ten, in order of preference, each group in every decade
/// or in none.
const PREFERENCE: [&[f64]; 7] = [&[2.0, 5.0], &[3.0], &[4.0], &[6.0], &[7.0], &[8.0], &[9.0]];
/// At most this many labels on an axis.
const MAX_LABELS: usize = 10;

/// Approximate width in pixels of a tick label of `chars` characters at the tick font size.
pub(super) fn label_width(chars: usize) -> f64 {
    7.4 * chars as f64 + 2.0
}

/// Height in pixels a tick label needs on a vertical axis.
const LABEL_HEIGHT: f64 = 16.0;

/// A log range over the positive finite values, padded by a tenth of a decade each side and at
/// least 0.6 decades wide (a single point or a flat series still gets a readable axis).
pub(super) fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return 1.0..10.0;
    }
    let (lo, hi) = (lo.log10() - 0.1, hi.log10() + 0.1);
    let grow = (0.6 - (hi - lo)).max(0.0) / 2.0;
    10f64.powf(lo - grow)..10f64.powf(hi + grow)
}

/// The values `m x 10^k` of `mantissas` in `range`, for every `step`-th decade.
fn candidates(range: &Range<f64>, mantissas: &[f64], step: i32) -> Vec<f64> {
    let (lo, hi) = (range.start, range.end);
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (k0..=k1)
        .filter(|k| k.rem_euclid(step) == 0)
        .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
        .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
        .collect()
}

/// Whether labels at `ticks` (sorted) fit an axis of `pixels` over `range` without touching:
/// horizontally (`vertical` false) by their widths, vertically by the label height.
fn fits(range: &Range<f64>, ticks: &[f64], pixels: f64, vertical: bool) -> bool {
    let span = (range.end / range.start).log10();
    let at = |v: f64| (v / range.start).log10() / span * pixels;
    ticks.windows(2).all(|w| {
        let need = if vertical {
            LABEL_HEIGHT + 4.0
        } else {
            (label_width(tick(w[0]).chars().count()) + label_width(tick(w[1]).chars().count())) / 2.0 + 10.0
        };
        at(w[1]) - at(w[0]) >= need
    })
}

/// Labelled and grid-only ticks of a log axis `pixels` long. Labels: the powers of ten, or every
/// `k`-th power when they would touch; then the 2s and 5s, the 3s, the 4s, ... of every decade,
/// each group when it fits beside those already placed (at most [`MAX_LABELS`] labels); the two
/// outermost when that leaves fewer than two. Grid lines at every integer mantissa over ranges up to six decades, at powers
/// of ten beyond.
pub(super) fn log_ticks(range: &Range<f64>, pixels: f64, vertical: bool) -> (Vec<f64>, Vec<f64>) {
    let span = (range.end / range.start).log10();
    let mut bold = (1..=12)
        .map(|step| candidates(range, &[1.0], step))
        .find(|t| t.len() <= MAX_LABELS && fits(range, t, pixels, vertical))
        .unwrap_or_default();
    let decades = bold.len() > 1 && fits(range, &candidates(range, &[1.0], 1), pixels, vertical);
    if decades || bold.len() < 2 {
        for group in PREFERENCE {
            let mut with = bold.clone();
            with.extend(candidates(range, group, 1));
            with.sort_by(f64::total_cmp);
            if with.len() <= MAX_LABELS && fits(range, &with, pixels, vertical) {
                bold = with;
            }
        }
    }
    let all = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
    if bold.len() < 2 {
        // Nothing fits (a very short axis): the two outermost powers of ten, or mantissas.
        let ends = |t: Vec<f64>| (t.len() >= 2).then(|| vec![t[0], t[t.len() - 1]]);
        bold = ends(candidates(range, &[1.0], 1)).or_else(|| ends(candidates(range, &all, 1))).unwrap_or_default();
    }
    let light = if span <= 6.0 { candidates(range, &all, 1) } else { candidates(range, &[1.0], 1) };
    let light = light.into_iter().filter(|v| !bold.iter().any(|b| (b / v - 1.0).abs() < 1e-9)).collect();
    (bold, light)
}

/// Tick label of `m x 10^e` (m an integer 1..9): plain for 0.01 to 99999 (`0.02`, `5`, `300`),
/// `me±e` otherwise (`2e-7`, `1e-3`, `5e5`).
pub(super) fn tick(v: f64) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let e = (v.log10() + 1e-9).floor() as i32;
    let m = v / 10f64.powi(e);
    if (m - m.round()).abs() > 1e-6 * m {
        return format!("{v:.2e}");
    }
    let m = m.round();
    match e {
        0..=4 => format!("{}", m as i64 * 10i64.pow(e as u32)),
        -2..=-1 => format!("{:.*}", (-e) as usize, m * 10f64.powi(e)),
        _ => format!("{m}e{e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(lo: f64, hi: f64, px: f64, vertical: bool) -> Vec<String> {
        log_ticks(&(lo..hi), px, vertical).0.into_iter().map(tick).collect()
    }

    #[test]
    fn log_axes_always_have_labelled_ticks() {
        for (lo, hi) in [(0.3, 0.8), (4.0, 16384.0), (5.0, 5.0), (1e-9, 2e-9), (0.0, f64::NAN), (1e-30, 1e30)] {
            let r = log_range([lo, hi].into_iter());
            assert!(r.start > 0.0 && r.end > r.start, "{r:?}");
            for (px, vertical) in [(560.0, false), (330.0, true), (150.0, false)] {
                let (bold, light) = log_ticks(&r, px, vertical);
                assert!(bold.len() >= 2 && bold.len() <= MAX_LABELS, "{r:?} {px}: {bold:?}");
                assert!(bold.iter().chain(&light).all(|v| *v >= r.start * 0.999 && *v <= r.end * 1.001), "{r:?}");
            }
        }
    }

    #[test]
    fn time_axes_get_several_labels_that_do_not_overlap() {
        // A CPU-time axis over 2.4 decades on a panel: more than the two powers of ten.
        let r = log_range([3e-7, 7e-5].into_iter());
        let l = labels(r.start, r.end, 560.0, false);
        assert!(l.len() >= 4, "{l:?}");
        assert!(fits(&r, &log_ticks(&r, 560.0, false).0, 560.0, false));
        assert_eq!(labels(0.5, 30.0, 560.0, false), ["0.5", "1", "2", "3", "4", "5", "10", "20", "30"]);
        // The frames of a sequence: every one labelled.
        assert_eq!(labels(0.8, 7.5, 600.0, false), ["0.8", "1", "2", "3", "4", "5", "6", "7"]);
        assert_eq!(labels(3.0, 20000.0, 560.0, false), ["3", "10", "30", "100", "300", "1000", "3000", "10000"]);
        // Narrow vertical axes fall back to fewer labels, wide ranges to every few decades.
        assert_eq!(labels(1e-6, 1e2, 330.0, true).len(), 9);
        assert!(labels(1e-30, 1e30, 330.0, true).len() <= 12);
    }

    #[test]
    fn ticks_are_readable() {
        assert_eq!(tick(100.0), "100");
        assert_eq!(tick(0.02), "0.02");
        assert_eq!(tick(3.0 * 0.1), "0.3");
        assert_eq!(tick(1e-3), "1e-3");
        assert_eq!(tick(5e-7), "5e-7");
        assert_eq!(tick(2e7), "2e7");
        assert_eq!(tick(f64::NAN), "");
    }
}
