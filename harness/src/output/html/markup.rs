//! HTML building blocks of the pages: escaping, tables, verdict badges, the page frame with its
//! style sheet and its one script ([`super::explore`]), both inline: a page needs no other file and
//! no network.

use std::fmt::Write as _;

/// `text` with `&`, `<`, `>`, `"` and `'` escaped (for text and attribute values).
pub fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A relative path as an `href`/`src` value: characters that would end or change a URL (`%`,
/// space, `#`, `?`, quotes, brackets) percent-encoded, then escaped.
pub fn url(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for c in path.chars() {
        match c {
            '%' | ' ' | '#' | '?' | '"' | '\'' | '<' | '>' => {
                let mut b = [0u8; 4];
                c.encode_utf8(&mut b).bytes().for_each(|x| {
                    let _ = write!(out, "%{x:02X}");
                });
            }
            c => out.push(c),
        }
    }
    esc(&out)
}

/// The CSS class of a verdict word: `v-` and the word with spaces as dashes (`v-not-held`).
pub fn verdict_class(verdict: &str) -> String {
    let slug: String =
        verdict.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
    format!("v-{slug}")
}

/// A verdict as a coloured badge.
pub fn badge(verdict: &str) -> String {
    format!("<span class=\"badge {}\">{}</span>", verdict_class(verdict), esc(verdict))
}

/// Counts as badges: `3 held`, `1 not held`, ...
pub fn count_badges(counts: &[(String, usize)]) -> String {
    let parts: Vec<String> = counts
        .iter()
        .map(|(w, n)| format!("<span class=\"badge {}\">{n} {}</span>", verdict_class(w), esc(w)))
        .collect();
    if parts.is_empty() {
        "<span class=\"muted\">none</span>".to_string()
    } else {
        parts.join(" ")
    }
}

/// One table cell: its HTML (already escaped) and an optional class (`num` right-aligns).
pub struct Cell {
    html: String,
    class: &'static str,
}

impl Cell {
    /// Plain text (escaped).
    pub fn text(text: &str) -> Cell {
        Cell { html: esc(text), class: "" }
    }
    /// A number (escaped, right-aligned).
    pub fn num(text: &str) -> Cell {
        Cell { html: esc(text), class: "num" }
    }
    /// Markup as given (the caller escaped it).
    pub fn html(html: String) -> Cell {
        Cell { html, class: "" }
    }
}

/// A positive interval whose upper end is more than this many times its lower end is marked wide.
pub const WIDE_FACTOR: f64 = 10.0;

/// Whether `[lo, hi]` is a positive interval spanning more than a factor of [`WIDE_FACTOR`].
pub fn is_wide(lo: f64, hi: f64) -> bool {
    lo > 0.0 && hi > WIDE_FACTOR * lo
}

/// An interval's `text` as a number cell; a wide one ([`is_wide`]) carries a visible mark whose
/// title says why it matters.
pub fn interval_cell(text: &str, bounds: Option<[f64; 2]>) -> Cell {
    match bounds {
        Some([lo, hi]) if is_wide(lo, hi) => Cell {
            html: format!(
                "{} <span class=\"wide\" title=\"a wide interval: its upper end is {} times its lower end (more than \
                 {WIDE_FACTOR}), so this run pins the value down only to within that factor; more repetitions narrow \
                 it\">\u{26a0} wide</span>",
                esc(text),
                crate::output::report::sig(hi / lo, 3)
            ),
            class: "num",
        },
        _ => Cell::num(text),
    }
}

/// A table with a header row; `row_class` gives each row's class (e.g. its verdict's).
pub fn table(header: &[&str], rows: Vec<(String, Vec<Cell>)>) -> String {
    let mut out = String::from("<div class=\"scroll\"><table>\n<thead><tr>");
    for h in header {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for (class, cells) in rows {
        if class.is_empty() {
            out.push_str("<tr>");
        } else {
            let _ = write!(out, "<tr class=\"{}\">", esc(&class));
        }
        for c in cells {
            if c.class.is_empty() {
                let _ = write!(out, "<td>{}</td>", c.html);
            } else {
                let _ = write!(out, "<td class=\"{}\">{}</td>", c.class, c.html);
            }
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table></div>\n");
    out
}

/// A whole page: `title`, the navigation links (`(href, text)`, already relative to the page)
/// and the body.
pub fn page(title: &str, nav: &[(String, String)], body: &str) -> String {
    let mut out = String::with_capacity(body.len() + 4096);
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>\n{STYLE}{}</style>\n</head>\n<body>\n<nav>",
        esc(title),
        super::explore::STYLE
    );
    let links: Vec<String> = nav.iter().map(|(h, t)| format!("<a href=\"{h}\">{}</a>", esc(t))).collect();
    out.push_str(&links.join(" "));
    out.push_str("</nav>\n<main>\n");
    out.push_str(body);
    out.push_str("</main>\n");
    out.push_str(&super::explore::script());
    out.push_str("</body>\n</html>\n");
    out
}

/// The style sheet of every page: system fonts only, verdict colours, compact tables.
const STYLE: &str = r#"body { margin: 0; font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; color: #1d2330; background: #f6f7f9; }
nav { position: sticky; top: 0; z-index: 2; background: #22324a; padding: 6px 16px; }
nav a { color: #dfe8f5; margin-right: 14px; text-decoration: none; font-size: 13px; }
nav a:hover { text-decoration: underline; }
main { max-width: 1280px; margin: 0 auto; padding: 8px 20px 40px; }
h1 { font-size: 24px; margin: 14px 0 6px; }
h2 { font-size: 19px; margin: 26px 0 8px; padding-bottom: 3px; border-bottom: 2px solid #d5dbe5; }
h3 { font-size: 16px; margin: 18px 0 6px; }
a { color: #1f5fa8; }
p { margin: 6px 0; }
.muted { color: #6b7482; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; margin: 6px 0 10px; background: #fff; font-size: 13px; }
th, td { border: 1px solid #d9dee6; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eef1f5; position: sticky; top: 0; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.note { max-width: 520px; color: #3d4553; }
tr.v-held td:first-child, tr.v-pass td:first-child { border-left: 4px solid #3f9b4f; }
tr.v-not-held td:first-child, tr.v-fail td:first-child { border-left: 4px solid #c9353f; }
tr.v-inconclusive td:first-child { border-left: 4px solid #e0a526; }
.badge { display: inline-block; padding: 0 7px; border-radius: 9px; font-size: 12px; white-space: nowrap; background: #e4e7ec; color: #3a4150; }
.v-held, .v-pass { background: #d5eed8; color: #1d5e2a; }
.v-not-held, .v-fail { background: #f8d3d5; color: #86161f; }
.v-biased { background: #f8e1c8; color: #7a3d06; }
.v-inconclusive { background: #fbedc2; color: #6d5200; }
.v-reported { background: #dbe6f6; color: #1f467f; }
.v-not-measured { background: #e4e7ec; color: #4f5766; }
tr[class^="v-"] { background: transparent; color: inherit; }
dl.meta { display: grid; grid-template-columns: max-content 1fr; gap: 2px 14px; background: #fff; border: 1px solid #d9dee6; padding: 8px 12px; }
dl.meta dt { font-weight: 600; }
dl.meta dd { margin: 0; }
.figs { display: grid; grid-template-columns: repeat(auto-fill, minmax(440px, 1fr)); gap: 12px; }
figure { margin: 0; background: #fff; border: 1px solid #d9dee6; padding: 6px; }
figure.wide { grid-column: 1 / -1; }
figure img { width: 100%; height: auto; display: block; }
figcaption { font-size: 12px; color: #4f5766; margin-top: 3px; }
img.thumb { display: block; border: 1px solid #d9dee6; background: #fff; }
img.px { image-rendering: pixelated; border: 1px solid #b9c0cb; display: block; }
.bar { display: inline-block; width: 160px; height: 11px; border: 1px solid #b9c0cb; vertical-align: middle; margin: 0 5px; }
details { margin: 6px 0; }
span.wide { color: #8a4b00; background: #fbe7c6; border-radius: 6px; padding: 0 4px; font-size: 12px; cursor: help; }
div.toc { background: #fff; border: 1px solid #d9dee6; padding: 6px 12px; }
div.toc ol { margin: 4px 0; padding-left: 22px; }
summary { cursor: pointer; color: #1f5fa8; }
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_urls_are_escaped() {
        assert_eq!(esc("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(url("../results/x y/a#b.csv"), "../results/x%20y/a%23b.csv");
        assert_eq!(verdict_class("not held"), "v-not-held");
        assert!(badge("held").contains("class=\"badge v-held\""));
        let t = table(&["a", "b"], vec![("v-held".into(), vec![Cell::text("<x>"), Cell::num("1")])]);
        assert!(t.contains("<tr class=\"v-held\"><td>&lt;x&gt;</td><td class=\"num\">1</td></tr>"), "{t}");
        let p = page("T & t", &[("index.html".into(), "home".into())], "<p>x</p>");
        assert!(p.starts_with("<!DOCTYPE html>") && p.contains("<title>T &amp; t</title>"));
        assert!(!p.contains("http://") && !p.contains("https://"), "no network");
        let wide = table(&["i"], vec![(String::new(), vec![interval_cell("[3.58, 116]", Some([3.58, 116.0]))])]);
        assert!(
            wide.contains("[3.58, 116] <span class=\"wide\" title=\"a wide interval") && wide.contains("\u{26a0} wide")
        );
        for (lo, hi) in [(1.0, 2.0), (1.0, 10.0), (-3.0, 116.0), (0.0, 5.0)] {
            let t = table(&["i"], vec![(String::new(), vec![interval_cell("x", Some([lo, hi]))])]);
            assert!(!t.contains("wide"), "[{lo}, {hi}] is not marked: {t}");
        }
        assert!(is_wide(1.0, f64::INFINITY) && !is_wide(f64::NAN, 5.0));
        let script = format!("<script id=\"{}\">", super::super::explore::SCRIPT_ID);
        assert_eq!(p.matches(&script).count(), 1, "the table script once");
        assert!(p.find(&script) > p.find("</main>"), "after the tables it works on");
    }
}
