#!/usr/bin/env python3
"""docs/api.md's example: trace a mesh with several bsprt modes and Embree,
compare every mode with the exact reference, and plot the error per ray set.

    python3 docs/examples/error_per_ray_set.py ../shared/scenes/stanford-bunny.obj -n 50000 -o docs/images/api_error.png

Ray sets are made here with numpy: random rays through the scene's box, and
rays aimed exactly at vertices and at edge midpoints (where float tests lose
hits). Prints a table and writes a bar chart (matplotlib).
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bsprt  # noqa: E402


def load_vertices(scene, path):
    """The mesh's triangle corners (OBJ only, for aiming rays)."""
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            p = line.split()
            if p and p[0] == "v":
                v.append([float(x) for x in p[1:4]])
            elif p and p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                f += [[idx[0], idx[j], idx[j + 1]] for j in range(1, len(idx) - 1)]
    return np.array(v, dtype=np.float32), np.array(f, dtype=np.int64)


def ray_sets(scene, verts, faces, n, rng):
    lo, hi = (np.array(b, dtype=np.float32) for b in scene.bounds)
    c, r = (lo + hi) / 2, np.linalg.norm(hi - lo)
    def origins(k):
        d = rng.normal(size=(k, 3))
        return (c + 1.5 * r * d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    o = origins(n)
    sets = {"random": (o, (c + (rng.random((n, 3)) - 0.5) * (hi - lo)).astype(np.float32) - o)}
    o = origins(n)
    sets["vertex"] = (o, verts[faces[rng.integers(len(faces), size=n), rng.integers(3, size=n)]] - o)
    o = origins(n)
    t = faces[rng.integers(len(faces), size=n)]
    k = rng.integers(3, size=n)
    mid = (verts[t[np.arange(n), k]] + verts[t[np.arange(n), (k + 1) % 3]]) * np.float32(0.5)
    sets["edge"] = (o, mid - o)
    return sets


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("-n", type=int, default=50000, help="rays per set")
    ap.add_argument("-o", "--output", default="api_error.png")
    args = ap.parse_args()
    scene = bsprt.Scene.load(args.mesh)
    verts, faces = load_vertices(scene, args.mesh)
    bsp = scene.build(accel="bsp")
    kd = scene.build(accel="kd")
    tracers = {"bsp (certified)": bsprt.Tracer(scene, bsp, "certified"),
               "bsp-float": bsprt.Tracer(scene, bsp, "float"),
               "kd-float": bsprt.Tracer(scene, kd, "float"),
               "embree": bsprt.Tracer(scene, accel="embree"),
               "embree-fast": bsprt.Tracer(scene, accel="embree-fast")}
    exact = bsprt.Tracer.exact(scene)
    sets = ray_sets(scene, verts, faces, args.n, np.random.default_rng(1))
    errors = {name: [] for name in tracers}
    print(f"{'rays':8} {'mode':16} {'lost':>6} {'extra':>6} {'farther':>8} {'nearer':>7} {'max ulps':>9}")
    for set_name, (o, d) in sets.items():
        ref = exact.intersect(o, d).records
        for name, t in tracers.items():
            r = bsprt.compare(ref, t.intersect(o, d).records)
            bad = r["lost"] + r["extra"] + r["farther"] + r["nearer"]
            errors[name].append(1000.0 * bad / r["rays"])
            print(f"{set_name:8} {name:16} {r['lost']:6} {r['extra']:6} {r['farther']:8} {r['nearer']:7} "
                  f"{r['max_t_ulps']:9.0f}")
    fig, ax = plt.subplots(figsize=(7, 3.5))
    width = 0.8 / len(tracers)
    for i, (name, e) in enumerate(errors.items()):
        ax.bar(np.arange(len(sets)) + i * width, e, width, label=name)
    ax.set_xticks(np.arange(len(sets)) + 0.4 - width / 2, list(sets))
    ax.set_ylabel("wrong hits per 1000 rays\n(lost + extra + farther + nearer)")
    ax.set_title(f"{scene.summary['source'].split('/')[-1]}: error against the exact reference, {args.n} rays a set")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
