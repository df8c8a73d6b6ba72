/// \file bindings.cpp
/// The `bsprt._bsprt` extension (pybind11): the public C++ API
/// (include/bsprt/) over numpy buffers. Arrays are checked here (dtype, shape,
/// contiguity) and turned into ValueError; rays and hits cross without copies
/// (N x 8 float32 rays = the .rays record, structured hits = the .hits record);
/// face indices are widened and range-checked (one copy, 12 bytes a triangle).
/// The GIL is released while loading, saving, building, verifying, tracing
/// and comparing. Paths are str or os.PathLike. python/bsprt/__init__.py adds
/// the friendly signatures.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cstring>
#include <optional>

#include "bsprt/bsprt.h"

namespace py = pybind11;

namespace {

using bsprt::Hit;
using bsprt::Ray;

/// numpy's dtype equality (byte order, fields), not object identity.
bool same_dtype(const py::dtype& a, const py::dtype& b) { return a.attr("__eq__")(b).cast<bool>(); }

/// Raises ValueError unless `a` is a C-contiguous array of `T` with `cols`
/// columns (cols == 0: one dimension).
template <typename T>
void require(const py::array& a, const char* what, py::ssize_t cols) {
  if (!same_dtype(a.dtype(), py::dtype::of<T>()))
    throw py::value_error(std::string(what) + ": expected dtype " + std::string(py::str(py::dtype::of<T>())) +
                          ", got " + std::string(py::str(a.dtype())));
  if (cols == 0 ? a.ndim() != 1 : (a.ndim() != 2 || a.shape(1) != cols))
    throw py::value_error(std::string(what) + ": expected shape " + (cols == 0 ? "(N,)" : "(N, " + std::to_string(cols) + ")") +
                          ", got " + std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()))))));
  if (!(a.flags() & py::array::c_style))
    throw py::value_error(std::string(what) + ": must be C-contiguous (numpy.ascontiguousarray)");
}

/// A path argument (str, bytes or os.PathLike, through os.fspath) as a
/// string; TypeError for anything else, ValueError for an embedded NUL, as
/// Python's open() does.
std::string path_of(const py::object& p) {
  const py::object fs = py::module_::import("os").attr("fspath")(p);
  const std::string s = py::isinstance<py::bytes>(fs) ? std::string(fs.cast<py::bytes>()) : fs.cast<std::string>();
  if (s.find('\0') != std::string::npos)
    throw py::value_error("path contains a NUL character: " + std::string(s.c_str()));
  return s;
}

std::span<const Ray> rays_of(const py::array& rays) {
  require<float>(rays, "rays", 8);
  return {reinterpret_cast<const Ray*>(rays.data()), std::size_t(rays.shape(0))};
}

/// The structured dtype of a .hits record: t, prim, u, v.
py::dtype hit_dtype() {
  py::list fields;
  fields.append(py::make_tuple("t", "<f4"));
  fields.append(py::make_tuple("prim", "<u4"));
  fields.append(py::make_tuple("u", "<f4"));
  fields.append(py::make_tuple("v", "<f4"));
  return py::dtype::from_args(fields);
}

std::span<const Hit> hits_of(const py::array& hits, const char* what) {
  if (!same_dtype(hits.dtype(), hit_dtype()) || hits.ndim() != 1 || !(hits.flags() & py::array::c_style))
    throw py::value_error(std::string(what) + ": expected a C-contiguous 1-d array of bsprt.HIT_DTYPE records");
  return {reinterpret_cast<const Hit*>(hits.data()), std::size_t(hits.shape(0))};
}

py::array new_hits(std::size_t n) { return py::array(hit_dtype(), std::vector<py::ssize_t>{py::ssize_t(n)}); }

bsprt::TraceOptions trace_options(int threads, int packet_width) {
  bsprt::TraceOptions o;
  o.threads = threads;
  o.packet_width = packet_width;
  return o;
}

