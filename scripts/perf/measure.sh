#!/usr/bin/env bash
# Measurements for docs/src/performance.md (not run by cargo or CI).
#   scripts/perf/measure.sh rss        peak RSS and wall time of each quick experiment (2 threads)
#   scripts/perf/measure.sh scaling E  experiment E at 1 and 2 threads: wall times, identical results
# Needs a release build: cargo build --release (mcbench from $CARGO_TARGET_DIR or target/).
set -euo pipefail
BIN="${CARGO_TARGET_DIR:-target}/release/mcbench"
OUT="${OUT:-/tmp/mcbench-perf}"
EXPERIMENTS="surface-smc media-smc transmittance particle-sweep pmc-hi pmc-ip envmap-smc single-scatter canonical-sweep"
mkdir -p "$OUT"

# Strips the timing columns from summary.csv so two runs can be compared byte for byte. The list is
# timing_columns.txt beside this script, one name a line: the harness's TIMING_COLUMNS
# (harness/src/analysis/metrics.rs), which tests/contract.rs checks it equals.
TIMING_COLUMNS="$(dirname "$0")/timing_columns.txt"
strip_timing() {
  python3 - "$TIMING_COLUMNS" "$1" <<'PY'
import csv, sys
timing = {l.strip() for l in open(sys.argv[1]) if l.strip()}
rows = list(csv.reader(open(sys.argv[2], newline="")))
missing = timing - set(rows[0])
if missing:
    sys.exit(f"{sys.argv[2]}: no timing column {sorted(missing)[0]} (is {sys.argv[1]} current?)")
keep = [i for i, h in enumerate(rows[0]) if h not in timing]
w = csv.writer(sys.stdout, lineterminator="\n")
for r in rows:
    w.writerow([r[i] for i in keep])
PY
}

case "${1:-}" in
rss)
  printf "%-16s %10s %12s\n" experiment wall_s peak_rss_MB
  for e in $EXPERIMENTS; do
    rm -rf "$OUT/rss-$e"
    /usr/bin/time -f "%e %M" -o "$OUT/rss-$e.time" "$BIN" run "$e" --threads 2 --no-plots \
      --results "$OUT/rss-$e/results" --plots "$OUT/rss-$e/plots" > "$OUT/rss-$e.log" 2>&1
    read -r wall kb < "$OUT/rss-$e.time"
    printf "%-16s %10s %12.1f\n" "$e" "$wall" "$(echo "$kb / 1024" | bc -l)"
  done
  ;;
scaling)
  e="$2"
  for t in 1 2; do
    rm -rf "$OUT/scale-$e-$t"
    load=$(cut -d' ' -f1 /proc/loadavg)
    /usr/bin/time -f "%e s wall, %U s user" -o "$OUT/scale-$e-$t.time" "$BIN" run "$e" --threads "$t" --no-plots \
      --results "$OUT/scale-$e-$t/results" --plots "$OUT/scale-$e-$t/plots" > "$OUT/scale-$e-$t.log" 2>&1
    echo "$e threads $t (load average before: $load): $(cat "$OUT/scale-$e-$t.time")," \
      "cells $(python3 -c "import json,sys; print(round(json.load(open(sys.argv[1]))['meta']['wall_seconds'],1))" "$OUT/scale-$e-$t/results/$e/summary.json") s (summary.json wall_seconds)"
  done
  a="$OUT/scale-$e-1/results/$e" b="$OUT/scale-$e-2/results/$e"
  for t in 1 2; do
    strip_timing "$OUT/scale-$e-$t/results/$e/summary.csv" > "$OUT/scale-$e-$t.summary.csv"
  done
  differ=""
  cmp -s "$OUT/scale-$e-1.summary.csv" "$OUT/scale-$e-2.summary.csv" || differ="summary.csv (timing columns aside)"
  cmp -s <(zcat "$a/integrals.csv.gz") <(zcat "$b/integrals.csv.gz") || differ="${differ:+$differ and }integrals.csv"
  if [ -z "$differ" ]; then
    echo "$e: summary.csv (timing columns aside) and integrals.csv identical at 1 and 2 threads"
  else
    echo "$e: RESULTS DIFFER between 1 and 2 threads: $differ"; exit 1
  fi
  ;;
*)
  sed -n 2,5p "$0"; exit 2
  ;;
esac
