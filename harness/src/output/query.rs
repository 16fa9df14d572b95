//! Look-ups in a run's rows by cell key: the rows of a (test bed, variant), of one estimator on
//! it, at one budget, or the largest budget measured. Every row type keyed by (test bed, variant,
//! estimator[, budget]) can be queried: summary rows, integral rows, fits, tests, speed-ups,
//! diagnostics, counts.
//!
//! ```
//! use mcbench::output::query::Query;
//! use mcbench::output::CellCounts;
//!
//! let cell = |testbed: &str, estimator: &str, budget| CellCounts {
//!     testbed: testbed.into(),
//!     variant: "default".into(),
//!     estimator: estimator.into(),
//!     budget,
//!     target_evals: 0.0,
//!     cache_ops: 0.0,
//! };
//! let rows = [cell("a", "x", 10), cell("a", "x", 20), cell("a", "y", 20), cell("b", "x", 40)];
//! let on_a = Query::new(&rows).testbed("a").variant("default");
//! assert_eq!(on_a.largest_budget(), Some(20));
//! assert_eq!(on_a.estimator("x").count(), 2);
//! assert_eq!(on_a.estimator("y").at(20).first().map(|r| r.budget), Some(20));
//! assert!(on_a.estimator("y").at(10).first().is_none());
//! ```

use crate::analysis::metrics::SummaryRow;
use crate::analysis::{Fit, SpeedUp, TestRow};
use crate::output::{CellCounts, Diagnostic, RunReport};

/// A row keyed by its cell: test bed, variant, estimator and, for rows of one budget, the budget.
/// (Integral rows implement it beside their type, in [`crate::output::integrals`].)
pub trait Keyed {
    /// Test bed id.
    fn testbed(&self) -> &str;
    /// Variant.
    fn variant(&self) -> &str;
    /// Estimator name.
    fn estimator(&self) -> &str;
    /// The budget of the row; `None` for rows over every budget (fits, integrals), which a
    /// query [`Query::at`] a budget never matches.
    fn budget(&self) -> Option<u64>;
}

macro_rules! keyed {
    ($t:ty, $r:ident => $budget:expr) => {
        impl Keyed for $t {
            fn testbed(&self) -> &str {
                &self.testbed
            }
            fn variant(&self) -> &str {
                &self.variant
            }
            fn estimator(&self) -> &str {
                &self.estimator
            }
            fn budget(&self) -> Option<u64> {
                let $r = self;
                $budget
            }
        }
    };
}

keyed!(SummaryRow, r => Some(r.budget));
keyed!(TestRow, r => Some(r.budget));
keyed!(SpeedUp, r => Some(r.budget));
keyed!(Diagnostic, r => Some(r.budget));
keyed!(CellCounts, r => Some(r.budget));
keyed!(Fit, _r => None);
// An integral row holds every budget's mean: it matches no single budget.
keyed!(crate::output::integrals::IntegralRow, _r => None);

impl<T: Keyed> Keyed for &T {
    fn testbed(&self) -> &str {
        (**self).testbed()
    }
    fn variant(&self) -> &str {
        (**self).variant()
    }
    fn estimator(&self) -> &str {
        (**self).estimator()
    }
    fn budget(&self) -> Option<u64> {
        (**self).budget()
    }
}

/// The rows of a slice that match every key set so far (none set: every row), in their order.
/// Cheap to copy: each narrowing returns a new query.
#[derive(Debug)]
pub struct Query<'r, 'k, T> {
    rows: &'r [T],
    testbed: Option<&'k str>,
    variant: Option<&'k str>,
    estimator: Option<&'k str>,
    budget: Option<u64>,
}

impl<T> Clone for Query<'_, '_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Query<'_, '_, T> {}

impl<'r, 'k, T: Keyed> Query<'r, 'k, T> {
    /// Every row of `rows`.
    pub fn new(rows: &'r [T]) -> Self {
        Query { rows, testbed: None, variant: None, estimator: None, budget: None }
    }

    /// Only the rows of test bed `testbed`.
    pub fn testbed(self, testbed: &'k str) -> Self {
        Query { testbed: Some(testbed), ..self }
    }

    /// Only the rows of variant `variant`.
    pub fn variant(self, variant: &'k str) -> Self {
        Query { variant: Some(variant), ..self }
    }

    /// Only the rows of the (test bed, variant) pair `bed`.
    pub fn bed(self, bed: (&'k str, &'k str)) -> Self {
        self.testbed(bed.0).variant(bed.1)
    }

    /// Only the rows of estimator `estimator`.
    pub fn estimator(self, estimator: &'k str) -> Self {
        Query { estimator: Some(estimator), ..self }
    }

    /// Only the rows at budget `budget`.
    pub fn at(self, budget: u64) -> Self {
        Query { budget: Some(budget), ..self }
    }

    /// Whether `row` matches every key set.
    pub fn matches(&self, row: &T) -> bool {
        self.testbed.is_none_or(|t| row.testbed() == t)
            && self.variant.is_none_or(|v| row.variant() == v)
            && self.estimator.is_none_or(|e| row.estimator() == e)
            && self.budget.is_none_or(|b| row.budget() == Some(b))
    }

