#!/usr/bin/env python3
"""The exported sky's discretisation error: Mitsuba's `envmap` of an exported scene (its bitmap,
interpolated as Mitsuba does) against the exact gradient `max(0, c0 + c1 w_z + c2 w_x)` of the
test beds (book: testbeds.md), at uniformly random directions.

    python3 sky_error.py SCENE [--directions 20000] [--require-upper MAX]

prints the largest and the mean absolute error per channel over the whole sphere (what the box
sees) and over the upper hemisphere (what the plane sees); with `--require-upper` it exits 1 when
the largest error over the upper hemisphere exceeds MAX (a bitmap in the wrong layout does).
"""
import argparse
import os

import numpy as np

import render  # noqa: E402  (sets the variant)

mi = render.mi
C0, C1, C2 = np.array([1.0, 0.8, 0.6]), np.array([1.0, 1.2, 1.5]), np.array([0.5, 0.0, -0.4])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--directions", type=int, default=20000)
    ap.add_argument("--require-upper", type=float)
    a = ap.parse_args()
    emitter = mi.load_file(os.path.join(a.scene, "scene.xml")).emitters()[0]
    d = np.random.default_rng(1).standard_normal((a.directions, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    err = np.empty((a.directions, 3))
    for n, w in enumerate(d):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*(-w))
        err[n] = np.array(emitter.eval(si)) - np.maximum(0.0, C0 + C1 * w[2] + C2 * w[0])
    for label, sel in [("sphere", np.ones(len(d), bool)), ("upper hemisphere", d[:, 2] > 0)]:
        e = np.abs(err[sel])
        print(f"{label}: max |error| {e.max():.2e}, mean |error| per channel "
              + ", ".join(f"{m:.2e}" for m in e.mean(0)) + f" ({sel.sum()} directions)")
    upper = float(np.abs(err[d[:, 2] > 0]).max())
    if a.require_upper is not None and not upper <= a.require_upper:
        raise SystemExit(f"sky bitmap: largest error over the upper hemisphere {upper:.2e} > {a.require_upper:.2e}")


if __name__ == "__main__":
    main()
