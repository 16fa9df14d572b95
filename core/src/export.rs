//! Test beds written as scenes for other renderers (`mcbench export`, book: exported-beds.md).
//!
//! A crate that knows how a test bed looks to another renderer registers a [`SceneExport`] in its
//! [`crate::Catalog`]; the harness builds the bed (for its reference) and writes the exporter's
//! files beside the reference image.

use crate::error::ConfigError;
use crate::params::Params;

/// One file of an exported scene: its name inside the output folder and its contents.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    /// File name (no folder).
    pub name: String,
    /// Contents.
    pub bytes: Vec<u8>,
}

impl SceneFile {
    /// A file named `name` holding `bytes`.
    pub fn new(name: &str, bytes: impl Into<Vec<u8>>) -> Self {
        SceneFile { name: name.to_string(), bytes: bytes.into() }
    }
}

/// Writes the scene files of a variant with the test bed's parameters.
pub type WriteScene = fn(variant: &str, params: &Params) -> Result<Vec<SceneFile>, ConfigError>;

/// A test bed as a scene of another renderer's format.
#[derive(Clone, Copy, Debug)]
pub struct SceneExport {
    /// The test bed's id.
    pub testbed: &'static str,
    /// The format's name (`--format`).
    pub format: &'static str,
    /// The variants this format can express.
    pub variants: &'static [&'static str],
    /// Why the bed's other variants are not exported (shown when one is asked for).
    pub not_exported: &'static str,
    /// The scene files.
    pub write: WriteScene,
}

/// Finds the exporter of `testbed` in `format` among `exports`, and checks `variant`: an error
/// names `--format` (no exporter of that format for the bed) or `--variant`.
pub fn find<'a>(
    exports: &'a [&'static SceneExport],
    testbed: &str,
    variant: &str,
    format: &str,
) -> Result<&'a SceneExport, ConfigError> {
    let of_bed: Vec<&&SceneExport> = exports.iter().filter(|e| e.testbed == testbed).collect();
    if of_bed.is_empty() {
        let beds: Vec<&str> = exports.iter().map(|e| e.testbed).collect();
        return Err(ConfigError::invalid(
            "testbed",
            testbed,
            format!("no exported scene for this test bed (exported: {})", beds.join(", ")),
        ));
    }
    let e = of_bed
        .iter()
        .find(|e| e.format == format)
        .ok_or_else(|| ConfigError::unknown("--format", format, of_bed.iter().map(|e| e.format)))?;
    if !e.variants.contains(&variant) {
        return Err(ConfigError::invalid(
            "--variant",
            format!("{testbed}/{variant}"),
            format!("not exported as {format} (exported: {}); {}", e.variants.join(", "), e.not_exported),
        ));
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn none(_: &str, _: &Params) -> Result<Vec<SceneFile>, ConfigError> {
        Ok(vec![SceneFile::new("a.txt", "x")])
    }
    static E: SceneExport = SceneExport {
        testbed: "bed",
        format: "fmt",
        variants: &["v"],
        not_exported: "w has no equivalent",
        write: none,
    };

    #[test]
    fn find_names_the_field_that_is_wrong() {
        let all = [&E];
        assert!(find(&all, "bed", "v", "fmt").is_ok());
        assert!(find(&all, "other", "v", "fmt").unwrap_err().to_string().contains("testbed"));
        assert!(find(&all, "bed", "v", "pbrt").unwrap_err().to_string().contains("--format"));
        let e = find(&all, "bed", "w", "fmt").unwrap_err().to_string();
        assert!(e.contains("--variant") && e.contains("w has no equivalent"), "{e}");
    }
}
