#!/usr/bin/env python3
"""Unit costs of a real renderer: Mitsuba 3 ray casts and grid-volume lookups, ns per CPU thread.

Not built or run by cargo. Run `scripts/peer/ray_cost.sh` (from the repository root): it installs
Mitsuba and libLLVM 19 if they are missing, sets DRJIT_LIBLLVM_PATH (Dr.Jit 1.x emits intrinsics
that libLLVM 14/15 cannot compile) and runs this at nice 5. docs/src/cost_model_source.md explains the
figures; this script writes them to scripts/peer/ray_cost.json.

What is timed (llvm_ad_rgb variant, Dr.Jit thread pool set to ONE thread with
`dr.set_thread_count(1)`; the DRJIT_NUM_THREADS environment variable is not honoured by
Dr.Jit 1.5, dr.thread_count() still reports the core count with it):
- rays: wavefronts of --rays rays (default 2^20) with origins uniform in [-0.99, 0.99]^3 (inside the
  Cornell box, some inside its boxes / the extra mesh) and directions uniform on the sphere,
  precomputed and evaluated before timing, so that the timed kernel reads the rays from memory.
  * closest_hit: `scene.ray_intersect(ray)`, evaluating the fields of the SurfaceInteraction a
    path tracer consumes (t, p, n, sh_frame.n, uv, wi): Embree traversal + hit-record work;
  * closest_hit_preliminary: `scene.ray_intersect_preliminary(ray)` (t, prim_index only);
  * closest_hit_full_si: `scene.ray_intersect(ray)` with every SurfaceInteraction field
    evaluated (stores ~40 floats per ray: a memory-bound upper figure);
  * shadow: `scene.ray_test(ray)` (any hit, boolean result);
  * baseline: a kernel that only reads the same rays and writes one float per ray.
- fetch: `gridvolume` (1 channel, trilinear, random values in [0, 1), N^3 voxels) `eval_1` at
  --fetches points uniform in the unit cube, + the same baseline.
Each measurement runs once untimed (JIT compilation, kernel cache), then --repeats timed runs, each
tracing the expression, `dr.eval` and `dr.sync_thread`; the median is reported. CPU time is
`time.process_time()` of the whole process (the primary figure: the machine may be shared);
wall time and Dr.Jit's own kernel execution time (KernelHistory, excludes Python tracing) are
reported beside it.
Optionally (--scalar N) the scalar_rgb variant in a Python loop: Python call overhead dominates
and cannot be separated, so it is reported only as an upper bound, labelled as such.
"""
import argparse
import datetime
import json
import os
import platform
import shlex
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def cpu_info():
    """model name, family/model numbers and the widest SIMD flag of the first CPU in /proc/cpuinfo"""
    info = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if not line.strip():
                    break
                k, _, v = line.partition(":")
                info[k.strip()] = v.strip()
    except OSError:
        pass
    flags = info.get("flags", "").split()
    simd = next((x for x in ("avx512f", "avx2", "avx", "sse4_2") if x in flags), "none")
    return {
        "cpu_model": info.get("model name", platform.processor() or "unknown"),
        "cpu_family_model": f"family {info.get('cpu family', '?')} model {info.get('model', '?')}",
        "cpu_simd": simd,
    }


def timed(dr, make, count, repeats):
    """make() traces the expression and returns what to evaluate. One untimed warm-up run (JIT
    compilation), then `repeats` timed runs; medians in ns per item."""
    dr.eval(make())
    dr.sync_thread()
    wall, cpu, kern = [], [], []
    for _ in range(repeats):
        dr.kernel_history()  # clear
        t0, c0 = time.perf_counter(), time.process_time()
        out = make()
        dr.eval(out)
        dr.sync_thread()
        w, c = time.perf_counter() - t0, time.process_time() - c0
        hist = dr.kernel_history()
        wall.append(w * 1e9 / count)
        cpu.append(c * 1e9 / count)
        kern.append(sum(float(k.get("execution_time", 0.0)) for k in hist) * 1e6 / count)
        del out
    return {
        "cpu_ns": statistics.median(cpu),
        "wall_ns": statistics.median(wall),
        "kernel_ns": statistics.median(kern),
        "cpu_ns_all": [round(x, 2) for x in cpu],
    }


