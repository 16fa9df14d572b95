#!/usr/bin/env python3
"""Redraws one figure of a finished run from its result files, with polars and matplotlib.

By default: paper 001's RMSE against samples per pixel on the gradient plane, from the results
folder of `surface-smc` (`mcbench run surface-smc` writes it to results/surface-smc). One line per
estimator with its 90% bootstrap band (summary.csv `rmse_lo`, `rmse_hi`, where present), the fitted
convergence slope and its 95% interval in the legend (summary.json `fits`) and a dashed slope -1/2
guide, as mcbench draws panel (a) of its own figure.

    python3 examples/python/redraw.py results/surface-smc --out rmse.png
    python3 examples/python/redraw.py results/media-smc --testbed gradient-box --variant albedo-0.8

Bad input (a folder without summary.csv, a test bed the run does not have, a missing column): one
line on stderr naming it, exit code 2, nothing written.
"""

import argparse
import json
import os
import sys
import tempfile


def fail(message):
    print(f"redraw.py: {message}", file=sys.stderr)
    sys.exit(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="a results folder of one experiment (holding summary.csv)")
    ap.add_argument("--testbed", default="gradient-plane")
    ap.add_argument("--variant", default="default")
    ap.add_argument("--out", default="rmse.png", help="output file (.png, .svg or .pdf)")
    args = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import polars as pl

    csv = os.path.join(args.results, "summary.csv")
    if not os.path.isfile(csv):
        fail(f"results: no summary.csv in {args.results}")
    rows = pl.read_csv(csv, infer_schema_length=None)
    for column in ("testbed", "variant", "estimator", "budget", "rmse", "budget_kind"):
        if column not in rows.columns:
            fail(f"summary.csv: no column {column}")
    rows = rows.filter((pl.col("testbed") == args.testbed) & (pl.col("variant") == args.variant))
    if rows.height == 0:
        fail(f"--testbed/--variant: no rows for {args.testbed}/{args.variant} in {csv}")
    fits = {}
    summary = os.path.join(args.results, "summary.json")
    if os.path.isfile(summary):
        with open(summary, encoding="utf-8") as f:
            for fit in json.load(f).get("fits", []):
                if fit.get("testbed") == args.testbed and fit.get("variant") == args.variant:
                    fits[fit["estimator"]] = fit
    banded = "rmse_lo" in rows.columns and "rmse_hi" in rows.columns

    colours = plt.get_cmap("tab10").colors
    markers = "osD^v<>ph*"
    fig, ax = plt.subplots(figsize=(9, 6.5), layout="constrained")
    estimators = list(dict.fromkeys(rows["estimator"].to_list()))
    for k, name in enumerate(estimators):
        mine = rows.filter(pl.col("estimator") == name).sort("budget")
        x, y = mine["budget"].to_list(), mine["rmse"].to_list()
        colour = colours[k % len(colours)]
        label = name
        fit = fits.get(name)
        if fit and fit.get("slope") is not None:
            label += f": slope {fit['slope']:.2f} [{fit['slope_ci_low']:.2f}, {fit['slope_ci_high']:.2f}]"
        ax.loglog(x, y, marker=markers[k % len(markers)], color=colour, label=label, lw=1.8, ms=5)
        if banded:
            band = mine.drop_nulls(["rmse_lo", "rmse_hi"])
            if band.height >= 2:
                ax.fill_between(band["budget"].to_list(), band["rmse_lo"].to_list(), band["rmse_hi"].to_list(),
                                color=colour, alpha=0.16, lw=0)
    # The slope -1/2 guide, above every line at the smallest budget (as mcbench draws it).
    x0, x1 = rows["budget"].min(), rows["budget"].max()
    top = rows.filter(pl.col("budget") == x0)["rmse"].max()
    if x1 > x0 and top > 0:
        ax.loglog([x0, x1], [2 * top, 2 * top * (x1 / x0) ** -0.5], "--", color="0.45", lw=1.5, label="slope -1/2 (guide)")
    kind = rows["budget_kind"][0]
    ax.set_xlabel({"samples": "samples per pixel (spp)", "fetches": "fetches per pixel"}.get(kind, kind))
    ax.set_ylabel("RMSE")
    title = f"{os.path.basename(os.path.normpath(args.results))}: RMSE vs budget, {args.testbed} / {args.variant}"
    ax.set_title(title + ("\nshaded: 90% bootstrap interval over repetition blocks" if banded else ""))
    ax.grid(True, which="both", color="0.92")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=9, frameon=False)
    # Written atomically: a temporary file beside the output, renamed over it.
    out_dir = os.path.dirname(os.path.abspath(args.out))
    suffix = os.path.splitext(args.out)[1] or ".png"
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix=".redraw-", suffix=suffix)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=100)
        os.replace(tmp, args.out)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(f"{args.out}: {len(estimators)} estimators on {args.testbed}/{args.variant}")


if __name__ == "__main__":
    main()