py::dict certificate_dict(const bsprt::Certificate& c) {
  py::dict d;
  d["certified"] = c.certified;
  d["failure"] = c.failure;
  d["node"] = c.node == 0xFFFFFFFFu ? py::object(py::none()) : py::object(py::int_(c.node));
  d["triangle"] = c.triangle == 0xFFFFFFFFu ? py::object(py::none()) : py::object(py::int_(c.triangle));
  d["witness"] = c.witness ? py::object(py::make_tuple(c.witness->x, c.witness->y, c.witness->z)) : py::object(py::none());
  d["nodes"] = c.nodes;
  d["leaves"] = c.leaves;
  d["pairs"] = c.pairs;
  d["exact_fallbacks"] = c.exact_fallbacks;
  d["seconds"] = c.seconds;
  return d;
}

py::dict comparison_dict(const bsprt::HitComparison& c) {
  py::dict d;
  d["rays"] = c.rays;
  d["both_miss"] = c.both_miss;
  d["same_triangle"] = c.same_triangle;
  d["t_off"] = c.t_off;
  d["tie"] = c.tie;
  d["lost"] = c.lost;
  d["extra"] = c.extra;
  d["farther"] = c.farther;
  d["nearer"] = c.nearer;
  d["max_t_ulps"] = c.max_t_ulps;
  d["first_bad_ray"] = c.first_bad_ray == UINT64_MAX ? py::object(py::none()) : py::object(py::int_(c.first_bad_ray));
  d["agrees"] = c.agrees();
  return d;
}

bsprt::Tree build(const bsprt::Scene& scene, const std::string& accel, int threads, const std::string& membership,
                  py::object progress) {
  bsprt::BuildOptions o;
  if (accel == "kd") o.kind = bsprt::TreeKind::Kd;
  else if (accel != "bsp") throw py::value_error("accel must be 'kd' or 'bsp', not '" + accel + "'");
  if (membership == "closed") o.membership = bsprt::Membership::Closed;
  else if (membership != "area") throw py::value_error("membership must be 'area' or 'closed', not '" + membership + "'");
  o.threads = threads;
  // A Python callback is called with the GIL held; if it raises, the build is
  // cancelled and the exception is re-raised here.
  auto failed = std::make_shared<std::atomic<bool>>(false);
  auto error = std::make_shared<py::object>();
  if (!progress.is_none()) {
    o.progress = [progress, failed, error](double done, double total) {
      py::gil_scoped_acquire gil;
      try {
        progress(done, total);
      } catch (py::error_already_set& e) {
        *error = e.value();
        failed->store(true);
      }
    };
    o.cancel = [failed] { return failed->load(); };
  }
  std::optional<bsprt::Tree> tree;
  try {
    py::gil_scoped_release release;
    tree = bsprt::build(scene, o);
  } catch (const bsprt::Cancelled&) {
    if (!*error) throw;
  }
  // The GIL is held again. A callback that raised stopped the build, or, on
  // the last report (total, total), after which nothing polls cancel, let it
  // finish: either way its exception is raised, as docs/api.md promises.
  if (*error) {
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error->ptr())), error->ptr());
    throw py::error_already_set();
  }
  return std::move(*tree);
}

