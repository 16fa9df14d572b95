//! Readable names in legends and titles, read from the registered entries: an entry's display
//! name ([`ParamSpec::display`]) with its parameters in words ([`ParamSpec::words`]) turns an
//! estimator name such as `smc_path[bridges=5]` into "SMC, path sampling, 5 bridges", and a test
//! bed and variant into a title. An entry without a display name is shown by its registered label
//! (with the name's parameters when the label lacks them) or its id, and a test bed by
//! `testbed / variant`.
//!
//! [`ParamSpec::display`]: mcbench_core::ParamSpec::display
//! [`ParamSpec::words`]: mcbench_core::ParamSpec::words

use mcbench_core::entry::{EstimatorEntry, TestBedEntry};

/// The entries whose display names legends and titles use.
#[derive(Clone, Copy, Default)]
pub struct DisplayNames<'a> {
    estimators: &'a [&'static EstimatorEntry],
    testbeds: &'a [&'static TestBedEntry],
}

impl std::fmt::Debug for DisplayNames<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DisplayNames")
            .field("estimators", &self.estimators.iter().map(|e| e.id).collect::<Vec<_>>())
            .field("testbeds", &self.testbeds.iter().map(|t| t.id).collect::<Vec<_>>())
            .finish()
    }
}

impl<'a> DisplayNames<'a> {
    /// No entries: labels and ids only.
    pub const NONE: DisplayNames<'static> = DisplayNames { estimators: &[], testbeds: &[] };

    /// The display names of these entries.
    pub fn new(estimators: &'a [&'static EstimatorEntry], testbeds: &'a [&'static TestBedEntry]) -> Self {
        DisplayNames { estimators, testbeds }
    }

    /// Estimator `name` (`id` or `id[param=value,...]`) by its entry's display name and its
    /// parameters in words; `None` for an id without a display name or a malformed name.
    pub fn named_estimator(&self, name: &str) -> Option<String> {
        let (id, params) = match name.split_once('[') {
            Some((id, rest)) => (id, rest.strip_suffix(']')?),
            None => (name, ""),
        };
        let entry = self.estimators.iter().find(|e| e.id == id)?;
        let mut out = entry.params.display.filter(|d| !d.is_empty())?.to_string();
        for kv in params.split(',').filter(|s| !s.is_empty()) {
            let (k, v) = kv.split_once('=')?;
            out.push_str(", ");
            out.push_str(&entry.params.word(k.trim(), v.trim()));
        }
        Some(out)
    }

    /// A (test bed, variant) by its entry's display name and the variant in words; `None` for a
    /// test bed without a display name.
    pub fn named_testbed(&self, testbed: &str, variant: &str) -> Option<String> {
        let entry = self.testbeds.iter().find(|b| b.id == testbed)?;
        let bed = entry.params.display.filter(|d| !d.is_empty())?;
        if variant.is_empty() || variant == "default" {
            return Some(bed.to_string());
        }
        let words = entry.params.words.and_then(|f| f("variant", variant)).unwrap_or_else(|| variant.to_string());
        Some(format!("{bed}, {words}"))
    }

    /// The legend name of estimator `name`, whose registered label is `label` (if known).
    pub fn estimator(&self, name: &str, label: Option<&str>) -> String {
        if let Some(shown) = self.named_estimator(name) {
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
        self.named_testbed(testbed, variant).unwrap_or_else(|| {
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
    use mcbench_core::ParamSpec;

    fn words(key: &str, value: &str) -> Option<String> {
        match key {
            "bridges" => Some(format!("{value} bridges")),
            "variant" => Some(value.replace('-', " ")),
            _ => None,
        }
    }

    static NAMED: EstimatorEntry = EstimatorEntry {
        id: "smc_path",
        label: "SMC, path",
        params: ParamSpec::NONE.display("SMC, path sampling").words(words),
        ..mcbench_papers::independent::is0_cv0::ENTRY
    };
    static LABELLED: EstimatorEntry = EstimatorEntry {
        id: "mis",
        label: "MIS (label)",
        params: ParamSpec::NONE,
        ..mcbench_papers::independent::is0_cv0::ENTRY
    };
    static BED: TestBedEntry = TestBedEntry {
        id: "gradient-box",
        params: ParamSpec::NONE.display("gradient box").words(words),
        ..mcbench_papers::testbeds::gradient_box::ENTRY
    };

    #[test]
    fn the_display_name_first_then_the_label_then_the_id() {
        let (ests, beds) = ([&NAMED, &LABELLED], [&BED]);
        let names = DisplayNames::new(&ests, &beds);
        assert_eq!(names.estimator("smc_path", Some("SMC, path")), "SMC, path sampling");
        assert_eq!(names.estimator("smc_path[bridges=5]", Some("SMC, path")), "SMC, path sampling, 5 bridges");
        assert_eq!(names.estimator("smc_path[moves=2]", None), "SMC, path sampling, moves = 2");
        assert_eq!(
            names.estimator("smc_path[bridges=5", Some("SMC, path")),
            "SMC, path [bridges=5",
            "malformed: the label"
        );
        assert_eq!(names.estimator("mis[n=2]", Some("MIS (label)")), "MIS (label) [n=2]");
        assert_eq!(names.estimator("other", None), "other");
        assert_eq!(DisplayNames::NONE.estimator("smc_path", Some("SMC, path")), "SMC, path");
        assert_eq!(names.testbed("gradient-box", "default"), "gradient box");
        assert_eq!(names.testbed("gradient-box", "albedo-1"), "gradient box, albedo 1");
        assert_eq!(names.testbed("gradient-plane", "default"), "gradient-plane");
        assert_eq!(names.testbed("gradient-plane", "mixed"), "gradient-plane / mixed");
    }
}
