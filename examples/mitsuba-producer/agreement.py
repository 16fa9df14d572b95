#!/usr/bin/env python3
"""Long-render agreement: an exported scene rendered at many samples per pixel against the
reference `mcbench export` wrote beside it (`reference.npy`, and `reference_var.npy` for stored
references), within their error bars.

    python3 agreement.py SCENE [--spp 16384] [--batches 8] [--integrator path|clamped]

Each pixel is rendered in `--batches` independent batches of `--spp` samples (distinct seeds);
the batch spread gives the standard error of the pixel's mean. Per pixel and channel,
`z = (mean - reference) / sqrt(se^2 + reference variance)`. Pixels are independent, the channels
of one pixel are not (the same paths), so the script prints, per channel, the mean of z^2 over
the pixels, which is about (B - 1) / (B - 3) for B batches when the render agrees (z is then a
Student t with B - 1 degrees of freedom when the reference's variance is small), with the
chi-square p-value of the sum of z^2 scaled by (B - 3) / (B - 1), the largest |z|, and the
mean relative difference over the image (inverse-variance weighted) with its standard error.
"""
import argparse
import math
import os
import time

import numpy as np

import render  # noqa: E402  (sets the variant, registers the clamped integrator)

mi = render.mi


def chi2_sf(x, k):
    """P(chi2_k >= x) by the Wilson-Hilferty approximation (k in the hundreds here)."""
    z = ((x / k) ** (1 / 3) - (1 - 2 / (9 * k))) / math.sqrt(2 / (9 * k))
    return 0.5 * math.erfc(z / math.sqrt(2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("--batches", type=int, default=8)
    ap.add_argument("--integrator", choices=["path", "clamped"], default="path", help="path: the scene's own")
    ap.add_argument("--clamp", type=float, default=1.6)
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args()
    scene = mi.load_file(os.path.join(a.scene, "scene.xml"))
    ref = np.load(os.path.join(a.scene, "reference.npy"))
    var_path = os.path.join(a.scene, "reference_var.npy")
    ref_var = np.load(var_path) if os.path.exists(var_path) else np.zeros_like(ref)
    side = ref.shape[0]
    integrator = dict((n.split("_")[1], i) for n, _, i in render.integrators(scene, a.clamp))[a.integrator]
    t0 = time.perf_counter()
    batches = np.stack([
        render.render_image(scene, integrator, a.spp, (a.seed * a.batches + b) * side * side, side)
        for b in range(a.batches)
    ]).astype(np.float64)
    seconds = time.perf_counter() - t0
    mean = batches.mean(0)
    se2 = batches.var(0, ddof=1) / a.batches
    z = (mean - ref) / np.sqrt(se2 + ref_var)
    expected = (a.batches - 1) / (a.batches - 3)
    rel = (mean - ref) / ref
    rel_se = np.sqrt(se2 + ref_var) / np.abs(ref)
    px = side * side
    label = str(integrator).split("[")[0] if a.integrator == "path" else f"clamped at {a.clamp}"
    print(f"{a.scene}: {side}x{side} pixels, {label}, {a.batches} x {a.spp} spp per pixel, {seconds:.1f} s")
    for c, name in enumerate("RGB"):
        zc = z[..., c].ravel()
        q = float(np.mean(zc ** 2))
        p = chi2_sf(q * px / expected, px)
        w = 1 / rel_se[..., c] ** 2
        pooled, pooled_se = float(np.sum(w * rel[..., c]) / np.sum(w)), float(1 / math.sqrt(np.sum(w)))
        print(f"  {name}: mean z^2 = {q:.3f} (expected {expected:.3f}; p = {p:.3f}), max |z| = {np.abs(zc).max():.2f}; "
              f"relative difference {pooled:+.2e} +- {pooled_se:.1e}")


if __name__ == "__main__":
    main()
