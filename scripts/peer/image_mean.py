#!/usr/bin/env python3
"""Image mean per channel and its standard error from an mcbench integrals.csv or integrals.csv.gz
(pixels are independent: se = sqrt(sum se_i^2) / pixels), per test bed variant, with the
reference's mean.
    python3 scripts/peer/image_mean.py /tmp/peer-ours/peer-gradient-box/integrals.csv.gz"""
import csv
import gzip
import math
import sys
from collections import defaultdict

acc = defaultdict(lambda: [0.0, 0.0, 0.0, 0])
opener = gzip.open if sys.argv[1].endswith(".gz") else open
for r in csv.DictReader(opener(sys.argv[1], "rt", newline="")):
    a = acc[(r["variant"], r["estimator"], int(r["channel"]))]
    a[0] += float(r["mean"])
    a[1] += float(r["std_err"]) ** 2
    a[2] += float(r["reference"])
    a[3] += 1
for (variant, est, ch), (m, v, ref, n) in sorted(acc.items()):
    print(f"{variant} {est} channel {ch}: mean {m / n:.5f} +- {math.sqrt(v) / n:.5f} (reference mean {ref / n:.5f})")