/// Scene(vertices, faces): vertices (V, 3) float32, faces (F, 3) of any integer
/// dtype. Contiguous float32 vertices and uint32 faces are read in place.
bsprt::Scene scene_from_arrays(const py::array& vertices, const py::array& faces, bool allow_nonfinite) {
  if (!same_dtype(vertices.dtype(), py::dtype::of<float>()))
    throw py::value_error("vertices: expected dtype float32, got " + std::string(py::str(vertices.dtype())) +
                          " (bsprt traces float scenes: pass vertices.astype(numpy.float32))");
  if (vertices.ndim() != 2 || vertices.shape(1) != 3) throw py::value_error("vertices: expected shape (V, 3)");
  const char kind = faces.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::value_error("faces: expected an integer dtype, got " + std::string(py::str(faces.dtype())));
  if (faces.ndim() != 2 || faces.shape(1) != 3) throw py::value_error("faces: expected shape (F, 3)");
  const auto v = py::array_t<float, py::array::c_style>::ensure(vertices);
  const std::int64_t nv = vertices.shape(0);
  std::vector<std::uint32_t> idx;
  // Widened to 64 bits of the faces' own signedness, so that no index wraps
  // around (a uint64 2^64 - 1 is not vertex -1) before the range check.
  const auto check = [&](const auto* fi, std::size_t n) {
    idx.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (fi[i] < 0 || std::uint64_t(fi[i]) >= std::uint64_t(nv))
        throw py::value_error("faces: triangle " + std::to_string(i / 3) + " corner " + std::to_string(i % 3) +
                              " is vertex " + std::to_string(fi[i]) + ", out of range [0, " + std::to_string(nv) + ")");
      idx[i] = std::uint32_t(fi[i]);
    }
  };
  if (kind == 'u') {
    const auto f = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(faces);
    check(f.data(), std::size_t(f.size()));
  } else {
    const auto f = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(faces);
    check(f.data(), std::size_t(f.size()));
  }
  bsprt::SceneOptions o;
  o.allow_nonfinite = allow_nonfinite;
  py::gil_scoped_release release;  // the exact degeneracy test of every triangle
  return bsprt::Scene::from_arrays({v.data(), std::size_t(v.size())}, idx, o);
}

}  // namespace

