"""Every binding of the bsprt module against the CLI's own results on the
shared meshes (bit for bit), and bad input: a clear ValueError, never a crash."""
import os

import numpy as np
import pytest

import bsprt
from conftest import cli


def test_version_and_accelerators():
    assert bsprt.__version__.count(".") == 2
    names = bsprt.Tracer.accelerators()
    assert {"bsp", "bsp-float", "kd", "exact", "embree"} <= set(names)


def test_scene_load_and_arrays(suzanne):
    s = bsprt.Scene.load(suzanne)
    assert s.triangle_count == 968 and s.vertex_count == 507
    assert "triangles   968" in cli("info", suzanne)
    assert s.summary["degenerate"] == 0
    (lo, hi) = s.bounds
    assert all(a < b for a, b in zip(lo, hi))
    assert bsprt.Scene.load("default").fingerprint == bsprt.Scene.default().fingerprint
    # The same soup from arrays: one vertex triple per triangle.
    tri = _corners(s)
    faces = np.arange(tri.shape[0], dtype=np.int64).reshape(-1, 3)
    a = bsprt.Scene(tri, faces)
    assert a.fingerprint == s.fingerprint


def _corners(scene):
    """Corner coordinates of every triangle, in triangle order, read from the
    OBJ independently of bsprt's loader (fan triangulation, formats.md)."""
    verts, faces = [], []
    with open(scene.summary["source"]) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                for j in range(1, len(idx) - 1):
                    faces.append([idx[0], idx[j], idx[j + 1]])
    v = np.array(verts, dtype=np.float32)
    return v[np.array(faces).reshape(-1)]


def test_bad_arrays_raise_value_error():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    f = np.array([[0, 1, 2]], dtype=np.int32)
    assert bsprt.Scene(v, f).triangle_count == 1
    with pytest.raises(ValueError, match="float32"):
        bsprt.Scene(v.astype(np.float64), f)
    with pytest.raises(ValueError, match="shape"):
        bsprt.Scene(v[:, :2].copy(), f)
    with pytest.raises(ValueError, match="integer"):
        bsprt.Scene(v, f.astype(np.float32))
    with pytest.raises(ValueError, match="out of range"):
        bsprt.Scene(v, np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match="out of range"):
        bsprt.Scene(v, np.array([[0, -1, 2]]))
    with pytest.raises(ValueError, match="no triangles"):
        bsprt.Scene(v, np.zeros((0, 3), dtype=np.uint32))
    nan = v.copy()
    nan[1, 0] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        bsprt.Scene(nan, f)
    kept = bsprt.Scene(nan, f, allow_nonfinite=True)
    assert kept.summary["nonfinite_triangles"] == 1 and kept.summary["degenerate"] == 1
    # Non-contiguous vertices are accepted (copied).
    wide = np.zeros((3, 6), dtype=np.float32)
    wide[:, ::2] = v
    assert bsprt.Scene(wide[:, ::2], f).fingerprint == bsprt.Scene(v, f).fingerprint


def test_bad_files_raise_input_error(tmp_path, scenes):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(bsprt.InputError, match="bad.obj:3"):
        bsprt.Scene.load(str(bad))
    with pytest.raises(ValueError):  # InputError is a ValueError
        bsprt.Scene.load(str(tmp_path / "missing.ply"))
    with pytest.raises(bsprt.InputError):
        bsprt.read_rays(str(bad))


@pytest.mark.parametrize("accel,mode,cli_mode", [("bsp", "certified", "bsp"), ("bsp", "float", "bsp-float"),
                                                 ("bsp", "top", "bsp-top"), ("bsp", "top-float", "bsp-top-float"),
                                                 ("kd", "certified", "kd"), ("kd", "float", "kd-float")])
