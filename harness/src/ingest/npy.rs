//! NumPy `.npy` images: little-endian float32 or float64, C order, shape `(H, W)`, `(H, W, 1)` or
//! `(H, W, 3)`. Anything else (another dtype, Fortran order, a truncated body) is refused with the
//! reason.

use super::image::Image;

/// Parses the bytes of a `.npy` file into an image; `Err` says what is wrong.
pub fn parse(bytes: &[u8]) -> Result<Image, String> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err("not a NumPy .npy file (no \\x93NUMPY magic)".into());
    }
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(format!("unsupported .npy version {v}")),
    };
    let header = bytes.get(start..start.saturating_add(header_len)).ok_or("truncated .npy header")?;
    let header = std::str::from_utf8(header).map_err(|_| "the .npy header is not text")?;
    let descr = value_of(header, "descr").ok_or("the .npy header has no `descr`")?;
    let width = match descr.trim_matches(|c| c == '\'' || c == '"') {
        "<f4" => 4,
        "<f8" => 8,
        d => return Err(format!("dtype {d}: only little-endian float32 (<f4) or float64 (<f8)")),
    };
    if value_of(header, "fortran_order").map(str::trim) != Some("False") {
        return Err("only C-order arrays (fortran_order False)".into());
    }
    let shape_text = header
        .split_once("'shape':")
        .and_then(|(_, rest)| rest.split_once('(').and_then(|(_, r)| r.split_once(')')).map(|(s, _)| s))
        .ok_or("the .npy header has no `shape`")?;
    let shape: Vec<usize> = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>().map_err(|_| format!("shape ({shape_text}) is not a list of sizes")))
        .collect::<Result<_, _>>()?;
    let (h, w, channels) = match shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] if c == 1 || c == 3 => (h, w, c),
        _ => return Err(format!("shape ({shape_text}): an image is (H, W), (H, W, 1) or (H, W, 3)")),
    };
    if h == 0 || w == 0 {
        return Err(format!("shape ({shape_text}) is empty"));
    }
    let count = h.checked_mul(w).and_then(|n| n.checked_mul(channels)).ok_or("shape too large")?;
    let body = &bytes[start + header_len..];
    if body.len() != count * width {
        return Err(format!(
            "truncated or padded: shape ({shape_text}) of {width}-byte floats needs {} bytes of data, the file has {}",
            count * width,
            body.len()
        ));
    }
    let values: Vec<f64> = if width == 4 {
        body.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64).collect()
    } else {
        body.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect()
    };
    Ok(Image::from_channels(w, h, channels, values))
}

/// The text after `'key':` in a header dict, up to the next `,` (not inside the shape's
/// parentheses, which only `shape` has).
fn value_of<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let (_, rest) = header.split_once(&format!("'{key}':"))?;
    Some(rest.split([',', '}']).next()?.trim())
}

/// The bytes of a float64 `.npy` file of shape `(h, w)` or `(h, w, c)` (tests and examples).
pub fn encode_f64(h: usize, w: usize, channels: usize, values: &[f64]) -> Vec<u8> {
    let shape = if channels == 1 { format!("({h}, {w})") } else { format!("({h}, {w}, {channels})") };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((header.len() as u16).to_le_bytes());
    out.extend(header.as_bytes());
    for v in values {
        out.extend(v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_grey_and_colour() {
        let grey = parse(&encode_f64(2, 3, 1, &[0., 1., 2., 3., 4., 5.])).unwrap();
        assert_eq!((grey.width, grey.height), (3, 2));
        assert_eq!(grey.pixels[4].0, [4.0; 3], "row 1, column 1 is value 4, every channel");
        let rgb: Vec<f64> = (0..12).map(f64::from).collect();
        let colour = parse(&encode_f64(2, 2, 3, &rgb)).unwrap();
        assert_eq!(colour.pixels[1].0, [3.0, 4.0, 5.0]);
    }

    #[test]
    fn truncated_wrong_dtype_and_shape_are_refused() {
        let good = encode_f64(2, 2, 1, &[1.0; 4]);
        assert!(parse(&good[..good.len() - 3]).unwrap_err().contains("truncated"));
        let mut ints = good.clone();
        let at = ints.windows(3).position(|w| w == b"<f8").expect("a dtype");
        ints[at + 1] = b'i';
        assert!(parse(&ints).unwrap_err().contains("dtype"));
        let four = encode_f64(1, 1, 4, &[1.0; 4]);
        assert!(parse(&four).unwrap_err().contains("shape"));
        assert!(parse(b"P6 not numpy").unwrap_err().contains("magic"));
    }
}
