#!/usr/bin/env python3
"""Python path against the CLI: the same rays, tree and mode, one thread.

    PYTHONPATH=build/python python3 bench/python_overhead.py build/apps/bsprt ../shared/scenes/stanford-bunny.obj -n 1000000

A benchmark, not a test: prints the CLI's trace seconds (its own timer, around
the traversal only), the Python call's wall time for intersect_rays (rays
already an (N, 8) float32 array: no copy) and for intersect (origins and
directions packed first), best of 3, and checks the hits are the same bytes.
"""
import argparse
import os
import re
import subprocess
import tempfile
import time

import numpy as np

import bsprt


def best(f, runs=3):
    out, t = None, float("inf")
    for _ in range(runs):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return out, t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("cli")
    ap.add_argument("mesh")
    ap.add_argument("-n", type=int, default=1000000)
    ap.add_argument("--kind", default="random")
    ap.add_argument("--accel", default="bsp")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rays_p, tree_p, hits_p = (os.path.join(tmp, x) for x in ("r.rays", "t.tree", "h.hits"))
        subprocess.run([args.cli, "gen-rays", args.mesh, "--kind", args.kind, "-n", str(args.n), "-o", rays_p],
                       check=True, capture_output=True)
        subprocess.run([args.cli, "build", args.mesh, "--accel", "bsp" if args.accel.startswith("bsp") else "kd",
                        "-o", tree_p], check=True, capture_output=True)
        cli_s = float("inf")
        for _ in range(3):
            out = subprocess.run([args.cli, "trace", args.mesh, rays_p, "-o", hits_p, "--accel", args.accel,
                                  "--tree", tree_p, "--threads", "1"], check=True, capture_output=True, text=True)
            cli_s = min(cli_s, float(re.search(r"trace ([0-9.]+) s", out.stdout).group(1)))
        scene = bsprt.Scene.load(args.mesh)
        tracer = bsprt.Tracer(scene, bsprt.Tree.load(tree_p, scene), mode=args.accel)
        rays = bsprt.read_rays(rays_p)
        hits, py_rays = best(lambda: tracer.intersect_rays(rays, threads=1))
        hits2, py_od = best(lambda: tracer.intersect(rays[:, 0:3], rays[:, 4:7], rays[:, 3], rays[:, 7], threads=1))
        same = hits.records.tobytes() == bsprt.read_hits(hits_p).tobytes() == hits2.records.tobytes()
    n = len(rays)
    print(f"{n} {args.kind} rays, {args.accel}, 1 thread, best of 3; hits identical to the CLI's: {same}")
    print("| path | seconds | ns/ray | vs CLI |\n|---|---:|---:|---:|")
    for name, s in (("bsprt trace (CLI timer)", cli_s), ("Tracer.intersect_rays", py_rays),
                    ("Tracer.intersect (pack origins, directions)", py_od)):
        print(f"| {name} | {s:.3f} | {1e9 * s / n:.0f} | {s / cli_s:.2f}x |")


if __name__ == "__main__":
    main()
