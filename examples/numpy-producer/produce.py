#!/usr/bin/env python3
"""A renderer stand-in in NumPy only: writes per-repetition estimates for `mcbench ingest`.

The "scene" is a smooth 16x16 RGB image whose exact value per pixel is known here. Two
estimators are drawn at 16, 64 and 256 samples per pixel, 64 repetitions each:

* `numpy_unbiased`: the exact value plus zero-mean noise whose variance falls as 1/samples;
* `numpy_biased`:   the same with every estimate 1% too high (a control that must be flagged).

The reference mcbench compares them with is an image of its own: the exact value plus the noise
of a 65536-sample render, written with that noise's per-pixel variance (`ref.npy`, `ref_var.npy`).
A second folder holds a scalar series of the same two estimators on four integrals (CSV), with a
1x4 reference image and 1024 repetitions. Each repetition's seconds are measured with
`time.perf_counter`.

    python3 produce.py OUT [--seed N]

writes OUT/images/manifest.toml and OUT/scalars/manifest.toml (experiment names `numpy-images`
and `numpy-scalars`). The seed draws the estimates; the references are drawn from a fixed seed,
so that producers run at two seeds share them (`mcbench compare --two-sample` pairs such runs).
"""
import argparse
import os
import time

import numpy as np

SIDE = 16
REPS = 64
SCALAR_REPS = 1024
REFERENCE_SEED = 12345
BUDGETS = [16, 64, 256]
REFERENCE_SAMPLES = 65536
SIGMA = 0.5  # per-sample standard deviation, relative to the pixel's value
ESTIMATORS = [("numpy_unbiased", "unbiased", 0.0), ("numpy_biased", "biased", 0.01)]


def truth_image():
    """The exact image, row 0 at the top: red grows left to right, green top to bottom."""
    rows, cols = np.mgrid[0:SIDE, 0:SIDE]
    red = 0.2 + 0.6 * (cols + 0.5) / SIDE
    green = 0.3 + 0.5 * (rows + 0.5) / SIDE
    blue = np.full((SIDE, SIDE), 0.5)
    return np.stack([red, green, blue], axis=-1)


def draw(rng, truth, samples, bias):
    """One repetition: the mean of `samples` samples of a noisy estimator of `truth`."""
    noise = rng.standard_normal(truth.shape) * SIGMA * truth / np.sqrt(samples)
    return truth * (1.0 + bias) + noise


def write_reference(folder, truth):
    rng = np.random.default_rng(REFERENCE_SEED)
    var = (SIGMA * truth) ** 2 / REFERENCE_SAMPLES
    np.save(os.path.join(folder, "ref.npy"), draw(rng, truth, REFERENCE_SAMPLES, 0.0))
    np.save(os.path.join(folder, "ref_var.npy"), var)


def manifest_head(name):
    """The manifest's first lines: the experiment name and the reference image with its variance."""
    return [f'name = "{name}"', "", "[reference]", 'image = "ref.npy"', 'variance = "ref_var.npy"',
            f"samples = {REFERENCE_SAMPLES}"]


def images(out, rng, name):
    folder = os.path.join(out, "images")
    os.makedirs(folder, exist_ok=True)
    truth = truth_image()
    write_reference(folder, truth)
    lines = manifest_head(name)
    for est, bias_word, bias in ESTIMATORS:
        lines += ["", "[[estimators]]", f'id = "{est}"', f'bias = "{bias_word}"']
        for spp in BUDGETS:
            sub = os.path.join(est, f"spp{spp}")
            os.makedirs(os.path.join(folder, sub), exist_ok=True)
            seconds = []
            for rep in range(REPS):
                t0 = time.perf_counter()
                img = draw(rng, truth, spp, bias).astype(np.float32)
                seconds.append(time.perf_counter() - t0)
                np.save(os.path.join(folder, sub, f"rep-{rep:04}.npy"), img)
            with open(os.path.join(folder, sub, "seconds.csv"), "w") as f:
                f.write("rep,seconds\n" + "".join(f"{r},{s:.9g}\n" for r, s in enumerate(seconds)))
            lines += ["[[estimators.budgets]]", f"samples = {spp}", f'files = "{sub}/rep-{{rep:04}}.npy"',
                      f"reps = {REPS}", f'seconds = "{sub}/seconds.csv"']
    # Claims judged on the ingested run, as in a config file; an image reference's test bed is
    # `reference-image/<the image's path>`.
    lines += ["", "[[claims]]", 'kind = "slope"', 'testbed = "reference-image/ref.npy"',
              'estimator = "numpy_unbiased"', "value = -0.5",
              'text = "independent noise: RMSE falls as samples^-1/2"',
              "", "[[claims]]", 'kind = "control_flagged"', 'estimator = "numpy_biased"']
    with open(os.path.join(folder, "manifest.toml"), "w") as f:
        f.write("\n".join(lines) + "\n")


def scalars(out, rng, name):
    folder = os.path.join(out, "scalars")
    os.makedirs(folder, exist_ok=True)
    truth = np.array([[1.0, 2.0, 0.5, 3.0]])  # one row of four integrals
    write_reference(folder, truth)
    lines = manifest_head(name)
    for est, bias_word, bias in ESTIMATORS:
        lines += ["", "[[estimators]]", f'id = "{est}"', f'bias = "{bias_word}"']
        for spp in BUDGETS:
            rows = ["rep,v0,v1,v2,v3,seconds"]
            for rep in range(SCALAR_REPS):
                t0 = time.perf_counter()
                v = draw(rng, truth, spp, bias)[0]
                s = time.perf_counter() - t0
                rows.append(f"{rep}," + ",".join(f"{x:.17g}" for x in v) + f",{s:.9g}")
            path = f"{est}-spp{spp}.csv"
            with open(os.path.join(folder, path), "w") as f:
                f.write("\n".join(rows) + "\n")
            lines += ["[[estimators.budgets]]", f"samples = {spp}", f'files = "{path}"', f"reps = {SCALAR_REPS}"]
    with open(os.path.join(folder, "manifest.toml"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    images(a.out, rng, "numpy-images")
    scalars(a.out, rng, "numpy-scalars")
    print(f"wrote {a.out}/images/manifest.toml and {a.out}/scalars/manifest.toml")


if __name__ == "__main__":
    main()
