"""bsprt: exact general BSP trees and certified ray tracing, from numpy.

    import numpy as np, bsprt
    scene = bsprt.Scene.load("bunny.obj")            # or bsprt.Scene(vertices, faces)
    tree = scene.build(accel="bsp")                   # exact BSP, certified float flattening
    assert scene.verify(tree)["certified"]
    tracer = bsprt.Tracer(scene, tree, mode="certified")
    hits = tracer.intersect(origins, directions)      # hits.t, hits.prim, hits.u, hits.v

Rays and hits cross the C++ boundary without copies where the layout allows:
an (N, 8) float32 array of .rays records (org, tnear, dir, tfar) is traced in
place (Tracer.intersect_rays), and hits come back as views of one HIT_DTYPE
buffer. Bad arrays raise ValueError; bad files raise bsprt.InputError (a
ValueError) naming the file and line. See docs/api.md.
"""
from __future__ import annotations

from typing import NamedTuple, Optional

import numpy as np

from ._bsprt import (HIT_DTYPE, Cancelled, InputError, Tree, __version__, compare,
                     read_hits, read_rays, write_hits, write_rays)
from ._bsprt import Scene
from ._bsprt import _MeshQuery, _Tracer

__all__ = ["Scene", "Tree", "Tracer", "Hits", "HIT_DTYPE", "NO_HIT", "InputError", "Cancelled", "compare",
           "read_rays", "write_rays", "read_hits", "write_hits", "make_rays", "MeshQuery", "Crossings",
           "OUTSIDE", "INSIDE", "SURFACE", "__version__"]

NO_HIT = 0xFFFFFFFF
OUTSIDE, INSIDE, SURFACE = 0, 1, 2  # MeshQuery.sides codes (bsprt::PointSide)


class Hits(NamedTuple):
    """Nearest hits: views of one HIT_DTYPE buffer (`records`). A miss is t=inf, prim=NO_HIT."""
    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
    records: np.ndarray


def _hits(records: np.ndarray) -> Hits:
    return Hits(records["t"], records["prim"], records["u"], records["v"], records)


def _numbers(name: str, a) -> np.ndarray:
    """`a` as an array of floats or integers (bool and other kinds refused)."""
    a = np.asarray(a)
    if a.dtype.kind not in "fiu":
        raise ValueError(f"{name}: expected float (or integer) numbers, got dtype {a.dtype}")
    return a


def _to_float32(name: str, a: np.ndarray) -> np.ndarray:
    """Rounds to float32 (to nearest); ValueError where a finite value overflows."""
    with np.errstate(over="ignore"):
        f = a.astype(np.float32)
    bad = np.isfinite(a) & ~np.isfinite(f)
    if bad.any():
        first = np.argwhere(bad)[0]
        raise ValueError(f"{name}: value {a[tuple(first)]!r} at {tuple(int(i) for i in first)} overflows float32, "
                         "the precision bsprt traces in")
    return f


def _bound(name: str, a, n: int, default: float, up: bool) -> np.ndarray:
    """tnear (up=True) or tfar as float32, rounded outward-in: tnear up and tfar
    down, so the float32 interval never holds a t outside the one asked for."""
    if a is None:
        return np.full(n, default, dtype=np.float32)
    a = _numbers(name, a)
    if a.ndim == 0:
        a = np.full(n, a, dtype=a.dtype)
    if a.shape != (n,):
        raise ValueError(f"{name}: expected shape ({n},), got {a.shape}")
    if a.dtype == np.float32:
        return a
    a = a.astype(np.float64)
    with np.errstate(over="ignore"):
        f = a.astype(np.float32)
    off = f > a if up is False else f < a  # rounded past the bound asked for (NaN compares False)
    f[off] = np.nextafter(f[off], np.float32(np.inf if up else -np.inf))
    return f


def make_rays(origins, directions, tnear=None, tfar=None) -> np.ndarray:
    """Packs origins (N, 3), directions (N, 3), tnear and tfar (N,) or scalars into
    the (N, 8) float32 .rays layout (docs/api.md, "Rays from float64"). Float64
    (or integer) origins and directions are rounded to the nearest float32, the
    precision bsprt traces in, and a finite value that overflows float32 is a
    ValueError; tnear is rounded up and tfar down, so that no hit outside the
    interval asked for is reported. NaN or reversed intervals make rays that miss."""
    o = _numbers("origins", origins)
    d = _numbers("directions", directions)
    for name, a in (("origins", o), ("directions", d)):
        if a.ndim != 2 or a.shape[1] != 3:
            raise ValueError(f"{name}: expected shape (N, 3), got {a.shape}")
    if o.shape != d.shape:
        raise ValueError(f"origins {o.shape} and directions {d.shape} differ in shape")
    n = o.shape[0]
    rays = np.empty((n, 8), dtype=np.float32)
    rays[:, 0:3] = _to_float32("origins", o)
    rays[:, 3] = _bound("tnear", tnear, n, 0.0, up=True)
    rays[:, 4:7] = _to_float32("directions", d)
    rays[:, 7] = _bound("tfar", tfar, n, np.inf, up=False)
    return rays


