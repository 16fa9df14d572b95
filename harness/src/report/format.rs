//! Formatting shared by the run's summaries: numbers with significant digits, markdown tables,
//! shortened text, and paths relative to the folder a page is in.

use std::path::{Component, Path, PathBuf};

/// Formats `x` with `digits` significant digits: fixed notation for magnitudes in
/// [1e-3, 10^(digits + 1)), scientific (`1.235e-5`) otherwise; `-` for NaN, `inf` / `-inf`.
pub fn sig(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "-".to_string();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let d = digits.max(1);
    let sci = format!("{:.*e}", d - 1, x);
    let exp: i32 = sci.rsplit('e').next().and_then(|e| e.parse().ok()).unwrap_or(0);
    if exp < -3 || exp > d as i32 {
        sci
    } else {
        format!("{:.*}", (d as i32 - 1 - exp).max(0) as usize, x)
    }
}

/// `sig(x, 4)` for a present value, `-` for a missing one.
pub fn opt(x: Option<f64>) -> String {
    x.map(|v| sig(v, 4)).unwrap_or_else(|| "-".to_string())
}

/// A cost: whole numbers as integers, others with 4 significant digits.
pub fn count(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e12 {
        format!("{}", x as i64)
    } else {
        sig(x, 4)
    }
}

/// A 95% interval as `[lo, hi]` (4 significant digits), empty without one.
pub fn interval(i: Option<[f64; 2]>) -> String {
    i.map(|[lo, hi]| format!("[{}, {}]", sig(lo, 4), sig(hi, 4))).unwrap_or_default()
}

/// `text` cut to at most `max` characters (an ellipsis marks the cut).
pub fn shorten(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        text.to_string()
    } else {
        let mut s: String = text.chars().take(max.saturating_sub(1)).collect();
        s.push('…');
        s
    }
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// A GitHub-flavoured markdown table with padded columns (readable as plain text too). Rows
/// shorter than the header are padded with empty cells; `|` in cells is escaped.
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let ncol = header.len().max(rows.iter().map(Vec::len).max().unwrap_or(0));
    let grid: Vec<Vec<String>> = std::iter::once(header.iter().map(|h| cell(h)).collect::<Vec<_>>())
        .chain(rows.iter().map(|r| r.iter().map(|c| cell(c)).collect()))
        .map(|mut r| {
            r.resize(ncol, String::new());
            r
        })
        .collect();
    let widths: Vec<usize> =
        (0..ncol).map(|c| grid.iter().map(|r| r[c].chars().count()).max().unwrap_or(0).max(3)).collect();
    let line = |r: &[String]| {
        let cells: Vec<String> =
            r.iter().zip(&widths).map(|(c, w)| format!("{c}{}", " ".repeat(w - c.chars().count()))).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    let mut out = line(&grid[0]);
    out.push_str(&format!("|{}|\n", widths.iter().map(|w| "-".repeat(w + 2)).collect::<Vec<_>>().join("|")));
    for r in &grid[1..] {
        out.push_str(&line(r));
    }
    out
}

/// `to` relative to the folder `from`, with `/` separators.
pub fn relative_path(from: &Path, to: &Path) -> String {
    let rel = match to.strip_prefix(from) {
        Ok(r) => r.to_path_buf(),
        Err(_) => {
            let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
            let (f, t) = (abs(from), abs(to));
            let (fc, tc): (Vec<Component>, Vec<Component>) = (f.components().collect(), t.components().collect());
            let common = fc.iter().zip(&tc).take_while(|(a, b)| a == b).count();
            let mut r = PathBuf::new();
            (common..fc.len()).for_each(|_| r.push(".."));
            tc[common..].iter().for_each(|c| r.push(c));
            r
        }
    };
    rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect::<Vec<_>>().join("/")
}

/// [`relative_path`] as a markdown link target (in `<>` when it holds a space or bracket).
pub fn md_target(from: &Path, to: &Path) -> String {
    let s = relative_path(from, to);
    if s.contains([' ', '(', ')', '<', '>']) {
        format!("<{s}>")
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sig_formats() {
        assert_eq!(sig(0.012345678, 4), "0.01235");
        assert_eq!(sig(1.23456e-5, 4), "1.235e-5");
        assert_eq!(sig(9.99996, 4), "10.00");
        assert_eq!(sig(12345.0, 4), "12345");
        assert_eq!(sig(1.5e8, 4), "1.500e8");
        assert_eq!(sig(-2.0, 3), "-2.00");
        assert_eq!(sig(0.0, 4), "0");
        assert_eq!(sig(f64::NAN, 4), "-");
    }

    #[test]
    fn tables_are_aligned_and_escaped() {
        let t = markdown_table(&["a", "long header"], &[vec!["x|y".into()], vec!["1".into(), "2".into()]]);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 4);
        assert!(lines.iter().all(|l| l.chars().count() == lines[0].chars().count()), "{t}");
        assert!(t.contains("x\\|y"));
        assert!(lines[1].starts_with("|---"));
    }

    #[test]
    fn paths_are_relative_to_the_page_and_text_is_shortened() {
        assert_eq!(relative_path(Path::new("/a/plots/x"), Path::new("/a/results/x/s.csv")), "../../results/x/s.csv");
        assert_eq!(relative_path(Path::new("/a/p"), Path::new("/a/p/f.svg")), "f.svg");
        assert_eq!(md_target(Path::new("/a"), Path::new("/a/b c.csv")), "<b c.csv>");
        assert_eq!(shorten("abcdef", 4), "abc…");
        assert_eq!(shorten("abc", 4), "abc");
        assert_eq!(interval(Some([1.0, 2.5])), "[1.000, 2.500]");
    }
}
