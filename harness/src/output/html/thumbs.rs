//! The thumbnails of the plots root's index: an experiment's first figure (the PNG when there is
//! one, else the SVG) shrunk to [`THUMB_WIDTH`] pixels, its height set from the image's own size so
//! the page does not reflow while images load, linking to the experiment's page.

use super::markup::{esc, url};
use crate::output::report::digest;
use std::io::Read as _;
use std::path::Path;

/// The width in CSS pixels of a thumbnail.
pub const THUMB_WIDTH: u32 = 160;

/// The width and height a PNG file declares in its header.
fn png_size(path: &Path) -> Option<(u32, u32)> {
    let mut head = [0u8; 24];
    std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head)).ok()?;
    if &head[..8] != b"\x89PNG\r\n\x1a\n" || &head[12..16] != b"IHDR" {
        return None;
    }
    let be = |i: usize| u32::from_be_bytes([head[i], head[i + 1], head[i + 2], head[i + 3]]);
    Some((be(16), be(20)))
}

/// The width and height an SVG file declares on its root element (in its first 512 bytes).
fn svg_size(path: &Path) -> Option<(u32, u32)> {
    let mut head = [0u8; 512];
    let n = std::fs::File::open(path).and_then(|mut f| f.read(&mut head)).ok()?;
    let text = String::from_utf8_lossy(&head[..n]);
    let svg = &text[text.find("<svg")?..];
    let attr = |name: &str| -> Option<u32> {
        let v = svg[svg.find(&format!(" {name}=\""))? + name.len() + 3..].split('"').next()?;
        v.trim_end_matches("px").parse::<f64>().ok().filter(|x| *x >= 1.0).map(|x| x.round() as u32)
    };
    Some((attr("width")?, attr("height")?))
}

/// The thumbnail of the experiment folder `name` under `root` linking to `page` (relative to the
/// root), or `None` when the folder has no figure whose size can be read.
pub fn thumbnail(root: &Path, name: &str, page: &str) -> Option<String> {
    let dir = root.join(name);
    let first = digest::figures_in(&dir).into_iter().next()?;
    let (file, (w, h)) = match (&first.png, &first.svg) {
        (Some(p), _) if png_size(p).is_some() => (p.clone(), png_size(p)?),
        (_, Some(s)) => (s.clone(), svg_size(s)?),
        _ => return None,
    };
    let height = ((THUMB_WIDTH as f64) * h as f64 / w.max(1) as f64).round().max(1.0) as u32;
    let src = format!("{name}/{}", file.file_name()?.to_str()?);
    Some(format!(
        "<a href=\"{}\"><img class=\"thumb\" src=\"{}\" width=\"{THUMB_WIDTH}\" height=\"{height}\" alt=\"{}\" \
         loading=\"lazy\"></a>",
        url(page),
        url(&src),
        esc(&first.stem)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_figure_is_shown_at_its_own_aspect_ratio() {
        let dir = tempfile::tempdir().expect("tempdir");
        let exp = dir.path().join("exp a");
        std::fs::create_dir_all(&exp).expect("folder");
        assert_eq!(thumbnail(dir.path(), "exp a", "exp a/index.html"), None, "no figure, no thumbnail");
        std::fs::write(exp.join("b_second.svg"), "<svg width=\"100\" height=\"100\">").expect("svg");
        std::fs::write(exp.join("a_first.svg"), "<svg width=\"1400px\" height=\"700\" viewBox=\"0 0 1400 700\">")
            .expect("svg");
        let t = thumbnail(dir.path(), "exp a", "exp a/index.html").expect("thumbnail");
        assert!(t.contains("src=\"exp%20a/a_first.svg\" width=\"160\" height=\"80\""), "{t}");
        assert!(t.starts_with("<a href=\"exp%20a/index.html\">"), "{t}");
        let png = crate::output::html::png::Rgb8::filled(300, 100, [1, 2, 3]).png().expect("png");
        std::fs::write(exp.join("a_first.png"), png).expect("png");
        let t = thumbnail(dir.path(), "exp a", "exp a/index.html").expect("thumbnail");
        assert!(t.contains("src=\"exp%20a/a_first.png\" width=\"160\" height=\"53\""), "the PNG first: {t}");
    }
}
