//! Readable names in legends and titles. The harness knows ids only; a suite that knows its papers'
//! vocabulary hands it a [`DisplayNames`] (through [`crate::Registry::with_display_names`]) that
//! turns an estimator name such as `smc_path[bridges=5]` into "SMC, path sampling, 5 bridges" and
//! a test bed and variant into a title. Where the hook has no name, an estimator is shown by its
//! registered label (with the name's parameters when the label lacks them) or its id, and a test
//! bed by `testbed / variant`.

/// Names an estimator (`id` or `id[param=value,...]`): `None` leaves it to the fallback.
pub type EstimatorNameFn = fn(&str) -> Option<String>;
/// Names a (test bed, variant): `None` leaves it to the fallback.
pub type TestBedNameFn = fn(&str, &str) -> Option<String>;

/// The display-name hooks of a suite.
#[derive(Clone, Copy, Debug, Default)]
pub struct DisplayNames {
    /// The estimator hook.
    pub estimator: Option<EstimatorNameFn>,
    /// The test-bed hook.
    pub testbed: Option<TestBedNameFn>,
}

impl DisplayNames {
    /// No hooks: labels and ids only.
    pub const NONE: DisplayNames = DisplayNames { estimator: None, testbed: None };

    /// The legend name of estimator `name`, whose registered label is `label` (if known).
    pub fn estimator(&self, name: &str, label: Option<&str>) -> String {
        if let Some(shown) = self.estimator.and_then(|f| f(name)).filter(|s| !s.is_empty()) {
            return shown;
        }
        let Some(label) = label.filter(|l| !l.is_empty() && *l != name) else { return name.to_string() };
        // Parametrised runs of one id share its label: keep their parameters.
        match name.find('[').map(|i| &name[i..]) {
            Some(params) if !label.ends_with(params) => format!("{label} {params}"),
            _ => label.to_string(),
        }
    }

    /// The title name of a (test bed, variant).
    pub fn testbed(&self, testbed: &str, variant: &str) -> String {
        self.testbed.and_then(|f| f(testbed, variant)).filter(|s| !s.is_empty()).unwrap_or_else(|| {
            if variant.is_empty() || variant == "default" {
                testbed.to_string()
            } else {
                format!("{testbed} / {variant}")
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mine(name: &str) -> Option<String> {
        (name == "is1_cv2").then(|| "IS1 CV2 (SMC cache)".to_string())
    }

    fn bed(testbed: &str, _: &str) -> Option<String> {
        (testbed == "gradient-plane").then(|| "gradient plane".to_string())
    }

    #[test]
    fn the_hook_names_first_then_the_label_then_the_id() {
        let names = DisplayNames { estimator: Some(mine), testbed: Some(bed) };
        assert_eq!(names.estimator("is1_cv2", Some("is1_cv2")), "IS1 CV2 (SMC cache)");
        assert_eq!(names.estimator("smc_path[bridges=5]", Some("SMC, path")), "SMC, path [bridges=5]");
        assert_eq!(names.estimator("mis", None), "mis");
        assert_eq!(DisplayNames::NONE.estimator("is1_cv2", Some("is1_cv2")), "is1_cv2");
        assert_eq!(names.testbed("gradient-plane", "default"), "gradient plane");
        assert_eq!(names.testbed("gradient-box", "albedo-1"), "gradient-box / albedo-1");
        assert_eq!(names.testbed("gradient-box", "default"), "gradient-box");
    }
}
