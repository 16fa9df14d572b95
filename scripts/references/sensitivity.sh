#!/usr/bin/env bash
# The stored references the `sensitivity` experiment reads beyond the test beds' defaults: the
# gradient box at albedo 0.8 at each extinction it sweeps (sigma_t = 2 is the stored default).
# Each file records the command that made it; on 2 cores they take 30-180 CPU-s each (thicker
# boxes scatter more). Usage: scripts/references/sensitivity.sh [MCBENCH] [REFERENCES_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
MCBENCH="${1:-target/release/mcbench}"
REFS="${2:-estimators/references}"
for sigma_t in 0.125 0.25 0.5 1 4; do
    "$MCBENCH" reference gradient-box --variant albedo-0.8 --param "sigma_t=$sigma_t" --references "$REFS"
done
