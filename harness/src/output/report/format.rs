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

/// Text from outside the harness's own words (a claim, a label, a note, a name read from a config,
/// a registry entry or a stored file) made safe to put in markdown, in a table cell or in prose:
/// `&`, `<` and `>` become character references, so no HTML tag reaches a viewer; `|` and `\` are
/// backslash-escaped, so a table cell cannot be split; line breaks become spaces. Backticks are
/// kept, so an id in backticks stays code.
pub fn md_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '|' => out.push_str("\\|"),
            '\\' => out.push_str("\\\\"),
            '\n' | '\r' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// The non-empty `parts` joined by `"; "` (a note made of optional pieces).
pub fn join_present(parts: &[&str]) -> String {
    parts.iter().filter(|s| !s.is_empty()).copied().collect::<Vec<_>>().join("; ")
}

/// A GitHub-flavoured markdown table with padded columns (readable as plain text too). Rows
/// shorter than the header are padded with empty cells; every cell is escaped ([`md_text`]).
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let ncol = header.len().max(rows.iter().map(Vec::len).max().unwrap_or(0));
    let grid: Vec<Vec<String>> = std::iter::once(header.iter().map(|h| md_text(h)).collect::<Vec<_>>())
        .chain(rows.iter().map(|r| r.iter().map(|c| md_text(c)).collect()))
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

/// [`relative_path`] as a markdown link target: `%`, `<` and `>` percent-encoded (a file name
/// cannot open an HTML tag), in `<>` when it holds a space or bracket.
pub fn md_target(from: &Path, to: &Path) -> String {
    let s = relative_path(from, to).replace('%', "%25").replace('<', "%3C").replace('>', "%3E");
    if s.contains([' ', '(', ')']) {
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
    fn text_is_escaped_for_markdown_and_ids_stay_readable() {
        let raw = "<script>alert(1)</script> & <img src=x onerror=alert(1)> a|b c\\|d\nnext `is0_cv0`";
        let safe = md_text(raw);
        assert_eq!(
            safe,
            "&lt;script&gt;alert(1)&lt;/script&gt; &amp; &lt;img src=x onerror=alert(1)&gt; a\\|b c\\\\\\|d next `is0_cv0`"
        );
        let t = markdown_table(&["claim"], &[vec![raw.to_string()]]);
        assert!(!t.contains('<') && !t.contains('>') && t.lines().count() == 3, "{t}");
        assert_eq!(
            md_text("spm_adaptive[sigma_samp=0.8] on eq21-medium/multiple"),
            "spm_adaptive[sigma_samp=0.8] on eq21-medium/multiple"
        );
        assert_eq!(md_target(Path::new("/a"), Path::new("/a/<img src=x>.svg")), "<%3Cimg src=x%3E.svg>");
        assert_eq!(md_target(Path::new("/a"), Path::new("/a/50%.csv")), "50%25.csv");
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