def bumpy_sphere(mi, dr, n_phi, n_theta, radius, centre):
    """Lat-long sphere mesh with a bumpy radius, 2 * n_phi * (n_theta - 1) triangles (poles are
    single vertices), smooth vertex normals."""
    th = np.linspace(0, np.pi, n_theta + 1)[1:-1]  # interior rings
    ph = np.linspace(0, 2 * np.pi, n_phi, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    r = radius * (1 + 0.08 * np.sin(7 * P) * np.sin(5 * T) + 0.04 * np.cos(23 * P + 11 * T))
    ring = np.stack([r * np.sin(T) * np.cos(P), r * np.cos(T), r * np.sin(T) * np.sin(P)], -1).reshape(-1, 3)
    verts = np.concatenate([[[0, radius, 0]], ring, [[0, -radius, 0]]]) + np.asarray(centre)
    nr, top, bot = n_theta - 1, 0, 1 + (n_theta - 1) * n_phi
    idx = lambda i, j: 1 + i * n_phi + (j % n_phi)  # noqa: E731
    j = np.arange(n_phi)
    faces = [np.stack([np.full(n_phi, top), idx(0, j + 1), idx(0, j)], -1)]
    for i in range(nr - 1):
        a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
        faces += [np.stack([a, b, d], -1), np.stack([a, d, c], -1)]
    faces.append(np.stack([np.full(n_phi, bot), idx(nr - 1, j), idx(nr - 1, j + 1)], -1))
    faces = np.concatenate(faces).astype(np.uint32)
    mesh = mi.Mesh("bumpy_sphere", len(verts), len(faces), has_vertex_normals=True)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(verts.astype(np.float32).ravel())
    params["faces"] = mi.UInt32(faces.ravel())
    params.update()  # rebuilds bbox and vertex normals
    return mesh


def scene_triangles(scene):
    return int(sum(s.face_count() for s in scene.shapes() if s.is_mesh()))


def random_rays(mi, n, seed):
    rng = np.random.default_rng(seed)
    o = rng.uniform(-0.99, 0.99, (n, 3)).astype(np.float32)
    d = rng.normal(size=(n, 3))
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    return o, d


def measure_rays(mi, dr, scene, n, repeats, seed):
    o_np, d_np = random_rays(mi, n, seed)
    o = mi.Point3f(*(mi.Float(o_np[:, k]) for k in range(3)))
    d = mi.Vector3f(*(mi.Float(d_np[:, k]) for k in range(3)))
    dr.eval(o, d)
    dr.sync_thread()

    def ray():
        return mi.Ray3f(o, d)

    def used_fields():
        si = scene.ray_intersect(ray())
        return si.t, si.p, si.n, si.sh_frame.n, si.uv, si.wi

    def prelim():
        pi = scene.ray_intersect_preliminary(ray())
        return pi.t, pi.prim_index

    out = {
        "baseline": timed(dr, lambda: o.x + o.y + o.z + d.x + d.y + d.z, n, repeats),
        "closest_hit": timed(dr, used_fields, n, repeats),
        "closest_hit_preliminary": timed(dr, prelim, n, repeats),
        "closest_hit_full_si": timed(dr, lambda: scene.ray_intersect(ray()), n, repeats),
        "shadow": timed(dr, lambda: scene.ray_test(ray()), n, repeats),
    }
    si = scene.ray_intersect(ray())
    out["hit_fraction"] = float(np.array(si.is_valid()).mean())
    return out


def measure_fetch(mi, dr, res, n, repeats, seed):
    rng = np.random.default_rng(seed)
    grid = rng.random((res, res, res, 1), dtype=np.float32)
    vol = mi.load_dict({"type": "gridvolume", "grid": mi.VolumeGrid(grid), "filter_type": "trilinear"})
    p_np = rng.random((n, 3), dtype=np.float32)
    it = dr.zeros(mi.Interaction3f, n)
    it.p = mi.Point3f(*(mi.Float(p_np[:, k]) for k in range(3)))
    dr.eval(it.p)
    dr.sync_thread()
    # check one value against a numpy trilinear lookup (cell-centred voxels, clamped)
    q = (p_np[0] * res - 0.5).clip(0, res - 1)
    i0 = np.floor(q).astype(int).clip(0, res - 2)
    f = q - i0
    ref = 0.0
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                w = (f[0] if dx else 1 - f[0]) * (f[1] if dy else 1 - f[1]) * (f[2] if dz else 1 - f[2])
                ref += w * grid[i0[2] + dz, i0[1] + dy, i0[0] + dx, 0]
    got = float(np.array(vol.eval_1(it))[0])
    return {
        "grid": f"{res}^3 float32, 1 channel, trilinear, {grid.nbytes / 2**20:.1f} MiB",
        "baseline": timed(dr, lambda: it.p.x + it.p.y + it.p.z, n, repeats),
        "fetch": timed(dr, lambda: vol.eval_1(it), n, repeats),
        "check_first_point": {"mitsuba": got, "numpy_trilinear": float(ref)},
    }


def measure_scalar(mi, n, seed):
    """scalar_rgb in a Python loop: an UPPER BOUND (Python call overhead dominates)."""
    mi.set_variant("scalar_rgb")
    scene = mi.load_dict(mi.cornell_box())
    o_np, d_np = random_rays(mi, n, seed)
    rays = [mi.Ray3f(mi.Point3f(*map(float, o)), mi.Vector3f(*map(float, d))) for o, d in zip(o_np, d_np)]
    res = {}
    for name, fn in [
        ("python_loop_only", lambda r: r.o),
        ("closest_hit", lambda r: scene.ray_intersect(r).t),
        ("shadow", lambda r: scene.ray_test(r)),
    ]:
        for r in rays[:1000]:
            fn(r)
        c0 = time.process_time()
        for r in rays:
            fn(r)
        res[name + "_cpu_ns"] = (time.process_time() - c0) * 1e9 / n
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rays", type=int, default=1 << 20, help="rays per wavefront")
    ap.add_argument("--fetches", type=int, default=1 << 20, help="grid lookups per wavefront")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--mesh-triangles", default="262144,1048576",
                    help="comma list: extra scenes = Cornell box + a bumpy sphere of about this many triangles")
    ap.add_argument("--grids", default="64,128,256", help="comma list of grid resolutions N (N^3 voxels)")
    ap.add_argument("--scalar", type=int, default=20000, help="rays for the scalar upper bound (0: skip)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(HERE, "ray_cost.json"))
    a = ap.parse_args()

    import drjit as dr
    import mitsuba as mi

    variant = "llvm_ad_rgb"
    mi.set_variant(variant)
    dr.set_thread_count(1)
    assert dr.thread_count() == 1, dr.thread_count()
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    load0 = os.getloadavg()

    scenes = []
    base = mi.cornell_box()
    scenes.append(("cornell_box", "mi.cornell_box(): 5 walls, light, 2 boxes (rectangles and cubes as meshes)", base))
    for tri in [int(x) for x in a.mesh_triangles.split(",") if x]:
        n_theta = max(4, int(round((tri / 4) ** 0.5)))
        n_phi = 2 * n_theta
        d = dict(base)
        d["bumpy_sphere"] = bumpy_sphere(mi, dr, n_phi, n_theta, 0.45, [0.0, 0.05, 0.0])
        scenes.append((f"cornell_box+sphere{tri}", f"mi.cornell_box() + bumpy lat-long sphere mesh ({n_phi}x{n_theta}, radius 0.45, centre of the box)", d))

    results = {"scenes": [], "fetch": []}
    for name, desc, sd in scenes:
        t0 = time.perf_counter()
        scene = mi.load_dict(sd)
        build = time.perf_counter() - t0
        r = measure_rays(mi, dr, scene, a.rays, a.repeats, a.seed)
        entry = {"name": name, "description": desc, "triangles": scene_triangles(scene),
                 "shapes": len(scene.shapes()), "load_and_bvh_build_s": round(build, 3), **r}
        results["scenes"].append(entry)
        print(f"{name}: {entry['triangles']} triangles, closest hit {r['closest_hit']['cpu_ns']:.1f} ns/ray, "
              f"shadow {r['shadow']['cpu_ns']:.1f} ns/ray (baseline {r['baseline']['cpu_ns']:.1f}, cpu time)", flush=True)
        del scene
    for res in [int(x) for x in a.grids.split(",") if x]:
        f = measure_fetch(mi, dr, res, a.fetches, a.repeats, a.seed)
        f["resolution"] = res
        results["fetch"].append(f)
        print(f"gridvolume {res}^3: {f['fetch']['cpu_ns']:.1f} ns/fetch (baseline {f['baseline']['cpu_ns']:.1f}, cpu time)", flush=True)

    scalar = None
    if a.scalar > 0:
        scalar = {"note": "UPPER BOUND: scalar_rgb called from a Python loop, Python call overhead included and not separable",
                  "rays": a.scalar, "scene": "cornell_box", **measure_scalar(mi, a.scalar, a.seed)}
        print(f"scalar_rgb python loop (upper bound): closest hit {scalar['closest_hit_cpu_ns']:.0f} ns/ray, "
              f"shadow {scalar['shadow_cpu_ns']:.0f}, loop alone {scalar['python_loop_only_cpu_ns']:.0f}", flush=True)

    cmd = " ".join(shlex.quote(x) for x in [sys.executable, *sys.argv])
    env = " ".join(f"{k}={shlex.quote(os.environ[k])}" for k in ("DRJIT_LIBLLVM_PATH",) if k in os.environ)
    primary = results["scenes"][0]
    out = {
        "what": "ns of ONE CPU thread per operation, Mitsuba 3 llvm_ad_rgb wavefronts (amortized throughput)",
        "mitsuba_version": mi.__version__,
        "drjit_version": dr.__version__,
        "llvm_version": ".".join(map(str, dr.detail.llvm_version())),
        "embree": bool(getattr(mi, "MI_ENABLE_EMBREE", False)),
        "variant": variant,
        "thread_count": dr.thread_count(),
        "thread_control": "dr.set_thread_count(1) (DRJIT_NUM_THREADS is not honoured by this Dr.Jit)",
        "rays_per_wavefront": a.rays,
        "fetches_per_wavefront": a.fetches,
        "repeats": a.repeats,
        "statistic": "median over repeats after one untimed warm-up; cpu_ns = time.process_time(), wall_ns = time.perf_counter(), kernel_ns = Dr.Jit KernelHistory execution time",
        "summary_cpu_ns": {
            "ray_closest_hit": {s["name"]: round(s["closest_hit"]["cpu_ns"], 1) for s in results["scenes"]},
            "ray_shadow": {s["name"]: round(s["shadow"]["cpu_ns"], 1) for s in results["scenes"]},
            "fetch_gridvolume": {f"{f['resolution']}^3": round(f["fetch"]["cpu_ns"], 1) for f in results["fetch"]},
            "default_ray": round(primary["closest_hit"]["cpu_ns"], 1),
            "default_shadow_ray": round(primary["shadow"]["cpu_ns"], 1),
            "default_fetch": round(results["fetch"][0]["fetch"]["cpu_ns"], 1) if results["fetch"] else None,
        },
        **results,
        "scalar_upper_bound": scalar,
        **cpu_info(),
        "logical_cpus": os.cpu_count(),
        "load_average_at_start": [round(x, 2) for x in load0],
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": os.environ.get("RAY_COST_COMMAND") or ((env + " " if env else "") + cmd),
    }
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
