//! Value stability: the first estimate of every registered estimator, on the
//! first of a list of small test beds it supports, for a fixed seed, pinned bit for bit in
//! `tests/pinned_estimates.json`. An accidental change to an estimator, a sampler, a test bed or
//! the random streams fails here; an intended one is re-pinned with
//! `MCBENCH_REPIN=1 cargo test -p experiments --test pinned` (and the diff reviewed).

use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins::{self, ESTIMATORS};
use std::collections::BTreeMap;
use std::path::Path;

/// Small test beds, tried in order: (id, variant, params). Eq. 21 at exponent 1, the reading the
/// estimates were first pinned on (the medium at k = 1 is the former one bit for bit).
fn beds() -> Vec<(&'static str, &'static str, Params)> {
    vec![
        ("gradient-plane", "default", Params::new().with("resolution", 2.0)),
        ("checker-direct", "default", Params::new().with("resolution", 2.0)),
        ("eq21-medium", "central-ray", Params::new().with("points", 4.0).with("exponent", 1.0)),
        ("eq21-medium", "single-scatter", Params::new().with("resolution", 2.0).with("exponent", 1.0)),
        ("eq21-medium", "multiple", Params::new().with("exponent", 1.0)),
        ("gradient-box", "albedo-0.8", Params::new()),
        ("envmap-sequence", "mixed", Params::new().with("resolution", 2.0).with("frames", 2.0)),
        ("checker-image", "default", Params::new()),
        ("product-peak", "smooth", Params::new()),
    ]
}

/// `estimator -> "bed/variant: bits of the three channels"` for every registered estimator.
fn first_estimates() -> BTreeMap<String, String> {
    let built: Vec<(String, Box<dyn TestBed>)> = beds()
        .into_iter()
        .map(|(id, v, p)| {
            let entry = builtins::testbed(id).expect("registered test bed");
            let refs = mcbench::store::references::ReferenceDir::new(REFERENCES);
            (format!("{id}/{v}"), (entry.build)(v, &p, &refs).expect("builds"))
        })
        .collect();
    let mut out = BTreeMap::new();
    for entry in ESTIMATORS {
        let est = (entry.build)(&Params::new()).expect("default parameters build");
        let runs = |b: &dyn TestBed| b.provides().contains(entry.needs) && est.supports(b).is_ok();
        let Some((label, bed)) = built.iter().find(|(_, b)| runs(b.as_ref())) else {
            out.insert(entry.id.to_string(), "no small test bed supports it".to_string());
            continue;
        };
        // The centre integral (corner pixels may miss the medium and be exact), estimated with the
        // sequence that holds it.
        let frames = bed.sequence_length().max(1);
        let (w, h) = bed.resolution();
        let mid = ((h / 2) * w + w / 2).min(bed.integrals() - 1);
        let first = mid / frames * frames;
        let budget = Budget::samples(32).expect("budget");
        let tasks: Vec<Task<'_>> = (first..first + frames).map(|i| Task::new(bed.as_ref(), i, budget)).collect();
        let key =
            StreamKey { seed: 7, testbed: label, estimator: entry.id, budget: 32, rep: 0, integral: first as u64 };
        let value = match est.estimate_sequence(&tasks, &mut key.rng()) {
            Ok(v) => v[mid - first].0.iter().map(|x| format!("{:016x}", x.to_bits())).collect::<Vec<_>>().join(" "),
            Err(e) => format!("error: {e}"),
        };
        out.insert(entry.id.to_string(), format!("{label}: {value}"));
    }
    out
}

/// The command that rewrites the pins (book: extending.md).
const REPIN_COMMAND: &str = "MCBENCH_REPIN=1 cargo test -p experiments --test pinned";

/// What a failure says to do.
const REPIN: &str = "if the change is intended, re-pin with `MCBENCH_REPIN=1 cargo test -p experiments --test pinned` and review the diff of tests/pinned_estimates.json";

#[test]
fn first_estimates_are_pinned() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/pinned_estimates.json");
    let now = first_estimates();
    if std::env::var_os("MCBENCH_REPIN").is_some() {
        let text = serde_json::to_string_pretty(&now).expect("json");
        std::fs::write(&path, text + "\n").expect("write the pins");
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("tests/pinned_estimates.json: {e}; {REPIN}"));
    let pinned: BTreeMap<String, String> = serde_json::from_str(&text).expect("pins parse");
    let mut diffs = Vec::new();
    for (id, value) in &now {
        match pinned.get(id) {
            Some(p) if p == value => {}
            Some(p) => diffs.push(format!("{id}: pinned {p}, now {value}")),
            None => diffs
                .push(format!("{id}: not pinned yet (now {value}); a new estimator is pinned with {REPIN_COMMAND}")),
        }
    }
    for id in pinned.keys().filter(|id| !now.contains_key(*id)) {
        diffs.push(format!("{id}: pinned but no longer registered"));
    }
    assert!(diffs.is_empty(), "first estimates changed ({REPIN}):\n{}", diffs.join("\n"));
}

/// The repository's stored references.
const REFERENCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references");
