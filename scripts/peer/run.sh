#!/usr/bin/env bash
# The peer comparison of docs/src/performance.md: mcbench's is0_cv0 and Mitsuba 3 volpath (LLVM and
# scalar) on gradient-box, 2 threads each, one after the other in the same session.
# Needs: a release build of mcbench, /work/venv-mitsuba with mitsuba + numpy, libLLVM >= 19.
set -euo pipefail
BIN="${CARGO_TARGET_DIR:-target}/release/mcbench"
PY="${MITSUBA_PYTHON:-/work/venv-mitsuba/bin/python}"
export DRJIT_LIBLLVM_PATH="${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM-19.so}"
OUT="${OUT:-/tmp/mcbench-peer}"
HERE="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$OUT"; mkdir -p "$OUT"
/usr/bin/time -f "%e %U %S" -o "$OUT/ours.time" "$BIN" run --config "$HERE/gradient_box_ours.toml" --threads 2 \
  --no-plots --results "$OUT/results" --plots "$OUT/plots" > "$OUT/ours.log" 2>&1
read -r wall user sys < "$OUT/ours.time"
paths=$((256 * 1024 * 8 * 2))  # pixels x spp x reps x two albedos
echo "mcbench is0_cv0: $paths paths, wall $wall s, cpu $(echo "$user + $sys" | bc) s:" \
  "$(echo "$paths / $wall" | bc) paths/s, $(echo "$paths / ($user + $sys)" | bc) paths/cpu-s (whole run: references, analysis included)"
python3 "$HERE/image_mean.py" "$OUT/results/peer-gradient-box/integrals.csv.gz"
for v in llvm_ad_rgb scalar_rgb; do
  for a in 0.8 1.0; do
    "$PY" "$HERE/mitsuba_gradient_box.py" --variant "$v" --albedo "$a" --threads 2
  done
done
