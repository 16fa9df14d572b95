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

# Strips the timing columns (docs/src/outputs.md: seconds, efficiency, seconds_median, efficiency_mse, p_eff)
# from summary.csv so two runs can be compared byte for byte.
strip_timing() {
  python3 - "$1" <<'PY'
import csv, sys
timing = {"seconds", "efficiency", "seconds_median", "efficiency_mse", "p_eff"}
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, h in enumerate(rows[0]) if h not in timing]
for r in rows:
    print(",".join(r[i] for i in keep))
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
  if cmp -s <(strip_timing "$a/summary.csv") <(strip_timing "$b/summary.csv") && cmp -s <(zcat "$a/integrals.csv.gz") <(zcat "$b/integrals.csv.gz"); then
    echo "$e: summary.csv (timing columns aside) and integrals.csv identical at 1 and 2 threads"
  else
    echo "$e: RESULTS DIFFER between 1 and 2 threads"; exit 1
  fi
  ;;
*)
  sed -n 2,5p "$0"; exit 2
  ;;
esac
