//! Small RGB images as PNG `data:` URIs, so a page carries its per-pixel maps inline (no extra
//! files, no network).

use crate::error::{HarnessError, Result};

/// An RGB image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgb8 {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width x height x 3` bytes.
    pub data: Vec<u8>,
}

impl Rgb8 {
    /// A `width x height` image of one colour.
    pub fn filled(width: usize, height: usize, rgb: [u8; 3]) -> Rgb8 {
        Rgb8 { width, height, data: rgb.repeat(width * height) }
    }

    /// Sets pixel (`x`, `y`).
    pub fn set(&mut self, x: usize, y: usize, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.data[i..i + 3].copy_from_slice(&rgb);
        }
    }

    /// The image as PNG bytes.
    pub fn png(&self) -> Result<Vec<u8>> {
        let err = |e: png::EncodingError| HarnessError::write("a per-pixel map", e);
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, self.width as u32, self.height as u32);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().map_err(err)?;
            w.write_image_data(&self.data).map_err(err)?;
        }
        Ok(bytes)
    }

    /// The image as a `data:image/png;base64,...` URI.
    pub fn data_uri(&self) -> Result<String> {
        Ok(format!("data:image/png;base64,{}", base64(&self.png()?)))
    }
}

/// Standard base64 (RFC 4648, with `=` padding).
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], chunk.get(1).copied().unwrap_or(0), chunk.get(2).copied().unwrap_or(0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_vectors() {
        let cases =
            [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foob", "Zm9vYg=="), ("foobar", "Zm9vYmFy")];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn images_encode_as_png() {
        let mut img = Rgb8::filled(3, 2, [255, 255, 255]);
        img.set(2, 1, [10, 20, 30]);
        img.set(9, 9, [0, 0, 0]);
        assert_eq!(&img.data[15..18], &[10, 20, 30]);
        let png = img.png().expect("encodes");
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert!(img.data_uri().expect("encodes").starts_with("data:image/png;base64,iVBORw0KGgo"));
    }
}