def test_trace_equals_cli(tmp_path, suzanne, accel, mode, cli_mode):
    rays_path, tree_path, hits_path = tmp_path / "r.rays", tmp_path / "t.tree", tmp_path / "h.hits"
    cli("gen-rays", suzanne, "--kind", "vertex", "-n", 3000, "-o", rays_path)
    cli("build", suzanne, "--accel", accel, "-o", tree_path)
    cli("trace", suzanne, rays_path, "-o", hits_path, "--accel", cli_mode, "--tree", tree_path)
    scene = bsprt.Scene.load(suzanne)
    expected = bsprt.read_hits(str(hits_path))
    rays = bsprt.read_rays(str(rays_path))
    for tree in (bsprt.Tree.load(str(tree_path), scene), scene.build(accel=accel)):
        t = bsprt.Tracer(scene, tree, mode=mode)
        assert t.name == cli_mode
        h = t.intersect_rays(rays)
        assert h.records.tobytes() == expected.tobytes()
        # origins/directions/tnear/tfar give the same rays, hence the same hits.
        h2 = t.intersect(rays[:, 0:3], rays[:, 4:7], rays[:, 3], rays[:, 7], threads=1, packet_width=8)
        assert h2.records.tobytes() == expected.tobytes()
        assert np.array_equal(h.prim != bsprt.NO_HIT, t.occluded_rays(rays))
    out = tmp_path / "api.hits"
    bsprt.write_hits(str(out), h.records)
    assert out.read_bytes() == hits_path.read_bytes()
    rays_out = tmp_path / "api.rays"
    bsprt.write_rays(str(rays_out), bsprt.make_rays(rays[:, 0:3], rays[:, 4:7], rays[:, 3], rays[:, 7]))
    assert rays_out.read_bytes() == rays_path.read_bytes()
    assert t.memory_bytes > 0 and bsprt.Tracer(scene, accel="brute").memory_bytes == 0


def test_certified_equals_exact_and_compare(tmp_path, suzanne):
    scene = bsprt.Scene.load(suzanne)
    rays_path = tmp_path / "e.rays"
    cli("gen-rays", suzanne, "--kind", "edge", "-n", 3000, "-o", rays_path)
    rays = bsprt.read_rays(str(rays_path))
    exact = bsprt.Tracer.exact(scene).intersect_rays(rays)
    cert = bsprt.Tracer(scene, scene.build(), mode="certified")
    assert cert.certified
    h = cert.intersect_rays(rays)
    # The exact reference's t (bit for bit) and triangle; u, v are float results.
    assert h.t.tobytes() == exact.t.tobytes() and np.array_equal(h.prim, exact.prim)
    r = bsprt.compare(exact.records, h.records)
    assert r["agrees"] and r["lost"] == 0 and r["rays"] == len(rays)
    lost = h.records.copy()
    i = int(np.argmax(lost["prim"] != bsprt.NO_HIT))
    lost[i] = (np.inf, bsprt.NO_HIT, 0, 0)
    r = bsprt.compare(exact.records, lost)
    assert r["lost"] == 1 and r["first_bad_ray"] == i and not r["agrees"]
    a, b = tmp_path / "a.hits", tmp_path / "b.hits"
    bsprt.write_hits(str(a), exact.records)
    bsprt.write_hits(str(b), lost)
    import subprocess
    from conftest import CLI
    out = subprocess.run([CLI, "compare", str(a), str(b)], capture_output=True, text=True)
    assert out.returncode == 1
    with pytest.raises(ValueError):
        bsprt.compare(exact.records, lost[:10])
    with pytest.raises(ValueError):
        bsprt.compare(exact.records, np.zeros(len(rays), dtype=np.float32))


