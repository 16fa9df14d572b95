#!/usr/bin/env bash
# Claim verdicts under load: runs the quick suite twice from scratch, once on an otherwise idle
# machine and once beside two busy-loop processes, and compares the verdict of every claim that
# compares two estimators (speed-ups, error and efficiency ratios, orderings, shares). Time-based
# claims use the estimating threads' CPU time with compared cells interleaved, so load should not
# change them. Not run by cargo or CI (two suite runs: about 10 minutes on 2 cores).
#   scripts/perf/load_verdicts.sh [OUT_DIR]   (default /tmp/mcbench-load-verdicts)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
OUT="${1:-/tmp/mcbench-load-verdicts}"
BIN="${MCBENCH:-$ROOT/target/release/mcbench}"
[ -x "$BIN" ] || (cd "$ROOT" && cargo build --release -q)
rm -rf "$OUT" && mkdir -p "$OUT"
suite() { "$BIN" --results "$OUT/$1/results" --plots "$OUT/$1/plots" --references "$ROOT/estimators/references" > "$OUT/$1.log" 2>&1; }

start=$(date +%s); suite idle; echo "idle run: $(( $(date +%s) - start )) s"
pids=()
for _ in 1 2; do (while :; do :; done) & pids+=($!); done
trap 'kill "${pids[@]}" 2>/dev/null || true' EXIT
start=$(date +%s); suite busy; echo "run beside two busy loops: $(( $(date +%s) - start )) s"
kill "${pids[@]}" 2>/dev/null || true
python3 "$ROOT/scripts/perf/compare_verdicts.py" "$OUT/idle/results" "$OUT/busy/results" | tee "$OUT/verdicts.md"
