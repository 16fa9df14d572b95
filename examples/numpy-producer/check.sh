#!/usr/bin/env bash
# The commands of the book's chapter "Testing your renderer with mcbench" (docs/src/your-renderer.md),
# run on the debug binary: the NumPy producer writes two series per manifest, `mcbench ingest` must
# read the unbiased one `pass` and the +1% one `biased` (images and scalars), and two producers at
# different seeds compare with `--two-sample`. NumPy is installed into a folder under the target
# directory when the system Python lacks it (later runs reuse it).
set -euo pipefail
cd "$(dirname "$0")/../.."
target="${CARGO_TARGET_DIR:-target}"
target="$(cd "$target" && pwd)"
mcbench="$target/debug/mcbench"
if ! python3 -c "import numpy" 2>/dev/null; then
    if [ ! -d "$target/tools/numpy-py/numpy" ]; then
        python3 -m pip install --quiet --target "$target/tools/numpy-py" numpy
    fi
    export PYTHONPATH="$target/tools/numpy-py${PYTHONPATH:+:$PYTHONPATH}"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
python3 "$OLDPWD/examples/numpy-producer/produce.py" estimates
python3 "$OLDPWD/examples/numpy-producer/produce.py" estimates-b --seed 2
for m in images scalars; do
    "$mcbench" ingest "estimates/$m/manifest.toml" | tee "ingest-$m.txt"
    grep -q "^numpy_unbiased: declared Unbiased, unbiasedness test pass: as declared" "ingest-$m.txt"
    grep -q "^numpy_biased: declared Biased, unbiasedness test biased: as declared" "ingest-$m.txt"
done
grep -q "claims 2 held |" ingest-images.txt
"$mcbench" ingest estimates-b/images/manifest.toml --results results-b --no-plots
"$mcbench" compare results/numpy-images results-b/numpy-images --two-sample numpy_unbiased numpy_unbiased | tee same.txt
grep -q " 0 differ" same.txt
"$mcbench" compare results/numpy-images results-b/numpy-images --two-sample numpy_unbiased numpy_biased | tee differ.txt
grep -q ": 3 cells: 0 same, 3 differ" differ.txt
echo "numpy producer: every series read as declared"