PYBIND11_MODULE(_bsprt, m) {
  m.doc() = "bsprt: exact general BSP trees, certified ray tracing (docs/api.md)";
  m.attr("__version__") = bsprt::version();
  m.attr("HIT_DTYPE") = hit_dtype();
  py::register_exception<bsprt::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<bsprt::Cancelled>(m, "Cancelled", PyExc_RuntimeError);
  // bsprt::UsageError derives from std::invalid_argument: pybind11 raises ValueError.

  py::class_<bsprt::Scene>(m, "Scene")
      .def(py::init(&scene_from_arrays), py::arg("vertices"), py::arg("faces"), py::arg("allow_nonfinite") = false,
           "vertices: (V, 3) float32; faces: (F, 3) integer vertex indices, 0-based.")
      .def_static(
          "load",
          [](const py::object& path, bool allow_nonfinite) {
            const std::string p = path_of(path);
            bsprt::SceneOptions o;
            o.allow_nonfinite = allow_nonfinite;
            py::gil_scoped_release release;
            return bsprt::Scene::load(p, o);
          },
          py::arg("path"), py::arg("allow_nonfinite") = false,
          "Loads an OBJ, PLY, OFF or STL file (every face kept), or 'default' for the embedded scene.")
      .def_static("default", &bsprt::Scene::default_scene, "The embedded default scene.")
      .def_property_readonly("triangle_count", &bsprt::Scene::triangle_count)
      .def_property_readonly("vertex_count", &bsprt::Scene::vertex_count)
      .def_property_readonly("fingerprint", &bsprt::Scene::fingerprint)
      .def_property_readonly("bounds",
                             [](const bsprt::Scene& s) {
                               const bsprt::Box3f b = s.bounds();
                               return py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z),
                                                     py::make_tuple(b.hi.x, b.hi.y, b.hi.z));
                             })
      .def_property_readonly("summary",
                             [](const bsprt::Scene& s) {
                               const bsprt::SceneSummary& r = s.summary();
                               py::dict d;
                               d["source"] = r.source;
                               d["vertices"] = r.vertices;
                               d["unreferenced_vertices"] = r.unreferenced_vertices;
                               d["triangles"] = r.triangles;
                               d["degenerate"] = r.degenerate;
                               d["nonfinite_triangles"] = r.nonfinite_triangles;
                               return d;
                             })
      .def("build", &build, py::arg("accel") = "bsp", py::arg("threads") = 0, py::arg("membership") = "area",
           py::arg("progress") = py::none(),
           "Builds a kd-tree or the exact BSP tree; progress(done, total) is called while it runs.")
      .def(
          "verify",
          [](const bsprt::Scene& s, const bsprt::Tree& t, int threads, bool strict) {
            bsprt::VerifyOptions o;
            o.threads = threads;
            o.strict = strict;
            bsprt::Certificate c;
            {
              py::gil_scoped_release release;
              c = bsprt::verify(s, t, o);
            }
            return certificate_dict(c);
          },
          py::arg("tree"), py::arg("threads") = 0, py::arg("strict") = false,
          "Exact, independent certificate of a tree (what `bsprt verify` prints).");

  py::class_<bsprt::Tree>(m, "Tree")
      .def_static(
          "load",
          [](const py::object& path, const bsprt::Scene& scene) {
            const std::string p = path_of(path);
            py::gil_scoped_release release;
            return bsprt::Tree::load(p, scene);
          },
          py::arg("path"), py::arg("scene"))
      .def(
          "save",
          [](const bsprt::Tree& t, const py::object& path) {
            const std::string p = path_of(path);
            py::gil_scoped_release release;
            t.save(p);
          },
          py::arg("path"))
      .def_property_readonly("kind", [](const bsprt::Tree& t) { return t.kind() == bsprt::TreeKind::Kd ? "kd" : "bsp"; })
      .def_property_readonly("build_seconds", &bsprt::Tree::build_seconds)
      .def_property_readonly("nbytes", [](const bsprt::Tree& t) { return t.bytes().size(); });

  py::class_<bsprt::Tracer>(m, "_Tracer")
      .def(py::init([](const bsprt::Scene& scene, const bsprt::Tree& tree, const std::string& mode) {
             py::gil_scoped_release release;  // flattening or loading the tree
             return bsprt::Tracer(scene, tree, mode);
           }),
           py::arg("scene"), py::arg("tree"), py::arg("mode") = "certified", py::keep_alive<1, 2>())
      .def_static(
          "by_name",
          [](const bsprt::Scene& scene, const std::string& accel) {
            py::gil_scoped_release release;  // builds the accelerator in memory
            return bsprt::Tracer::by_name(scene, accel);
          },
          py::arg("scene"), py::arg("accel"))
      .def_static("accelerators", &bsprt::Tracer::accelerators)
      .def_property_readonly("name", &bsprt::Tracer::name)
      .def_property_readonly("certified", &bsprt::Tracer::certified)
      .def_property_readonly("memory_bytes", &bsprt::Tracer::memory_bytes)
      .def(
          "_intersect_rays",
          [](const bsprt::Tracer& t, const py::array& rays, int threads, int packet_width) {
            const std::span<const Ray> in = rays_of(rays);
            py::array hits = new_hits(in.size());
            std::span<Hit> out(static_cast<Hit*>(hits.mutable_data()), in.size());
            {
              py::gil_scoped_release release;
              t.intersect(in, out, trace_options(threads, packet_width));
            }
            return hits;
          },
          py::arg("rays"), py::arg("threads") = 0, py::arg("packet_width") = 1)
      .def(
          "_occluded_rays",
          [](const bsprt::Tracer& t, const py::array& rays, int threads, int packet_width) {
            const std::span<const Ray> in = rays_of(rays);
            py::array_t<std::uint8_t> occ(py::ssize_t(in.size()));
            std::span<std::uint8_t> out(occ.mutable_data(), in.size());
            {
              py::gil_scoped_release release;
              t.occluded(in, out, trace_options(threads, packet_width));
            }
            return occ;
          },
          py::arg("rays"), py::arg("threads") = 0, py::arg("packet_width") = 1);

  py::class_<bsprt::MeshQuery>(m, "_MeshQuery")
      .def(py::init([](const bsprt::Scene& scene) {
             py::gil_scoped_release release;  // the exact reference's AABB tree
             return bsprt::MeshQuery(scene);
           }),
           py::arg("scene"))
      .def_property_readonly("open_or_inconsistent_edges",
                             [](const bsprt::MeshQuery& q) {
                               py::gil_scoped_release release;
                               return q.open_or_inconsistent_edges();
                             })
      .def(
          "_sides",
          [](const bsprt::MeshQuery& q, const py::array& points, int threads) {
            require<float>(points, "points", 3);
            const std::span<const bsprt::Vec3f> in(reinterpret_cast<const bsprt::Vec3f*>(points.data()),
                                                   std::size_t(points.shape(0)));
            py::array_t<std::uint8_t> sides(py::ssize_t(in.size()));
            std::span<bsprt::PointSide> out(reinterpret_cast<bsprt::PointSide*>(sides.mutable_data()), in.size());
            bsprt::QueryOptions o;
            o.threads = threads;
            {
              py::gil_scoped_release release;
              q.sides(in, out, o);
            }
            return sides;
          },
          py::arg("points"), py::arg("threads") = 0)
      .def(
          "_all_hits",
          [](const bsprt::MeshQuery& q, const py::array& rays, int threads) {
            const std::span<const Ray> in = rays_of(rays);
            bsprt::QueryOptions o;
            o.threads = threads;
            std::vector<bsprt::Crossing> xs;
            {
              py::gil_scoped_release release;
              xs = q.all_hits(in, o);
            }
            const py::ssize_t n = py::ssize_t(xs.size());
            py::array_t<std::int64_t> ray(n);
            py::array_t<std::uint32_t> prim(n);
            py::array_t<float> t(n);
            py::array_t<std::int8_t> side(n);
            for (py::ssize_t i = 0; i < n; ++i) {
              const bsprt::Crossing& x = xs[std::size_t(i)];
              ray.mutable_at(i) = std::int64_t(x.ray);
              prim.mutable_at(i) = x.prim;
              t.mutable_at(i) = x.t;
              side.mutable_at(i) = std::int8_t(x.side);
            }
            return py::make_tuple(ray, prim, t, side);
          },
          py::arg("rays"), py::arg("threads") = 0);

  m.def(
      "read_rays",
      [](const py::object& path) {
        const std::string p = path_of(path);
        std::vector<Ray> rays;
        {
          py::gil_scoped_release release;
          rays = bsprt::read_rays(p);
        }
        py::array_t<float> a(std::vector<py::ssize_t>{py::ssize_t(rays.size()), 8});
        if (!rays.empty()) std::memcpy(a.mutable_data(), rays.data(), rays.size() * sizeof(Ray));
        return a;
      },
      py::arg("path"), "Reads a .rays file as an (N, 8) float32 array: org, tnear, dir, tfar.");
  m.def(
      "write_rays",
      [](const py::object& path, const py::array& rays) {
        const std::string p = path_of(path);
        const std::span<const Ray> r = rays_of(rays);
        py::gil_scoped_release release;
        bsprt::write_rays(p, r);
      },
      py::arg("path"), py::arg("rays"));
  m.def(
      "read_hits",
      [](const py::object& path) {
        const std::string p = path_of(path);
        std::vector<Hit> hits;
        {
          py::gil_scoped_release release;
          hits = bsprt::read_hits(p);
        }
        py::array a = new_hits(hits.size());
        if (!hits.empty()) std::memcpy(a.mutable_data(), hits.data(), hits.size() * sizeof(Hit));
        return a;
      },
      py::arg("path"), "Reads a .hits file as a structured array of HIT_DTYPE records.");
  m.def(
      "write_hits",
      [](const py::object& path, const py::array& hits) {
        const std::string p = path_of(path);
        const std::span<const Hit> h = hits_of(hits, "hits");
        py::gil_scoped_release release;
        bsprt::write_hits(p, h);
      },
      py::arg("path"), py::arg("hits"));
  m.def(
      "compare",
      [](const py::array& reference, const py::array& tested, double rel_tol) {
        const std::span<const Hit> r = hits_of(reference, "reference"), t = hits_of(tested, "tested");
        bsprt::HitComparison c;
        {
          py::gil_scoped_release release;
          c = bsprt::compare_hits(r, t, rel_tol);
        }
        return comparison_dict(c);
      },
      py::arg("reference"), py::arg("tested"), py::arg("rel_tol") = 1e-5,
      "Ray-by-ray comparison, the vocabulary of `bsprt compare`.");
}
