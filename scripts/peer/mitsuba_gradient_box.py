#!/usr/bin/env python3
"""Peer comparison: Mitsuba 3's `volpath` on mcbench's `gradient-box` (docs/src/testbeds.md).

Not built or run by cargo. Setup (outside the repository):
    python3 -m venv /work/venv-mitsuba && /work/venv-mitsuba/bin/pip install mitsuba
    apt-get install libllvm19        # the LLVM variant needs libLLVM >= 19
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
Run (both variants, 2 threads, albedo 0.8 and 1):
    /work/venv-mitsuba/bin/python scripts/peer/mitsuba_gradient_box.py --variant llvm_ad_rgb --albedo 0.8
    /work/venv-mitsuba/bin/python scripts/peer/mitsuba_gradient_box.py --variant scalar_rgb --albedo 0.8
It prints camera paths per second of wall time and per CPU second of the process (all threads;
the machine is shared, so the second is the fairer one under load), after a warm-up render that
compiles the LLVM kernels, and the
image mean per channel with its standard error over the passes, as one JSON line.

The scene, as the test bed defines it (docs/src/testbeds.md):
- cube [-0.5, 0.5]^3 (Mitsuba `cube` scaled by 0.5) with a `null` BSDF (index-matched boundary)
  and a `homogeneous` interior medium: sigma_t = 2, albedo a (grey), isotropic phase;
- orthographic camera looking along +y from y = -1, covering x, z in [-0.5, 0.5], 16 x 16 pixels;
- background L_b(w) = max(0, c0 + c1 w_z + c2 w_x) per channel (gradient-plane's coefficients) over the
  whole sphere, w the direction of travel of the ray leaving the scene.
Differences from mcbench (stated in docs/src/performance.md):
- Mitsuba has no analytic-gradient emitter: the background is a lat-long `envmap` tabulated at
  the texel centres (--env-width x width/2, bilinear lookup); `--check` shows the lookup error.
- Mitsuba's film integrates each pixel's footprint (box filter, jittered positions); mcbench's
  pixel value is the pixel-centre ray. Every footprint lies inside the box, the image is smooth,
  and the midpoint-rule difference of the image mean is far below the error bars here.
- `volpath` samples the emitter at every scattering vertex (next-event estimation) and uses
  Russian roulette from depth 5; mcbench's `is0_cv0` is the plain free-flight + phase-sampling
  tracer of paper 000 (no NEE). Both are unbiased, so the image means must agree; a Mitsuba path
  does more work (and has lower variance) than one of ours.
"""
import argparse
import json
import math
import time

import numpy as np

C0 = np.array([1.0, 0.8, 0.6])
C1 = np.array([1.0, 1.2, 1.5])
C2 = np.array([0.5, 0.0, -0.4])


def background(wx, wy, wz):
    """The gradient background, clamped at 0 per channel; arrays of direction components."""
    return np.maximum(0.0, C0 + C1 * wz[..., None] + C2 * wx[..., None])


def envmap_bitmap(width):
    """Lat-long texels at their centres in Mitsuba's envmap convention: u = atan2(v.x, -v.z) / 2pi,
    v = acos(v.y) / pi in the emitter's local frame v. The emitter is rotated by -90 degrees about
    z (ENV_TO_WORLD: world = (v.y, -v.x, v.z)) so that the map's poles, where the bilinear lookup
    is least accurate, sit at +-x and not at +y, the direction every unscattered camera ray sees."""
    height = width // 2
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, theta = np.meshgrid(2 * math.pi * u, math.pi * v)
    wx, wy, wz = np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)
    return background(wy, -wx, wz).astype(np.float32)


def scene_dict(mi, albedo, spp, env_width, with_box=True, sensor=None):
    T = mi.ScalarTransform4f
    d = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": -1},
        "sensor": sensor
        or {
            "type": "orthographic",
            "to_world": T().look_at(origin=[0, -1, 0], target=[0, 0, 0], up=[0, 0, 1]) @ T().scale([0.5, 0.5, 1]),
            "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "env": {
            "type": "envmap",
            "bitmap": mi.Bitmap(envmap_bitmap(env_width)),
            "to_world": T().rotate(axis=[0, 0, 1], angle=-90),
        },
    }
    if with_box:
        d["box"] = {
            "type": "cube",
            "to_world": T().scale(0.5),
            "bsdf": {"type": "null"},
            "interior": {
                "type": "homogeneous",
                "sigma_t": 2.0,
                "albedo": {"type": "rgb", "value": [albedo] * 3},
                "phase": {"type": "isotropic"},
            },
        }
    return d


def check_background(mi, env_width):
    """The tabulated emitter seen directly along a few directions vs the analytic gradient."""
    T = mi.ScalarTransform4f
    worst = 0.0
    for d in [(0, 0, 1), (1, 0, 0), (0, 1, 0), (0.3, 0.8, 0.5), (0.6, 0.0, 0.8), (-0.48, 0.6, -0.64), (0.0, -0.6, 0.8)]:
        d = np.array(d, float) / np.linalg.norm(d)
        up = [0, 0, 1] if abs(d[2]) < 0.9 else [0, 1, 0]
        sensor = {
            "type": "perspective",
            "fov": 0.01,
            "to_world": T().look_at(origin=[0, 0, 0], target=d.tolist(), up=up),
            "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": 4},
        }
        scene = mi.load_dict(scene_dict(mi, 0.0, 4, env_width, with_box=False, sensor=sensor))
        got = np.array(mi.render(scene)).reshape(-1, 3)[0]
        want = background(np.array(d[0]), np.array(d[1]), np.array(d[2]))
        worst = max(worst, float(np.max(np.abs(got - want))))
        print(f"check direction {d.round(3).tolist()}: mitsuba {got.round(5).tolist()} exact {want.round(5).tolist()}")
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--albedo", type=float, default=0.8)
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel per pass")
    ap.add_argument("--passes", type=int, default=8, help="timed passes (the standard error is their spread)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--env-width", type=int, default=2048)
    ap.add_argument("--check", action="store_true", help="also compare the tabulated background with the exact one")
    a = ap.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant(a.variant)
    dr.set_thread_count(a.threads)
    check = check_background(mi, a.env_width) if a.check else None
    scene = mi.load_dict(scene_dict(mi, a.albedo, a.spp, a.env_width))
    np.array(mi.render(scene, spp=a.spp, seed=10_000))  # warm-up (LLVM: compiles the kernel)
    means, seconds, cpu = [], 0.0, 0.0
    for k in range(a.passes):
        t0, c0 = time.perf_counter(), time.process_time()
        img = np.array(mi.render(scene, spp=a.spp, seed=k))
        seconds += time.perf_counter() - t0
        cpu += time.process_time() - c0
        means.append(img.reshape(-1, 3).mean(axis=0))
    means = np.array(means)
    paths = 16 * 16 * a.spp * a.passes
    out = {
        "renderer": f"mitsuba {mi.__version__} {a.variant} volpath",
        "albedo": a.albedo,
        "threads": a.threads,
        "spp_per_pass": a.spp,
        "passes": a.passes,
        "seconds": seconds,
        "paths_per_second": paths / seconds,
        "cpu_seconds": cpu,
        "paths_per_cpu_second": paths / cpu,
        "image_mean": means.mean(axis=0).tolist(),
        "image_mean_se": (means.std(axis=0, ddof=1) / math.sqrt(a.passes)).tolist(),
        "background_check_max_abs_error": check,
    }
    print(json.dumps(out))


if __name__ == "__main__":
    main()