    /// The matching rows, in their order.
    pub fn iter(self) -> Matches<'r, 'k, T> {
        Matches { query: self, next: 0 }
    }

    /// The first matching row.
    pub fn first(self) -> Option<&'r T> {
        self.iter().next()
    }

    /// How many rows match.
    pub fn count(self) -> usize {
        self.iter().count()
    }

    /// The largest budget of the matching rows (`None` when no matching row has a budget).
    pub fn largest_budget(self) -> Option<u64> {
        self.iter().filter_map(|r| r.budget()).max()
    }
}

impl<'r, 'k, T: Keyed> IntoIterator for Query<'r, 'k, T> {
    type Item = &'r T;
    type IntoIter = Matches<'r, 'k, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The iterator over a [`Query`]'s matching rows.
#[derive(Debug)]
pub struct Matches<'r, 'k, T> {
    query: Query<'r, 'k, T>,
    next: usize,
}

impl<'r, T: Keyed> Iterator for Matches<'r, '_, T> {
    type Item = &'r T;

    fn next(&mut self) -> Option<&'r T> {
        let rows = self.query.rows;
        while let Some(row) = rows.get(self.next) {
            self.next += 1;
            if self.query.matches(row) {
                return Some(row);
            }
        }
        None
    }
}

impl RunReport {
    /// A query over the run's summary rows (every cell of `summary.csv`).
    pub fn query(&self) -> Query<'_, 'static, SummaryRow> {
        Query::new(&self.rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::integrals::IntegralRow;

    fn row(testbed: &str, variant: &str, estimator: &str, budget: u64) -> CellCounts {
        CellCounts {
            testbed: testbed.into(),
            variant: variant.into(),
            estimator: estimator.into(),
            budget,
            target_evals: budget as f64,
            cache_ops: 0.0,
        }
    }

    fn rows() -> Vec<CellCounts> {
        vec![
            row("a", "v", "x", 10),
            row("a", "v", "x", 20),
            row("a", "v", "y", 20),
            row("a", "w", "x", 80),
            row("b", "v", "x", 40),
        ]
    }

    fn budgets<'r>(q: Query<'r, '_, CellCounts>) -> Vec<(&'r str, &'r str, &'r str, u64)> {
        q.iter().map(|r| (r.testbed.as_str(), r.variant.as_str(), r.estimator.as_str(), r.budget)).collect()
    }

    #[test]
    fn no_key_matches_every_row_in_order() {
        let rows = rows();
        assert_eq!(budgets(Query::new(&rows)).len(), 5);
        assert_eq!(Query::new(&rows).iter().map(|r| r.budget).collect::<Vec<_>>(), [10, 20, 20, 80, 40]);
    }

    #[test]
    fn each_key_narrows() {
        let rows = rows();
        let q = Query::new(&rows);
        assert_eq!(q.testbed("a").count(), 4);
        assert_eq!(q.testbed("a").variant("v").count(), 3);
        assert_eq!(q.bed(("a", "v")).estimator("x").count(), 2);
        assert_eq!(budgets(q.bed(("a", "v")).estimator("x").at(20)), [("a", "v", "x", 20)]);
        // Any variant of a test bed, and any test bed of an estimator at a budget.
        assert_eq!(q.testbed("a").estimator("x").count(), 3);
        assert_eq!(budgets(q.estimator("x").at(40)), [("b", "v", "x", 40)]);
        assert!(q.testbed("c").first().is_none());
        assert!(q.bed(("a", "v")).at(30).first().is_none());
    }

    #[test]
    fn largest_budget_is_over_the_matching_rows_only() {
        let rows = rows();
        let q = Query::new(&rows);
        assert_eq!(q.largest_budget(), Some(80));
        assert_eq!(q.bed(("a", "v")).largest_budget(), Some(20));
        assert_eq!(q.testbed("b").largest_budget(), Some(40));
        assert_eq!(q.testbed("c").largest_budget(), None);
    }

    #[test]
    fn rows_without_a_budget_never_match_a_budget() {
        let pixel = IntegralRow {
            testbed: "a".into(),
            variant: "v".into(),
            estimator: "x".into(),
            integral: 0,
            px: 0,
            py: 0,
            channel: 0,
            reference: 1.0,
            reference_se: 0.0,
            mean: 1.0,
            std_err: 0.0,
            geometry: Vec::new(),
            estimator_id: "x".into(),
        };
        let pixels = [pixel];
        assert_eq!(Query::new(&pixels).bed(("a", "v")).estimator("x").count(), 1);
        assert_eq!(Query::new(&pixels).at(0).count(), 0);
        assert_eq!(Query::new(&pixels).largest_budget(), None);
    }

    #[test]
    fn a_query_over_references_matches_like_one_over_rows() {
        let rows = rows();
        let refs: Vec<&CellCounts> = rows.iter().collect();
        assert_eq!(Query::new(&refs).bed(("a", "v")).estimator("x").count(), 2);
        assert_eq!(Query::new(&refs).testbed("b").first().map(|r| r.budget), Some(40));
    }
}
