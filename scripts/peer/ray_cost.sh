#!/usr/bin/env bash
# Unit costs of a real renderer for the cost model (docs/src/cost_model_source.md): Mitsuba 3 ray casts
# and grid-volume lookups in ns of one CPU thread, written to scripts/peer/ray_cost.json.
# Installs what it needs when missing (libLLVM 19 from Debian, a venv with mitsuba + numpy), then
# runs ray_cost.py at nice 5. Extra arguments go to ray_cost.py (e.g. --repeats 9, --scalar 0).
# Takes about 20 s of one core with the defaults.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
VENV="${MITSUBA_VENV:-/work/venv-mitsuba}"
PY="${MITSUBA_PYTHON:-$VENV/bin/python}"
MITSUBA_SPEC="${MITSUBA_SPEC:-mitsuba==3.9.1}"
SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"

# Dr.Jit's LLVM backend emits intrinsics (llvm.maximum) that libLLVM 14/15 cannot select.
LLVM_LIB="/usr/lib/$(uname -m)-linux-gnu/libLLVM-19.so"
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ] && [ ! -e "$LLVM_LIB" ]; then
  $SUDO apt-get update -qq && $SUDO apt-get install -y -qq libllvm19
fi
export DRJIT_LIBLLVM_PATH="${DRJIT_LIBLLVM_PATH:-$LLVM_LIB}"

if ! "$PY" -c "import mitsuba, numpy" 2>/dev/null; then
  if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" 2>/dev/null || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq python3-venv && python3 -m venv "$VENV"; }
  fi
  "$VENV/bin/pip" install -q "$MITSUBA_SPEC" numpy
  PY="$VENV/bin/python"
fi

export RAY_COST_COMMAND="DRJIT_LIBLLVM_PATH=$DRJIT_LIBLLVM_PATH scripts/peer/ray_cost.sh${*:+ $*}"
exec nice -n 5 "$PY" "$HERE/ray_cost.py" "$@"
