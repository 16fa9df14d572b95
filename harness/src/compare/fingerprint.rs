//! What a run records of its test beds so that two runs can be compared: per (test bed, variant),
//! the test bed's parameters with every default filled in and a digest of the reference it measured
//! against (values, standard errors and how it was made). Two runs whose fingerprints of one
//! (test bed, variant) differ measured different integrals, so their errors are not comparable.

use serde::{Deserialize, Serialize};

/// The fingerprint of one test bed of a run (`beds` in summary.json).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BedPrint {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// The test bed's parameters with every default filled in, as JSON.
    pub testbed_params: String,
    /// Integrals (pixels).
    pub integrals: usize,
    /// FNV-1a digest (16 hex digits) of the reference as JSON: its values, standard errors and kind.
    pub reference: String,
    /// The parameters as given, as the keys of the cells in the cell store hold them (JSON).
    #[serde(default)]
    pub cell_params: String,
}

impl BedPrint {
    /// The fingerprint of a prepared test bed.
    pub fn of(bed: &crate::plan::PreparedBed) -> BedPrint {
        let reference = bed.bed.reference();
        BedPrint {
            testbed: bed.spec.id.clone(),
            variant: bed.variant.clone(),
            testbed_params: bed.params_json.clone(),
            integrals: reference.value.len(),
            reference: reference_digest(reference),
            cell_params: serde_json::to_string(&bed.spec.params).unwrap_or_default(),
        }
    }
}

/// The digest of a reference: FNV-1a of its JSON text, as 16 hex digits.
pub fn reference_digest(reference: &mcbench_core::testbed::Reference) -> String {
    format!("{:016x}", mcbench_core::rng::fnv1a(&serde_json::to_string(reference).unwrap_or_default()))
}

/// The fingerprints of a run: its `beds`, or for files written before them, what its rows say
/// (parameters and integrals; no reference digest).
fn prints(report: &crate::output::RunReport) -> Vec<BedPrint> {
    if !report.beds.is_empty() {
        return report.beds.clone();
    }
    let mut out: Vec<BedPrint> = Vec::new();
    for r in &report.rows {
        if !out.iter().any(|p| p.testbed == r.testbed && p.variant == r.variant) {
            out.push(BedPrint {
                testbed: r.testbed.clone(),
                variant: r.variant.clone(),
                testbed_params: r.testbed_params.clone(),
                integrals: r.integrals,
                reference: String::new(),
                cell_params: String::new(),
            });
        }
    }
    out
}

/// Refuses two runs of one experiment that measured a (test bed, variant) of both with different
/// parameters, integrals or references: one line naming B's summary and the test bed.
pub fn check(a: &super::load::Experiment, b: &super::load::Experiment) -> crate::error::Result<()> {
    match difference(&prints(&a.report), &prints(&b.report)) {
        None => Ok(()),
        Some((bed, what)) => Err(crate::error::HarnessError::bad_file(
            b.dir.join("summary.json"),
            format!(
                "test bed {bed} differs from the one in {} ({what}): runs of different test beds or references are not compared",
                a.dir.display()
            ),
        )),
    }
}

/// Before a run with `--baseline NAME`: refuses (exit 2, nothing written) a planned experiment
/// whose test beds `planned` differ from those of the baseline's run of it, `a` (parameters,
/// integrals or references), so that a run that could not be compared does not start.
pub fn check_planned(name: &str, a: &super::load::Experiment, planned: &[BedPrint]) -> crate::error::Result<()> {
    match difference(&prints(&a.report), planned) {
        None => Ok(()),
        Some((bed, what)) => Err(mcbench_core::error::ConfigError::invalid(
            "--baseline",
            name,
            format!(
                "test bed {bed} of experiment {} differs from the baseline's ({what}): runs of different test beds or references are not compared",
                a.report.meta.experiment
            ),
        )
        .into()),
    }
}

/// The first (test bed, variant) of both `pa` and `pb` whose parameters, integrals or references
/// differ, as `testbed/variant` and what differs.
fn difference(pa: &[BedPrint], pb: &[BedPrint]) -> Option<(String, String)> {
    for x in pa {
        let Some(y) = pb.iter().find(|y| y.testbed == x.testbed && y.variant == x.variant) else { continue };
        let what = if x.testbed_params != y.testbed_params {
            Some(format!("parameters {} and {}", x.testbed_params, y.testbed_params))
        } else if x.integrals != y.integrals {
            Some(format!("{} and {} integrals", x.integrals, y.integrals))
        } else if !x.reference.is_empty() && !y.reference.is_empty() && x.reference != y.reference {
            Some(format!("references {} and {}", x.reference, y.reference))
        } else {
            None
        };
        if let Some(what) = what {
            return Some((format!("{}/{}", x.testbed, x.variant), what));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::testbed::{Reference, ReferenceKind};
    use mcbench_core::Rgb;

    #[test]
    fn a_reference_that_differs_in_one_value_or_its_kind_has_another_digest() {
        let r = Reference {
            kind: ReferenceKind::Exact { method: "closed form".into(), bound: 0.0 },
            value: vec![Rgb([1.0, 2.0, 3.0])],
            std_err: vec![Rgb::ZERO],
        };
        let mut other = r.clone();
        other.value[0] = Rgb([1.0, 2.0, 3.0000001]);
        let mut kind = r.clone();
        kind.kind = ReferenceKind::Exact { method: "quadrature".into(), bound: 0.0 };
        assert_eq!(reference_digest(&r), reference_digest(&r.clone()));
        assert_ne!(reference_digest(&r), reference_digest(&other));
        assert_ne!(reference_digest(&r), reference_digest(&kind));
        assert_eq!(reference_digest(&r).len(), 16);
    }
}
