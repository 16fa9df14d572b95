#!/usr/bin/env bash
# Mitsuba 3 on an exported test bed (book: exported-beds.md, your-renderer.md), on the debug
# binary: `mcbench export` writes gradient-plane/diffuse at 4x4 pixels as a Mitsuba scene (its sky
# bitmap checked against the exact sky), render.py renders 64 repetitions at 16, 64 and 256
# samples per pixel with Mitsuba's path tracer and with a clamped copy of it, and `mcbench ingest`
# must read the path tracer `pass` against the bed's exact reference and the clamped one `biased`
# (the combined rows of tests.csv say so too). Mitsuba and NumPy are installed with pip into a
# folder under the target directory (later runs reuse it); a failed install fails the check.
set -euo pipefail
cd "$(dirname "$0")/../.."
target="${CARGO_TARGET_DIR:-target}"
target="$(cd "$target" && pwd)"
mcbench="$target/debug/mcbench"
py="$target/tools/mitsuba-py"
if [ ! -d "$py/mitsuba" ] || [ ! -d "$py/numpy" ]; then
    python3 -m pip install --quiet --target "$py" mitsuba numpy
fi
export PYTHONPATH="$py${PYTHONPATH:+:$PYTHONPATH}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
here="$PWD"
cd "$work"
start=$(date +%s.%N)  # seconds, for the closing line
"$mcbench" export gradient-plane --variant diffuse --param resolution=4 --out scene
# The sky bitmap in Mitsuba's layout: its error over the upper hemisphere is 3.2e-5 (book).
python3 "$here/examples/mitsuba-producer/sky_error.py" scene --directions 4000 --require-upper 1e-4
python3 "$here/examples/mitsuba-producer/render.py" scene renders --bed gradient-plane/diffuse
rendered=$(date +%s.%N)
"$mcbench" ingest renders/manifest.toml --no-plots | tee ingest.txt
done_at=$(date +%s.%N)
grep -q "^mitsuba_path: declared Unbiased, unbiasedness test pass: as declared" ingest.txt
grep -q "^mitsuba_clamped: declared Biased, unbiasedness test biased: as declared" ingest.txt
python3 - results/mitsuba-gradient-plane/tests.csv "$start" "$rendered" "$done_at" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["test"] == "combined"]
verdict = {r["estimator"]: r["verdict"] for r in rows}
assert verdict == {"mitsuba_path": "pass", "mitsuba_clamped": "biased"}, verdict
for r in rows:
    print(f'{r["estimator"]}: {r["verdict"]}, relative bias {float(r["rel_bias"]):+.4f} +- {float(r["rel_bias_se"]):.4f}, '
          f'detectable {float(r["detectable_rel_bias"]):.4f}')
start, rendered, done = map(float, sys.argv[2:5])
print(f"mitsuba producer: path tracer pass, clamped biased; export + render {rendered - start:.1f} s, ingest {done - rendered:.1f} s")
PY
