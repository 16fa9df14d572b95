#!/usr/bin/env python3
"""Compares the claim verdicts of two results roots (summary.json `paper` blocks of every
experiment): every claim with a compared pair or an interval (ratio, speed-up, ordering, share,
slope claims), by experiment, test bed and claim text. Prints a table and exits 1 if any differs.
Usage: compare_verdicts.py RESULTS_A RESULTS_B"""
import json
import pathlib
import sys

from compare_results import verdict


def claims(root):
    out = {}
    for f in sorted(pathlib.Path(root).glob("*/summary.json")):
        for c in json.loads(f.read_text())["paper"]:
            if c.get("pair") or c.get("interval"):
                key = (f.parent.name, c["testbed"], c["claim"], c.get("regime", ""))
                out[key] = (verdict(c), c.get("our_value"), c.get("interval"))
    return out


def fmt(v):
    value, interval = v[1], v[2]
    s = "-" if value is None else f"{value:.4g}"
    if interval:
        s += f" [{interval[0]:.4g}, {interval[1]:.4g}]"
    return f"{v[0]}: {s}"


a, b = claims(sys.argv[1]), claims(sys.argv[2])
keys = sorted(set(a) | set(b))
differ = 0
print("| experiment | claim | idle | busy | same |")
print("|---|---|---|---|---|")
for k in keys:
    va, vb = a.get(k, ("missing", None, None)), b.get(k, ("missing", None, None))
    same = va[0] == vb[0]
    differ += not same
    text = f"{k[1]}: {k[2][:90]}" + (f" [{k[3]}]" if k[3] else "")
    print(f"| {k[0]} | {text} | {fmt(va)} | {fmt(vb)} | {'yes' if same else 'NO'} |")
print(f"\n{len(keys)} claims compared, {differ} verdicts differ")
sys.exit(1 if differ else 0)
