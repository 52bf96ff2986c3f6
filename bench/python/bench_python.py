#!/usr/bin/python3
"""Python against C++ and Embree: Mrays/s of hprt.RaycastingScene.cast_rays on
the same rays as `hprt trace` (the C++ command, same mesh, same backend), and
of an Embree-backed scene in the same process. Prints thread count, triangle
count, medians and the ratios; the Python overhead is python / C++ time - 1,
the median over repetitions of back-to-back pairs.

Usage: bench_python.py MESH [--rays N] [--kind random] [--repeat R] [--threads T] [--hprt PATH]
(PYTHONPATH must reach the hprt module: BUILD/python, or an installed prefix's
lib/python3/dist-packages.)"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import hprt


def read_rays(path):
    """A .rays file (32-byte records: org, tnear, dir, tfar) as (N, 6) float32."""
    raw = np.fromfile(path, dtype=np.float32).reshape(-1, 8)
    return np.ascontiguousarray(raw[:, [0, 1, 2, 4, 5, 6]])


def cpp_trace_ms(hprt_bin, mesh, rays_path, backend, threads, out_dir):
    """The median of three traces in one `hprt trace` process: warm, as the
    Python scene is after its first call."""
    r = subprocess.run([hprt_bin, "trace", mesh, "--rays", rays_path, "--backend", backend,
                        "--threads", str(threads), "--repeat", "3", "--json", "-o",
                        os.path.join(out_dir, "h.hits")],
                       check=True, capture_output=True, text=True)
    return json.loads(r.stdout)["ms"]


def python_ms(scene, rays):
    """The median of three back-to-back calls, as cpp_trace_ms times three
    traces in one process (each call makes fresh result arrays)."""
    times = []
    for _ in range(3):
        start = time.perf_counter()
        scene.cast_rays(rays)
        times.append(1e3 * (time.perf_counter() - start))
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--kind", default="random")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="0 = every hardware thread")
    ap.add_argument("--hprt", default="hprt", help="the hprt command")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rays_path = os.path.join(tmp, "b.rays")
        subprocess.run([a.hprt, "rays", a.mesh, "--kind", a.kind, "-n", str(a.rays), "-o",
                        rays_path], check=True, capture_output=True)
        rays = read_rays(rays_path)
        vertices, triangles = hprt.load_mesh(a.mesh)
        scenes = {}
        for backend in ("bvh", "embree"):
            s = hprt.RaycastingScene(nthreads=a.threads, backend=backend)
            s.add_triangles(vertices, triangles)
            s.cast_rays(rays[:1])  # builds
            scenes[backend] = s
        times = {"python bvh": [], "python embree": [], "C++ hprt trace bvh": []}
        for _ in range(a.repeat):  # alternating, so load changes hit all alike
            times["python bvh"].append(python_ms(scenes["bvh"], rays))
            times["python embree"].append(python_ms(scenes["embree"], rays))
            times["C++ hprt trace bvh"].append(
                cpp_trace_ms(a.hprt, a.mesh, rays_path, "bvh", a.threads, tmp))
    threads = a.threads or os.cpu_count()
    print(f"bench_python: {a.mesh}, {len(triangles):,} triangles, {len(rays):,} {a.kind} rays, "
          f"{threads} threads, median of {a.repeat} (hprt {hprt.__version__})")
    med = {k: statistics.median(v) for k, v in times.items()}
    for k, ms in med.items():
        print(f"  {k:<22} {ms:9.1f} ms  {len(rays) / (ms * 1e3):7.2f} Mrays/s")
    # Each repetition's Python and C++ runs are back to back, so their ratio
    # sees the same machine load; the median of those ratios is the figure.
    pairs = [p / c for p, c in zip(times["python bvh"], times["C++ hprt trace bvh"])]
    over = statistics.median(pairs) - 1.0
    print(f"  python bvh / C++ hprt trace time, median of the {a.repeat} paired ratios: "
          f"{1 + over:.3f} (overhead {100 * over:+.1f}%, aim <= 5%; "
          f"pairs {min(pairs):.3f}-{max(pairs):.3f})")
    print(f"  python bvh / python embree speed: {med['python embree'] / med['python bvh']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
