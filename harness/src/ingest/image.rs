//! An image of estimates read from a file: OpenEXR (`.exr`, RGB in half or float, by the `exr`
//! crate) or NumPy (`.npy`, [`super::npy`]). Pixel `(row, col)` is integral `row * width + col`,
//! row 0 at the top, the way the built-in pinhole test beds number their pixels.

use mcbench_core::math::Rgb;
use std::path::Path;

/// An image: `width x height` pixels, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Pixels, row-major.
    pub pixels: Vec<Rgb>,
}

impl Image {
    /// An image from interleaved values with 1 (grey: the value in every channel) or 3 channels.
    pub fn from_channels(width: usize, height: usize, channels: usize, values: Vec<f64>) -> Image {
        let pixels = values
            .chunks_exact(channels.max(1))
            .map(|c| if channels == 3 { Rgb([c[0], c[1], c[2]]) } else { Rgb([c[0]; 3]) })
            .collect();
        Image { width, height, pixels }
    }

    /// The first non-finite value: (row, column, channel).
    pub fn first_non_finite(&self) -> Option<(usize, usize, usize)> {
        self.pixels.iter().enumerate().find_map(|(i, p)| {
            p.0.iter().position(|v| !v.is_finite()).map(|c| (i / self.width.max(1), i % self.width.max(1), c))
        })
    }
}

/// Reads an image by its extension (`.npy` or `.exr`); `Err` says what is wrong with the file.
pub fn read(path: &Path) -> Result<Image, String> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("npy") => {
            let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
            super::npy::parse(&bytes)
        }
        Some("exr") => read_exr(path),
        _ => Err("an image is a .npy or .exr file".into()),
    }
}

/// The first RGB layer of an OpenEXR file at its largest resolution, as 64-bit floats.
fn read_exr(path: &Path) -> Result<Image, String> {
    use exr::prelude::ReadChannels as _;
    use exr::prelude::ReadLayers as _;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| Image { width: size.width(), height: size.height(), pixels: vec![Rgb::ZERO; size.area()] },
            |img: &mut Image, pos: exr::math::Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                let i = pos.y() * img.width + pos.x();
                if let Some(p) = img.pixels.get_mut(i) {
                    *p = Rgb([r as f64, g as f64, b as f64]);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .pedantic()
        .from_file(path)
        .map_err(|e| format!("not a readable OpenEXR RGB image: {}", crate::run::guarded::one_line(&e.to_string())))?;
    Ok(image.layer_data.channel_data.pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_pixels_read_row_major_from_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        exr::prelude::write_rgb_file(&path, 3, 2, |x, y| ((y * 3 + x) as f32, 0.5f32, 2.0f32)).unwrap();
        let img = read(&path).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        assert_eq!(img.pixels[4].0, [4.0, 0.5, 2.0]);
        std::fs::write(dir.path().join("b.exr"), b"not an exr").unwrap();
        assert!(read(&dir.path().join("b.exr")).unwrap_err().contains("OpenEXR"));
    }
}
