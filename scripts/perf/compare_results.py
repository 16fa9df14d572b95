#!/usr/bin/env python3
"""Compares two results roots of the same suite (e.g. the quick suite before and after a change)
experiment by experiment, time-derived values aside:
- every CSV file of an experiment (summary.csv, integrals.csv or integrals.csv.gz, and the
  experiments' own tables; a gzip-compressed table is compared by its text with the plain one of
  the same name, and over the columns both sides have: the columns only one side has, such as the
  `params` columns older integrals.csv files repeated per row, are listed, not compared),
  with the columns named in harness/src/analysis/metrics.rs TIMING_COLUMNS (and the other time-derived
  names below) removed, cell by cell; tests.csv and claims.csv are left to the next point (they
  are summary.json's `tests` and `paper` as tables, and a time-derived claim's value may move);
- every claim's verdict and value in summary.json (`paper`), and the tests' verdicts and p-values.
Claims and table columns that are time-derived are listed apart: they move with machine load.
Prints one line per experiment and exits 1 if anything that is not time-derived differs.
Usage: compare_results.py RESULTS_A RESULTS_B"""
import csv
import gzip
import json
import pathlib
import sys

# TIMING_COLUMNS of harness/src/analysis/metrics.rs (timing_columns.txt beside this script, which a
# test keeps equal to the code's list), and the summary.json fields and table columns that are
# derived from measured time (as scripts/slurm/smoke_test.sh strips them).
TIMING_COLUMNS = set((pathlib.Path(__file__).parent / "timing_columns.txt").read_text().split())
TIMING = TIMING_COLUMNS | {"wall_seconds", "overhead", "speedup", "run_id", "overhead_wall", "speedup_wall",
                          "cpu_seconds_total", "speedup_ci_low", "speedup_ci_high", "overhead_renderer",
                          "speedup_renderer", "speedup_renderer_ci_low", "speedup_renderer_ci_high",
                          "break_even_ray_ns", "git_commit", "notes"}

# Tables that repeat summary.json's `tests` and `paper` (compared there, time-derived claims apart).
COPIES = {"tests.csv", "claims.csv"}


def timed(name):
    n = name.lower()
    return n in TIMING or "seconds" in n or "eff" in n or "speedup" in n or n.endswith("_s") or "time" in n


def rows_of(path):
    opener = gzip.open if path.name.endswith(".gz") else open
    return list(csv.reader(opener(path, "rt", newline="")))


def table(rows, other_header):
    """The rows without time-derived columns and without columns the other side lacks."""
    if not rows:
        return [], []
    keep = [i for i, h in enumerate(rows[0]) if not timed(h) and h in other_header]
    dropped = [h for h in rows[0] if timed(h)]
    return [[r[i] for i in keep if i < len(r)] for r in rows], dropped


def tables(d):
    """CSV tables of a results folder by name, a gzip-compressed one under its plain name."""
    out = {}
    for g in ("*.csv", "*.csv.gz"):
        for p in d.glob(g):
            out.setdefault(p.name.removesuffix(".gz"), p)
    return out


def verdict(c):
    if c.get("verdict"):
        return c["verdict"]
    if c.get("held") is None:
        return "reported" if c.get("our_value") is not None else "not measured"
    return "held" if c["held"] else "not held"


def timed_claim(c):
    """A claim judged on time: a cost regime (measured CPU time, or the renderer model, which adds
    the measured time to priced counts), or one about speed, efficiency or P-Eff."""
    if c.get("regime"):
        return True
    text = (c.get("claim", "") + " " + c.get("note", "")).lower()
    words = ("equal time", "speed-up", "speedup", "faster", "efficien", "p-eff", "p_eff", "cpu s", "seconds")
    return any(w in text for w in words)


def main(a, b):
    a, b = pathlib.Path(a), pathlib.Path(b)
    bad = 0
    for exp in sorted(p.name for p in a.iterdir() if (p / "summary.json").exists()):
        da, db = a / exp, b / exp
        notes = []
        if not (db / "summary.json").exists():
            print(f"{exp}: missing in {b}")
            bad += 1
            continue
        pa, pb = tables(da), tables(db)
        files = sorted((set(pa) | set(pb)) - COPIES)
        for f in files:
            if f not in pa or f not in pb:
                notes.append(f"{f} only in one")
                bad += 1
                continue
            ra, rb = rows_of(pa[f]), rows_of(pb[f])
            ha, hb = (ra[0] if ra else []), (rb[0] if rb else [])
            extra = sorted(set(ha) ^ set(hb))
            if extra:
                notes.append(f"{f}: columns only in one, not compared: {', '.join(extra)}")
            (ta, dropped), (tb, _) = table(ra, hb), table(rb, ha)
            if ta != tb:
                diff = sum(x != y for x, y in zip(ta, tb)) + abs(len(ta) - len(tb))
                notes.append(f"{f}: {diff} rows differ")
                bad += 1
        ja, jb = (json.load(open(d / "summary.json")) for d in (da, db))
        ca = {(c["testbed"], c["claim"], c.get("regime", "")): c for c in ja["paper"]}
        cb = {(c["testbed"], c["claim"], c.get("regime", "")): c for c in jb["paper"]}
        moved = []
        for k in sorted(set(ca) | set(cb)):
            x, y = ca.get(k), cb.get(k)
            if x is None or y is None:
                notes.append(f"claim only in one: {k[1][:60]}")
                bad += 1
            elif verdict(x) != verdict(y) or (x.get("our_value") != y.get("our_value") and not timed_claim(x)):
                if timed_claim(x):
                    moved.append(f"{k[1][:70]}: {verdict(x)} -> {verdict(y)}")
                else:
                    notes.append(f"claim differs: {k[1][:70]}: {verdict(x)} {x.get('our_value')} -> {verdict(y)} {y.get('our_value')}")
                    bad += 1
        ta = [(t["testbed"], t["variant"], t["estimator"], t["test"], t["verdict"], t["p_value"]) for t in ja["tests"]]
        tb = [(t["testbed"], t["variant"], t["estimator"], t["test"], t["verdict"], t["p_value"]) for t in jb["tests"]]
        if ta != tb:
            notes.append("tests differ")
            bad += 1
        same = sum(verdict(ca[k]) == verdict(cb[k]) for k in ca if k in cb)
        line = f"{exp}: {len(files)} tables, {len(ca)} claims ({same} same verdict), {len(ta)} tests"
        print(line + (": identical (time-derived values aside)" if not notes else ": " + "; ".join(notes)))
        for m in moved:
            print(f"  time-derived claim moved: {m}")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
