#!/usr/bin/env python3
"""docs/api.md's MeshQuery example: a slice through a closed mesh, each pixel
a point classified exactly as inside, outside or on the surface, with the exact
crossings of a few rays in the slice plane drawn on top.

    python3 docs/examples/inside_slice.py ../shared/scenes/stanford-dragon-100k.ply -o docs/images/inside_slice.png

The rays run along the slice's horizontal axis from left of the mesh; each of
their crossings (MeshQuery.all_hits) must lie where the classification changes,
and their count along a ray must be even. The script checks both and prints the
counts.
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bsprt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("--axis", type=int, default=2, help="the slice is normal to this axis (0, 1, 2)")
    ap.add_argument("--width", type=int, default=600, help="pixels along the slice's horizontal axis")
    ap.add_argument("--rays", type=int, default=24, help="horizontal rays whose crossings are drawn")
    ap.add_argument("-o", "--output", default="inside_slice.png")
    a = ap.parse_args()

    scene = bsprt.Scene.load(a.mesh)
    query = bsprt.MeshQuery(scene)
    if query.open_or_inconsistent_edges:
        print(f"warning: {query.open_or_inconsistent_edges} open or inconsistent edges: parity is not well defined")
    lo, hi = (np.array(b, dtype=np.float64) for b in scene.bounds)
    u, v = [k for k in range(3) if k != a.axis]  # the slice's horizontal and vertical axes
    pad = 0.05 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    height = max(1, int(round(a.width * (hi[v] - lo[v]) / (hi[u] - lo[u]))))
    xs = np.linspace(lo[u], hi[u], a.width)
    ys = np.linspace(lo[v], hi[v], height)
    X, Y = np.meshgrid(xs, ys)
    points = np.empty((X.size, 3))
    points[:, a.axis] = 0.5 * (lo[a.axis] + hi[a.axis])
    points[:, u], points[:, v] = X.ravel(), Y.ravel()
    sides = query.sides(points).reshape(height, a.width)  # float64 points: rounded to float32

    # Rays in the slice plane, along +u from the left edge: their exact crossings.
    rows = np.linspace(lo[v], hi[v], a.rays + 2)[1:-1]
    origins = np.zeros((a.rays, 3))
    origins[:, a.axis] = points[0, a.axis]
    origins[:, u], origins[:, v] = lo[u], rows
    directions = np.zeros((a.rays, 3))
    directions[:, u] = 1.0
    c = query.all_hits(origins, directions)
    per_ray = np.bincount(c.ray, minlength=a.rays)
    odd = int((per_ray % 2).sum())
    o32 = bsprt.make_rays(origins, directions)
    hit_u = o32[c.ray, u] + c.t * o32[c.ray, 4 + u]

    counts = {name: int((sides == code).sum()) for name, code in
              (("inside", bsprt.INSIDE), ("outside", bsprt.OUTSIDE), ("surface", bsprt.SURFACE))}
    print(f"{scene.triangle_count} triangles, {sides.size} points: {counts}; "
          f"{a.rays} rays, {len(c.t)} crossings, {odd} rays with an odd count")

    fig, ax = plt.subplots(figsize=(8, 8 * height / a.width + 0.6))
    colours = np.array([[1.0, 1.0, 1.0], [0.25, 0.4, 0.7], [0.9, 0.1, 0.1]])  # outside, inside, surface
    ax.imshow(colours[sides], origin="lower", extent=(lo[u], hi[u], lo[v], hi[v]), interpolation="nearest")
    ax.plot(hit_u, o32[c.ray, v], "o", ms=3, mfc="none", mec="orange",
            label=f"exact crossings of {a.rays} rays (MeshQuery.all_hits)")
    for y in rows:
        ax.axhline(y, color="orange", lw=0.3)
    ax.set_title(f"{scene.summary['source'].split('/')[-1]}: slice at {'xyz'[a.axis]} = "
                 f"{points[0, a.axis]:.4g}, inside (blue) by exact parity (MeshQuery.sides)", fontsize=9)
    ax.set_xlabel("xyz"[u])
    ax.set_ylabel("xyz"[v])
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)
    print(f"wrote {a.output}")
    if odd:
        raise SystemExit(f"{odd} rays crossed the closed mesh an odd number of times")


if __name__ == "__main__":
    main()
