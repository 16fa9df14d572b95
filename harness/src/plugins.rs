//! What a crate of plug-ins adds to the checks of built-in entries it cannot edit: exemptions of
//! biased controls on its own test beds ([`Registry::with_exemption`]) and samplers of its own for
//! the conformance suite's chi-square tests ([`Registry::with_sampler`]).
//!
//! ```
//! use mcbench::Registry;
//! use mcbench_core::samplers::registry::SamplerEntry;
//!
//! /// A sampler of your own with its chi-square checks (here: none).
//! static MINE: SamplerEntry = SamplerEntry { id: "my_sampler", summary: "mine", check: Vec::new };
//!
//! let registry = Registry::new()
//!     .with_catalog(mcbench_papers::catalog())
//!     .with_exemption("clamped_is0_cv0", "my-bed", &["*"], "f/p never exceeds the clamp on this bed")
//!     .with_sampler(&MINE);
//! assert_eq!(registry.exemption("clamped_is0_cv0", "my-bed", "any"), Some("f/p never exceeds the clamp on this bed"));
//! assert_eq!(registry.exemption("clamped_is0_cv0", "gradient-plane", "default"), None);
//! assert!(registry.sampler("my_sampler").is_some() && registry.sampler("cosine_hemisphere").is_some());
//! ```

use crate::registry::Registry;
use mcbench_core::entry::Exemption;
use mcbench_core::samplers::registry as samplers;
use mcbench_core::SamplerEntry;

impl Registry {
    /// Marks the biased control `control` as "not a control here" on `variants` of `testbed` (the
    /// patterns of [`Exemption::variants`]: `prefix*`, `*suffix`, `*` or an exact name), with the
    /// reason the `unbiasedness` table and report show: for a test bed of your own on which a
    /// built-in control is unbiased by construction (a clamp the integrand never reaches).
    pub fn with_exemption(
        mut self,
        control: &'static str,
        testbed: &'static str,
        variants: &'static [&'static str],
        reason: &'static str,
    ) -> Self {
        self.exemptions.push((control, Exemption { testbed, variants, reason }));
        self
    }

    /// Registers a sampler of your own: an estimator that names it in
    /// [`mcbench_core::EstimatorEntry::samplers`] gets its chi-square checks in the conformance
    /// suite, like the built-in samplers of [`mcbench_core::samplers::registry::SAMPLERS`].
    pub fn with_sampler(mut self, entry: &'static SamplerEntry) -> Self {
        self.samplers.push(entry);
        self
    }

    /// Why the biased control `id` is not required to be flagged on `testbed/variant`: its entry's
    /// own exemptions, then those added with [`Registry::with_exemption`].
    pub fn exemption(&self, id: &str, testbed: &str, variant: &str) -> Option<&'static str> {
        let own = self.estimator(id).ok().and_then(|e| e.checks.exempt.iter().find(|x| x.covers(testbed, variant)));
        own.or_else(|| {
            self.exemptions.iter().filter(|(c, _)| *c == id).map(|(_, x)| x).find(|x| x.covers(testbed, variant))
        })
        .map(|x| x.reason)
    }

    /// A sampler by id: one registered with [`Registry::with_sampler`], else a built-in one.
    pub fn sampler(&self, id: &str) -> Option<&'static SamplerEntry> {
        self.samplers.iter().copied().find(|s| s.id == id).or_else(|| samplers::sampler(id))
    }
}
