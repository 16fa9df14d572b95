#!/usr/bin/env bash
# A researcher's crate outside the workspace, as CI builds it: the template (src/main.rs, at most
# 80 lines of Rust: one estimator, a biased copy and one generic-integrand test bed) is written
# into a temporary folder with a Cargo.toml depending on the workspace's crates by path and the
# workspace's Cargo.lock (the same versions, so the shared target folder's build is reused), built,
# and run through its binary: a sweep, `conformance` of its estimators without --references, and
# `run unbiasedness --estimators <its ids>`, where the biased copy must be flagged and the
# unbiased one not.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
workspace="$(cd "$here/../.." && pwd)"
lines=$(wc -l < "$here/src/main.rs")
if [ "$lines" -gt 80 ]; then
    echo "outside crate: src/main.rs has $lines lines (at most 80)" >&2
    exit 1
fi
crate="$(mktemp -d)"
trap 'rm -rf "$crate"' EXIT
mkdir -p "$crate/src"
sed "s|@WORKSPACE@|$workspace|g" "$here/Cargo.toml.in" > "$crate/Cargo.toml"
cp "$here/src/main.rs" "$crate/src/main.rs"
cp "$here/sweep.toml" "$crate/sweep.toml"
cp "$workspace/Cargo.lock" "$crate/Cargo.lock"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$workspace/target}"
cargo build --quiet --manifest-path "$crate/Cargo.toml"
bin="$CARGO_TARGET_DIR/debug/my-integrands"
start=$(date +%s)
cd "$crate"
"$bin" run --config sweep.toml --threads 2 --no-plots >/dev/null
"$bin" conformance my_stratified my_stratified_biased
"$bin" run unbiasedness --estimators 'my_*' --threads 2 --no-plots >/dev/null
table=results/unbiasedness/unbiasedness.csv
verdict() { awk -F, -v e="$1" '$1 == e && $2 == "my-exp" { print $7 }' "$table"; }
if [ "$(verdict my_stratified_biased)" != "biased" ] || [ "$(verdict my_stratified)" = "biased" ] \
    || [ -z "$(verdict my_stratified)" ]; then
    echo "outside crate: expected the biased copy flagged and the estimator not:" >&2
    cat "$table" >&2
    exit 1
fi
echo "outside crate: $lines lines of Rust; sweep, conformance and unbiasedness in $(( $(date +%s) - start )) s"