def _rays_array(rays) -> np.ndarray:
    if not isinstance(rays, np.ndarray):
        raise TypeError(f"rays: expected an (N, 8) float32 numpy array of .rays records, got {type(rays).__name__}; "
                        "bsprt.make_rays(origins, directions, tnear, tfar) makes one")
    return rays


class Tracer:
    """Tracer(scene, tree, mode="certified") traces a built tree; Tracer(scene,
    accel="embree") any accelerator by name; Tracer.exact(scene) the exact reference."""

    def __init__(self, scene, tree: Optional[Tree] = None, mode: str = "certified",
                 accel: Optional[str] = None):
        if tree is not None and accel is not None:
            raise ValueError("give either a tree (with a mode) or an accelerator name, not both")
        if tree is None and accel is None:
            raise ValueError("Tracer needs a tree (scene.build()) or accel=NAME")
        self._t = _Tracer(scene, tree, mode) if tree is not None else _Tracer.by_name(scene, accel)
        self._scene = scene

    @staticmethod
    def exact(scene) -> "Tracer":
        """The exact reference: CGAL AABB tree, exact predicates and parameters."""
        return Tracer(scene, accel="exact")

    @staticmethod
    def accelerators() -> list:
        return _Tracer.accelerators()

    name = property(lambda self: self._t.name)
    certified = property(lambda self: self._t.certified)
    memory_bytes = property(lambda self: self._t.memory_bytes)

    def intersect_rays(self, rays: np.ndarray, threads: int = 0, packet_width: int = 1) -> Hits:
        """Nearest hits of an (N, 8) float32 array of .rays records, traced in place."""
        return _hits(self._t._intersect_rays(_rays_array(rays), threads, packet_width))

    def intersect(self, origins, directions, tnear=None, tfar=None, threads: int = 0,
                  packet_width: int = 1) -> Hits:
        """Nearest hits in [tnear, tfar] (defaults 0 and inf): arrays t, prim, u, v."""
        return self.intersect_rays(make_rays(origins, directions, tnear, tfar), threads, packet_width)

    def occluded_rays(self, rays: np.ndarray, threads: int = 0, packet_width: int = 1) -> np.ndarray:
        """True where the ray of an (N, 8) float32 array of .rays records hits anything in [tnear, tfar]."""
        return self._t._occluded_rays(_rays_array(rays), threads, packet_width).astype(bool)

    def occluded(self, origins, directions, tnear=None, tfar=None, threads: int = 0,
                 packet_width: int = 1) -> np.ndarray:
        """True where the ray hits anything in [tnear, tfar] (shadow / any-hit rays)."""
        return self.occluded_rays(make_rays(origins, directions, tnear, tfar), threads, packet_width)


class Crossings(NamedTuple):
    """Every crossing of every ray (MeshQuery.all_hits), ordered by ray, then t, then
    triangle: the rows of `bsprt trace --all-hits`."""
    ray: np.ndarray   # int64: index of the ray
    prim: np.ndarray  # uint32: triangle number
    t: np.ndarray     # float32: the exact t rounded to the nearest float
    side: np.ndarray  # int8: +1 or -1, the sign of n . dir with n = (v1 - v0) x (v2 - v0)


class MeshQuery:
    """Exact queries on a closed mesh (docs/api.md, "Inside and all hits"): where
    points lie, by exact parity with simulation of simplicity, and every crossing
    of a ray. Builds the exact reference's AABB tree once."""

    def __init__(self, scene):
        self._q = _MeshQuery(scene)
        self._scene = scene

    @property
    def open_or_inconsistent_edges(self) -> int:
        """Edges used by other than two triangles, or twice in one direction: 0 for a
        closed, consistently oriented mesh, where inside and outside are defined."""
        return self._q.open_or_inconsistent_edges

    def sides(self, points, threads: int = 0) -> np.ndarray:
        """OUTSIDE, INSIDE or SURFACE (uint8) for each point of an (N, 3) array. Float64
        (or integer) points are rounded to the nearest float32, as mesh coordinates
        are; a NaN or infinite point is a ValueError."""
        p = _numbers("points", points)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points: expected shape (N, 3), got {p.shape}")
        return self._q._sides(np.ascontiguousarray(_to_float32("points", p)), threads)

    def contains(self, points, threads: int = 0) -> np.ndarray:
        """True where a point is inside the mesh or on its surface (closed solid)."""
        return self.sides(points, threads) != OUTSIDE

    def all_hits_rays(self, rays: np.ndarray, threads: int = 0) -> Crossings:
        """Every crossing of each ray of an (N, 8) float32 array of .rays records."""
        return Crossings(*self._q._all_hits(_rays_array(rays), threads))

    def all_hits(self, origins, directions, tnear=None, tfar=None, threads: int = 0) -> Crossings:
        """Every crossing with t in [tnear, tfar] (defaults 0 and inf), each edge or
        vertex crossing counted once."""
        return self.all_hits_rays(make_rays(origins, directions, tnear, tfar), threads)