def test_bad_rays_raise_value_error(suzanne):
    scene = bsprt.Scene.load(suzanne)
    t = bsprt.Tracer(scene, accel="brute")
    o = np.zeros((4, 3), dtype=np.float32)
    d = np.ones((4, 3), dtype=np.float32)
    assert len(t.intersect(o, d).t) == 4
    with pytest.raises(ValueError, match="shape"):
        t.intersect(o[:, :2], d)
    with pytest.raises(ValueError, match="differ"):
        t.intersect(o[:3], d)
    # Integer coordinates are numbers too (traced as their float32 values);
    # booleans and complex numbers are not.
    assert np.array_equal(t.intersect(o.astype(np.int32), d).records, t.intersect(o, d).records)
    with pytest.raises(ValueError, match="float"):
        t.intersect(o.astype(bool), d)
    with pytest.raises(ValueError, match="float"):
        t.intersect(o.astype(np.complex64), d)
    with pytest.raises(ValueError, match="tnear"):
        t.intersect(o, d, tnear=np.zeros(3))
    with pytest.raises(ValueError, match="dtype"):
        t.intersect_rays(np.zeros((4, 8), dtype=np.float64))
    with pytest.raises(ValueError, match="shape"):
        t.intersect_rays(np.zeros((4, 7), dtype=np.float32))
    with pytest.raises(ValueError, match="packet_width"):
        t.intersect(o, d, packet_width=3)
    # NaN rays are invalid rays: they miss (formats.md), no error.
    h = t.intersect(np.full((2, 3), np.nan), d[:2])
    assert np.all(h.prim == bsprt.NO_HIT) and np.all(np.isinf(h.t))
    with pytest.raises(ValueError):
        bsprt.Tracer(scene)
    with pytest.raises(ValueError):
        bsprt.Tracer(scene, accel="no-such-accel")
    kd_tree = scene.build(accel="kd")
    assert bsprt.Tracer(scene, kd_tree, mode="certified").name == "kd"  # exact leaves on kd-trees too
    with pytest.raises(ValueError):
        bsprt.Tracer(scene, kd_tree, mode="top")
    with pytest.raises(ValueError):
        scene.build(accel="octree")


