#!/usr/bin/env python3
"""Coverage of the ratio claims' 95% intervals against long runs.

For one experiment, runs `mcbench run EXPERIMENT --quick` at each of the given seeds and at two
long-run seeds with `--reps LONG`, then reports per ratio claim (a claims.csv row with an interval)
how often a quick run's interval covers the long runs' value (the geometric mean of the two long
runs' values), the seeds' spread of the log value beside the intervals' mean half-width over
1.96, and the two long runs' disagreement in units of their own intervals. Runs already in
OUT are reused (delete OUT to measure again).

Usage: python3 scripts/statistics/ratio_coverage.py --mcbench target/release/mcbench \
           --experiment transmittance --seeds 201-230 --long 9001,9002 --long-reps 1024 --out /tmp/cov
"""

from __future__ import annotations

import argparse
import csv
import math
import statistics
import subprocess
import sys
from pathlib import Path


def seeds_of(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        out.extend(range(int(lo), int(hi or lo) + 1))
    return out


def run(mcbench: str, experiment: str, seed: int, reps: int | None, out: Path) -> Path:
    folder = out / (f"long-{seed}" if reps else f"seed-{seed}")
    claims = folder / experiment / "claims.csv"
    if not claims.is_file():
        cmd = [mcbench, "run", experiment, "--quick", "--seed", str(seed), "--no-plots", "--results", str(folder)]
        if reps:
            cmd += ["--reps", str(reps)]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return claims


def ratio_rows(path: Path) -> dict[tuple[str, str, str], tuple[float, float, float]]:
    rows = {}
    for r in csv.DictReader(path.open()):
        try:
            v, lo, hi = float(r["our_value"]), float(r["interval_low"]), float(r["interval_high"])
        except ValueError:
            continue
        if r.get("pair") and v > 0 and lo > 0 and hi > 0:
            rows[(r["testbed"], r["claim"], r["pair"])] = (v, lo, hi)
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mcbench", required=True)
    ap.add_argument("--experiment", required=True)
    ap.add_argument("--seeds", required=True, help="e.g. 201-230 or 1,2,5-9")
    ap.add_argument("--long", default="9001,9002")
    ap.add_argument("--long-reps", type=int, default=1024)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    longs = [ratio_rows(run(a.mcbench, a.experiment, s, a.long_reps, a.out)) for s in seeds_of(a.long)]
    quick = [ratio_rows(run(a.mcbench, a.experiment, s, None, a.out)) for s in seeds_of(a.seeds)]
    total = [0, 0]
    print(f"{a.experiment}: {len(quick)} seeds ({a.seeds}) against long runs {a.long} at {a.long_reps} reps")
    print("claim | long-run value | long runs apart (z) | seeds' sd(log) | mean half-width/1.96 | covered")
    for key in sorted(longs[0]):
        if not all(key in L for L in longs):
            continue
        logs = [math.log(L[key][0]) for L in longs]
        truth = sum(logs) / len(logs)
        # The long runs' disagreement over their combined standard error (intervals as 95% ones).
        ses = [(math.log(L[key][2]) - math.log(L[key][1])) / (2 * 1.96) for L in longs]
        apart = abs(logs[0] - logs[-1]) / math.hypot(*ses[:2]) if len(ses) > 1 and any(ses) else float("nan")
        vals = [q[key] for q in quick if key in q]
        covered = sum(lo <= math.exp(truth) <= hi for _, lo, hi in vals)
        sd = statistics.stdev(math.log(v) for v, _, _ in vals) if len(vals) > 1 else float("nan")
        hw = statistics.mean((math.log(hi) - math.log(lo)) / (2 * 1.96) for _, lo, hi in vals)
        total[0] += covered
        total[1] += len(vals)
        print(f"{key[0]} {key[2]} ({key[1][:50]}...) | {math.exp(truth):.4g} | {apart:.1f} | {sd:.3f} | {hw:.3f} | {covered}/{len(vals)}")
    if total[1]:
        print(f"all: {total[0]}/{total[1]} = {100 * total[0] / total[1]:.1f}%")
    return 0


if __name__ == "__main__":
    sys.exit(main())
