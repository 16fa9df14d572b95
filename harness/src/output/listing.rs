//! `mcbench list`: the registry as tables (test beds with their variants and what they provide,
//! estimators with the test beds they run on, experiments), and with `--params` every estimator's
//! and test bed's parameters from their typed parameter structs.

use crate::output::report::markdown_table;
use crate::registry::Registry;
use mcbench_core::params::ParamDoc;
use std::fmt::Write;

/// What to list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum What {
    /// Test beds.
    TestBeds,
    /// Estimators.
    Estimators,
    /// Named experiments.
    Experiments,
}

fn params_table(out: &mut String, owner: &str, docs: &[ParamDoc]) {
    let _ = writeln!(out, "\n### {owner}\n");
    if docs.is_empty() {
        let _ = writeln!(out, "no parameters");
        return;
    }
    let rows: Vec<Vec<String>> =
        docs.iter().map(|d| vec![d.name.clone(), d.kind.clone(), d.default.clone(), d.doc.clone()]).collect();
    let _ = writeln!(out, "{}", markdown_table(&["parameter", "type", "default", "meaning"], &rows));
}

/// The tables of `mcbench list [what] [--params]` (everything when `what` is `None`).
pub fn list(what: Option<What>, params: bool, registry: &Registry) -> String {
    let mut out = String::new();
    let show = |w: What| what.is_none() || what == Some(w);
    if show(What::TestBeds) {
        let rows: Vec<Vec<String>> = registry
            .test_beds()
            .iter()
            .map(|t| {
                vec![
                    t.id.into(),
                    t.variants.join(", "),
                    t.provides.to_string(),
                    t.summary.into(),
                    t.display_name().into(),
                ]
            })
            .collect();
        let header = ["test bed", "variants", "provides", "summary", "display name"];
        let _ = writeln!(out, "{}", markdown_table(&header, &rows));
        if params {
            for t in registry.test_beds() {
                params_table(&mut out, t.id, &(t.params.describe)());
            }
        }
    }
    if show(What::Estimators) {
        let rows: Vec<Vec<String>> = registry
            .estimators()
            .iter()
            .map(|e| {
                let on: Vec<&str> =
                    registry.test_beds().iter().filter(|t| e.skip_reason(t.provides).is_none()).map(|t| t.id).collect();
                vec![
                    e.id.into(),
                    e.paper.into(),
                    e.bias.name().into(),
                    e.needs.to_string(),
                    on.join(", "),
                    e.summary.into(),
                    e.display_name().into(),
                ]
            })
            .collect();
        let header = ["estimator", "paper", "claim", "needs", "runs on", "summary", "display name"];
        let _ = writeln!(out, "{}", markdown_table(&header, &rows));
        if params {
            for e in registry.estimators() {
                params_table(&mut out, e.id, &(e.params.describe)());
            }
        }
    }
    if show(What::Experiments) {
        let rows: Vec<Vec<String>> = registry
            .experiments()
            .iter()
            .map(|e| vec![e.name.clone(), e.reproduces.clone(), e.summary.clone()])
            .collect();
        let _ = writeln!(out, "{}", markdown_table(&["experiment", "reproduces", "summary"], &rows));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_are_listed_with_their_docs() {
        let text = list(Some(What::TestBeds), true, &Registry::new().with_catalog(mcbench_papers::catalog()));
        assert!(text.contains("### gradient-box") && text.contains("sigma_t"), "{text}");
        assert!(text.contains("Extinction of the box"), "{text}");
        assert!(!text.contains("| estimator |"));
    }

    #[test]
    fn entries_are_listed_with_their_display_names() {
        let text = list(None, false, &Registry::new().with_catalog(mcbench_papers::catalog()));
        // The last cell of the row of `id`.
        let last = |id: &str| {
            let row = text.lines().find(|l| l.starts_with(&format!("| {id} "))).unwrap_or_default();
            row.split('|').rev().nth(1).unwrap_or_default().trim().to_string()
        };
        assert_eq!(last("smc_path"), "SMC, path sampling", "{text}");
        assert_eq!(last("gradient-box"), "gradient box (paper 000)", "{text}");
    }
}