def test_tree_save_load_verify(tmp_path, suzanne):
    scene = bsprt.Scene.load(suzanne)
    for accel in ("bsp", "kd"):
        calls = []
        tree = scene.build(accel=accel, progress=lambda d, t: calls.append((d, t)))
        assert calls and calls[-1][0] == calls[-1][1]
        assert tree.kind == accel and tree.nbytes > 40
        cert = scene.verify(tree)
        assert cert["certified"] and cert["failure"] == ""
        p = tmp_path / f"{accel}.tree"
        tree.save(str(p))
        assert "CERTIFIED" in cli("verify", suzanne, p)
        again = bsprt.Tree.load(str(p), scene)
        assert again.nbytes == tree.nbytes
        with pytest.raises(bsprt.InputError):
            bsprt.Tree.load(str(p), bsprt.Scene.default())
        data = bytearray(p.read_bytes())
        data[len(data) // 2] ^= 1
        p.write_bytes(bytes(data))
        with pytest.raises(bsprt.InputError, match="CRC"):
            bsprt.Tree.load(str(p), scene)


def test_progress_exception_cancels_build(suzanne):
    scene = bsprt.Scene.load(suzanne)

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        scene.build(accel="bsp", progress=stop)


# Found by a review of the module (2026-12-07); each was a crash, a silent
# loss or a misleading error before.


def test_progress_exception_on_the_last_report_is_raised(suzanne):
    """An exception from the final (total, total) report was dropped: nothing
    polled cancel after it, and build() returned a tree."""
    scene = bsprt.Scene.load(suzanne)

    def at_end(done, total):
        if total > 0 and done == total:
            raise RuntimeError("raised at the end")

    for accel in ("kd", "bsp"):
        with pytest.raises(RuntimeError, match="raised at the end"):
            scene.build(accel=accel, threads=1, progress=at_end)


def test_float64_rays_never_reach_outside_the_interval_asked_for(scenes):
    """tnear and tfar were rounded to nearest: a hit at 4.5 came back for
    tfar = 4.49999999 and for tnear = 4.50000001."""
    t = bsprt.Tracer(bsprt.Scene.load(os.path.join(scenes, "cube.obj")), accel="bsp")
    o = np.array([[0.1, 0.2, -5.0]])
    d = np.array([[0.0, 0.0, 1.0]])
    front = float(t.intersect(o, d).t[0])
    assert front == 4.5  # the cube spans [-0.5, 0.5]
    assert not np.isfinite(t.intersect(o, d, tfar=4.49999999).t[0])
    assert t.intersect(o, d, tnear=4.50000001).t[0] > 4.5
    assert t.intersect(o, d, tfar=4.5).t[0] == 4.5  # a float64 bound that is a float32 stays put
    assert t.intersect(o, d, tfar=10).t[0] == 4.5  # an int scalar, like 10.0
    rays = bsprt.make_rays(o, d, tnear=np.array([0.1]), tfar=np.array([1e39]))
    assert rays[0, 3] >= 0.1 and rays[0, 7] == np.finfo(np.float32).max
    with pytest.raises(ValueError, match="overflows float32"):
        t.intersect(np.array([[0.0, 0.0, -1e39]]), d)


def test_paths_are_str_or_pathlike_and_never_hold_nul(tmp_path, suzanne):
    import pathlib
    scene = bsprt.Scene.load(pathlib.Path(suzanne))
    tree = scene.build(accel="kd")
    tree.save(tmp_path / "s.kd")
    assert bsprt.Tree.load(tmp_path / "s.kd", scene).kind == "kd"
    rays = bsprt.make_rays(np.zeros((3, 3)), np.ones((3, 3)))
    bsprt.write_rays(tmp_path / "r.rays", rays)
    assert np.array_equal(bsprt.read_rays(tmp_path / "r.rays"), rays)
    with pytest.raises(ValueError, match="NUL"):
        bsprt.Scene.load(suzanne + "\0junk")
    with pytest.raises(TypeError):
        bsprt.Scene.load(5)


def test_errors_name_what_the_caller_passed(scenes):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    with pytest.raises(ValueError, match="is vertex 18446744073709551615"):  # not "vertex -1"
        bsprt.Scene(v, np.array([[0, 1, 2**64 - 1]], np.uint64))
    scene = bsprt.Scene.load(os.path.join(scenes, "cube.obj"))
    for threads in (-1, 70000):
        with pytest.raises(ValueError, match="threads"):
            scene.build(accel="kd", threads=threads)
        with pytest.raises(ValueError, match="threads"):
            scene.verify(scene.build(accel="kd"), threads=threads)
    # Embree named the ray by its index within a block of 4096 (or 0).
    e = bsprt.Tracer(scene, accel="embree")
    rays = np.tile(np.array([[0, 0, -5, 0, 0, 0, 1, np.inf]], np.float32), (5000, 1))
    rays[4100, 3] = -1.0
    for call in (lambda: e.intersect_rays(rays, threads=2), lambda: e.occluded_rays(rays, threads=1)):
        with pytest.raises(ValueError, match="ray 4100 has tnear < 0"):
            call()
    with pytest.raises(TypeError, match="make_rays"):
        e.intersect_rays([[0, 0, -5, 0, 0, 0, 1, np.inf]])
    with pytest.raises(ValueError, match="tolerance"):
        h = e.intersect_rays(rays[:2]).records
        bsprt.compare(h, h, rel_tol=-1)
    assert "NO_HIT" in bsprt.__all__


def test_exact_reference_misses_in_a_segment_at_infinity(scenes):
    """tnear = tfar = +inf (or -inf): no finite t lies there. The exact
    reference dropped an infinite bound whatever its side and hit the cube."""
    scene = bsprt.Scene.load(os.path.join(scenes, "cube.obj"))
    inf = np.inf
    rays = np.array([[0, 0, -5, inf, 0, 0, 1, inf], [0, 0, -5, -inf, 0, 0, 1, -inf]], np.float32)
    for accel in ("exact", "brute-certified", "bsp", "kd"):
        hits = bsprt.Tracer(scene, accel=accel).intersect_rays(rays)
        assert np.all(hits.prim == bsprt.NO_HIT), accel


def test_compare_counts_a_wrong_t_on_the_right_triangle(scenes):
    scene = bsprt.Scene.load(os.path.join(scenes, "cube.obj"))
    t = bsprt.Tracer(scene, accel="bsp")
    hits = t.intersect(np.array([[0.1, 0.2, -5.0]], np.float32), np.array([[0, 0, 1]], np.float32)).records
    wrong = hits.copy()
    wrong["t"] *= 3
    c = bsprt.compare(hits, wrong)
    assert c["t_off"] == 1 and not c["agrees"] and c["first_bad_ray"] == 0
    broken = hits.copy()
    broken["t"] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        bsprt.compare(hits, broken)


def test_mesh_query_equals_cli_inside_and_all_hits(tmp_path):
    obj = tmp_path / "torus.obj"
    cli("gen", "torus", "-o", obj)
    scene = bsprt.Scene.load(obj)
    q = bsprt.MeshQuery(scene)
    assert q.open_or_inconsistent_edges == 0
    assert bsprt.MeshQuery(bsprt.Scene.default()).open_or_inconsistent_edges > 0
    # float64 points on a grid over the box, plus float32 points near the surface
    (lo, hi) = (np.array(b, dtype=np.float64) for b in scene.bounds)
    g = np.linspace(0.0, 1.0, 13)
    grid = lo - 0.1 * (hi - lo) + 1.2 * (hi - lo) * np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    rays = bsprt.read_rays(_vertex_rays(tmp_path, obj))
    aimed = rays[:200, 0:3] + rays[:200, 4:7]  # the vertex rays' targets, rounded: on or next to the surface
    points = np.concatenate([grid, aimed.astype(np.float64)])
    pts = tmp_path / "points.txt"
    np.savetxt(pts, points, fmt="%.17g")
    out = tmp_path / "sides.txt"
    cli("inside", obj, pts, "-o", out)
    codes = {"outside": bsprt.OUTSIDE, "inside": bsprt.INSIDE, "surface": bsprt.SURFACE}
    want = np.array([codes[w] for w in out.read_text().split()], dtype=np.uint8)
    got = q.sides(points)
    assert got.dtype == np.uint8 and np.array_equal(got, want)
    assert (want == bsprt.INSIDE).sum() > 20 and (want == bsprt.OUTSIDE).sum() > 1000
    assert (want == bsprt.SURFACE).sum() > 0
    assert np.array_equal(q.sides(points, threads=1), want)
    assert np.array_equal(q.contains(points), want != bsprt.OUTSIDE)
    # all hits: the CLI's CSV rows, t bit for bit
    rays_path = _vertex_rays(tmp_path, obj)
    csv = tmp_path / "all.csv"
    cli("trace", obj, rays_path, "--all-hits", "-o", csv)
    rows = np.loadtxt(csv, delimiter=",", skiprows=1, dtype=np.float64, ndmin=2)
    c = q.all_hits_rays(bsprt.read_rays(rays_path))
    assert len(c.ray) == rows.shape[0] > 1000
    assert np.array_equal(c.ray, rows[:, 0].astype(np.int64))
    assert np.array_equal(c.prim, rows[:, 1].astype(np.uint32))
    assert np.array_equal(c.t, rows[:, 2].astype(np.float32))
    assert np.array_equal(c.side, rows[:, 3].astype(np.int8))
    again = q.all_hits(rays[:, 0:3], rays[:, 4:7], rays[:, 3], rays[:, 7])
    assert np.array_equal(again.t, c.t) and np.array_equal(again.prim, c.prim)
    # bad input: ValueError, never a crash
    with pytest.raises(ValueError, match="point 1 has a NaN"):
        q.sides([[0, 0, 0], [0, np.nan, 0]])
    with pytest.raises(ValueError, match="shape"):
        q.sides(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="dtype"):
        q.sides(np.zeros((4, 3), dtype=bool))
    with pytest.raises(ValueError, match="overflows float32"):
        q.sides([[1e300, 0, 0]])
    with pytest.raises(TypeError):
        q.all_hits_rays([[0] * 8])
    with pytest.raises(ValueError):
        q.all_hits_rays(np.zeros((3, 7), dtype=np.float32))


def _vertex_rays(tmp_path, obj):
    path = tmp_path / "vertex.rays"
    if not path.exists():
        cli("gen-rays", obj, "--kind", "vertex", "-n", "1500", "--seed", "3", "-o", path)
    return path
