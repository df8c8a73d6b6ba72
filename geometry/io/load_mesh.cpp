/// \file load_mesh.cpp
/// Loading OBJ, PLY, OFF and STL through OpenMesh's IO layer into a triangle
/// soup, without losing or misreading anything.
///
/// OpenMesh 9.0's readers parse the files; a recording importer
/// (openmesh_import.cpp) takes every vertex and face they deliver. Light
/// pre-passes (mesh_scan_*.cpp) run first, because the readers on their own
/// silently lose or misread data. What we found (by reading OpenMesh 9.0's
/// reader sources and by experiment), and what we do about it:
///
/// | reader | silent behaviour | handling |
/// |---|---|---|
/// | all | warnings go to omerr/omlog or std::cerr | captured into a string during the read; quoted in errors |
/// | all | ImporterT (halfedge mesh) drops non-manifold faces and faces with bad indices ("Face contains invalid vertex index") | our importer keeps every face; indices validated here |
/// | OBJ | a `v` line whose x, y or z `>> double` cannot read (nan, inf, 1.#IND) is skipped, shifting every later index | pre-pass finds them, writes "0" in their place for OpenMesh, puts the value back after |
/// | OBJ | repeated indices in a face are removed, a face left with < 3 corners is dropped | pre-pass reads each face's indices; we triangulate those and check OpenMesh's face is their de-duplication |
/// | OBJ | negative indices | OpenMesh resolves them (counting `v` lines); the pre-pass does too and they must agree |
/// | OBJ | `mtllib` opens and reads any named file (relative to a stale folder when reading a stream) | pre-pass blanks `mtllib` lines: materials are not used |
/// | PLY/OFF text | `>> float` on nan/inf fails and derails every later value | pre-pass blanks them to "0" and records them |
/// | PLY/OFF | fewer values than the header declares: reads stop at EOF (PLY) or read garbage (OFF faces); more: ignored | pre-pass walks every element and requires the exact count, byte or token |
/// | PLY | list properties other than vertex_indices (before/in the face element) are skipped as one scalar | rejected with an InputError |
/// | PLY | the header parser loops forever on some malformed lines (e.g. "format ascii x.0") | we parse the header strictly and hand OpenMesh a rebuilt one |
/// | PLY/OFF | indices arrive unsigned (a negative one wraps) | range-checked in the pre-pass and again here |
/// | OFF | counts on the OFF line are lost; comments and face colors without a 'C' header derail it | pre-pass moves the counts to their own line, blanks comments and those colors |
/// | STL | corners are merged and a facet whose corners merged is dropped | pre-pass reads every facet's corners; dropped facets are put back in place |
/// | STL | ascii vs binary chosen by file size; NaN breaks its vertex map | a size fitting neither is an error; non-finite STLs bypass OpenMesh (see load_stl) |
/// | STL ascii | any line containing "outer" starts a facet ("solid outer_shell") | pre-pass blanks the solid's name |
///
/// After the read, every count and value that both OpenMesh and the pre-pass
/// saw is compared, and any disagreement is an InputError: nothing is dropped
/// or misread without an error.

#include "geometry/io/load_mesh.h"

#include <algorithm>
#include <cfloat>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <fstream>
#include <map>
#include <sstream>
#include <cstring>

#include "bsprt/error.h"
#include "geometry/core/read_file.h"
#include "geometry/io/mesh_scan.h"
#include "geometry/io/openmesh_import.h"
#include "robust/degenerate.h"

namespace bsprt {
namespace {

using detail::ElementScan;
using detail::NonFiniteCoord;
using detail::OpenMeshResult;

/// A polygon soup before triangulation, with lines for messages.
struct Polygons {
  std::vector<Vec3f> vertices;
  std::vector<std::uint32_t> corners;
  std::vector<std::size_t> face_begin{0};
  std::vector<std::int64_t> vertex_line;   ///< may be empty (binary files)
  std::vector<std::int64_t> face_line;     ///< may be empty
  std::size_t face_count() const { return face_begin.size() - 1; }
  std::int64_t line_of_vertex(std::size_t v) const { return v < vertex_line.size() ? vertex_line[v] : -1; }
  std::int64_t line_of_face(std::size_t f) const { return f < face_line.size() ? face_line[f] : -1; }
};

std::string lower_extension(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  const std::size_t dot = name.rfind('.');
  std::string ext = dot == std::string::npos ? "" : name.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string read_file(const std::string& path) {
  std::string bytes = read_file_bytes(path, "mesh file");
  if (bytes.empty()) throw InputError(path, "file is empty");
  return bytes;
}

std::string describe(const Vec3f& p) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

std::string describe_face(const std::int64_t* idx, std::size_t n) {
  std::ostringstream s;
  s << "[";
  for (std::size_t k = 0; k < n; ++k) s << (k ? " " : "") << idx[k];
  s << "]";
  return s.str();
}

/// Same value, where -0 == 0 and NaN == NaN (what a read of the same text or
/// bytes gives twice).
bool same_value(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool same_point(const Vec3f& a, const Vec3f& b) {
  return same_value(a.x, b.x) && same_value(a.y, b.y) && same_value(a.z, b.z);
}

void patch_nonfinite(std::vector<Vec3f>& vertices, const std::vector<NonFiniteCoord>& nonfinite) {
  for (const NonFiniteCoord& n : nonfinite) vertices[n.vertex][n.axis] = n.value;
}

// ---------------------------------------------------------------------------
// OBJ

/// OpenMesh's OBJ reader removes repeated indices from a face (keeping first
/// occurrences) and drops the face when fewer than 3 remain.
std::vector<std::int64_t> openmesh_obj_face(const std::uint32_t* idx, std::size_t n) {
  std::vector<std::int64_t> out;
  for (std::size_t k = 0; k < n; ++k)
    if (std::find(out.begin(), out.end(), std::int64_t{idx[k]}) == out.end()) out.push_back(idx[k]);
  if (out.size() < 3) out.clear();
  return out;
}

void cross_check_obj_faces(const std::string& path, const detail::ObjScan& scan, const OpenMeshResult& om) {
  std::size_t j = 0;
  for (std::size_t f = 0; f < scan.face_count(); ++f) {
    const std::size_t n = scan.face_begin[f + 1] - scan.face_begin[f];
    const std::vector<std::int64_t> expect = openmesh_obj_face(&scan.corners[scan.face_begin[f]], n);
    if (expect.empty()) continue;
    const bool same = j < om.face_count() && om.face_size(j) == expect.size() &&
                      std::equal(expect.begin(), expect.end(), om.corners.begin() + std::ptrdiff_t(om.face_begin[j]));
    if (!same) {
      const std::string got = j < om.face_count() ? describe_face(&om.corners[om.face_begin[j]], om.face_size(j)) : "nothing";
      throw InputError(path, scan.face_line[f], "OpenMesh read this face as " + got + " but the line lists " +
                                                    describe_face(expect.data(), expect.size()) + " (0-based)");
    }
    ++j;
  }
  if (j != om.face_count())
    throw InputError(path, "OpenMesh read " + std::to_string(om.face_count()) + " faces, the file has " + std::to_string(j));
}

Polygons load_obj(const std::string& path, std::string& bytes) {
  detail::ObjScan scan = detail::scan_obj(path, bytes);
  OpenMeshResult om = detail::openmesh_read(path, bytes, "obj");
  if (om.vertices.size() != scan.vertices)
    throw InputError(path, "OpenMesh read " + std::to_string(om.vertices.size()) + " vertices, the file has " +
                               std::to_string(scan.vertices) + " `v` lines");
  patch_nonfinite(om.vertices, scan.nonfinite);
  cross_check_obj_faces(path, scan, om);
  Polygons p;
  p.vertices = std::move(om.vertices);
  p.corners = std::move(scan.corners);
  p.face_begin = std::move(scan.face_begin);
  p.vertex_line = std::move(scan.vertex_line);
  p.face_line = std::move(scan.face_line);
  return p;
}

// ---------------------------------------------------------------------------
// PLY and OFF

void cross_check_elements(const std::string& path, const ElementScan& scan, const OpenMeshResult& om) {
  auto fail = [&](const std::string& what) { throw InputError(path, "OpenMesh and the file disagree: " + what); };
  if (om.vertices.size() != scan.vertices)
    fail("OpenMesh read " + std::to_string(om.vertices.size()) + " vertices, the header declares " + std::to_string(scan.vertices));
  if (om.face_count() != scan.faces)
    fail("OpenMesh read " + std::to_string(om.face_count()) + " faces, the header declares " + std::to_string(scan.faces));
  if (om.corners.size() != scan.corners)
    fail("OpenMesh read " + std::to_string(om.corners.size()) + " face corners, the file has " + std::to_string(scan.corners));
  std::uint64_t sum = 0;
  for (std::int64_t c : om.corners) sum += static_cast<std::uint64_t>(c);
  if (sum != scan.index_sum) fail("OpenMesh read different face indices than the file holds");
  for (std::size_t v = 0; v < scan.coords.size(); ++v)
    if (!same_point(om.vertices[v], scan.coords[v]))
      throw InputError(path, v < scan.vertex_line.size() ? scan.vertex_line[v] : -1,
                       "OpenMesh read vertex " + std::to_string(v) + " as " + describe(om.vertices[v]) +
                           " but the file holds " + describe(scan.coords[v]));
}

Polygons load_elements(const std::string& path, std::string& bytes, const std::string& ext) {
  ElementScan scan = ext == "ply" ? detail::scan_ply(path, bytes) : detail::scan_off(path, bytes);
  if (scan.body_offset != 0 || !scan.openmesh_header.empty())
    bytes = scan.openmesh_header + bytes.substr(scan.body_offset);
  OpenMeshResult om = detail::openmesh_read(path, bytes, ext);
  cross_check_elements(path, scan, om);
  if (!scan.binary) patch_nonfinite(om.vertices, scan.nonfinite);
  Polygons p;
  p.vertices = std::move(om.vertices);
  p.corners.reserve(om.corners.size());
  for (std::int64_t c : om.corners) {
    if (c < 0 || static_cast<std::size_t>(c) >= p.vertices.size())
      throw InputError(path, "face vertex index " + std::to_string(c) + " out of range");
    p.corners.push_back(static_cast<std::uint32_t>(c));
  }
  p.face_begin = std::move(om.face_begin);
  p.vertex_line = std::move(scan.vertex_line);
  return p;
}

// ---------------------------------------------------------------------------
// STL

/// OpenMesh's STL vertex map order (CmpVec with eps = FLT_MIN): coordinates
/// closer than FLT_MIN are the same vertex.
struct StlLess {
  bool operator()(const Vec3f& a, const Vec3f& b) const {
    for (int k = 0; k < 2; ++k)
      if (!(std::fabs(a[k] - b[k]) <= FLT_MIN)) return a[k] < b[k] - FLT_MIN;
    return a.z < b.z - FLT_MIN;
  }
};

/// A non-finite corner breaks OpenMesh's vertex map (NaN compares equal to
/// anything), so such files (only loaded with allow_nonfinite) are built from
/// the pre-pass's corners directly, merging bit-identical corners.
Polygons stl_from_scan(const detail::StlScan& scan) {
  Polygons p;
  std::map<std::array<std::uint32_t, 3>, std::uint32_t> index;
  for (const Vec3f& c : scan.corners) {
    std::array<std::uint32_t, 3> key;
    std::memcpy(key.data(), &c, sizeof key);
    auto [it, added] = index.emplace(key, static_cast<std::uint32_t>(p.vertices.size()));
    if (added) p.vertices.push_back(c);
    p.corners.push_back(it->second);
    if (p.corners.size() % 3 == 0) p.face_begin.push_back(p.corners.size());
  }
  return p;
}

Polygons stl_from_openmesh(const std::string& path, const detail::StlScan& scan, OpenMeshResult& om) {
  std::map<Vec3f, std::uint32_t, StlLess> index;
  for (std::size_t v = 0; v < om.vertices.size(); ++v) index.emplace(om.vertices[v], static_cast<std::uint32_t>(v));
  Polygons p;
  std::size_t j = 0;
  for (std::size_t f = 0; f < scan.facet_count(); ++f) {
    const std::int64_t line = f < scan.facet_line.size() ? scan.facet_line[f] : -1;
    std::int64_t tri[3];
    for (int k = 0; k < 3; ++k) {
      const auto it = index.find(scan.corners[3 * f + static_cast<std::size_t>(k)]);
      if (it == index.end())
        throw InputError(path, line, "OpenMesh did not read corner " + std::to_string(k) + " of facet " + std::to_string(f) +
                                         " " + describe(scan.corners[3 * f + static_cast<std::size_t>(k)]));
      tri[k] = it->second;
      p.corners.push_back(it->second);
    }
    p.face_begin.push_back(p.corners.size());
    // OpenMesh drops a facet whose corners merged; we keep it in its place.
    if (tri[0] == tri[1] || tri[0] == tri[2] || tri[1] == tri[2]) continue;
    if (j >= om.face_count() || om.face_size(j) != 3 || !std::equal(tri, tri + 3, om.corners.begin() + std::ptrdiff_t(om.face_begin[j])))
      throw InputError(path, line, "OpenMesh read facet " + std::to_string(f) + " differently than the file holds");
    ++j;
  }
  if (j != om.face_count())
    throw InputError(path, "OpenMesh read " + std::to_string(om.face_count()) + " facets, the file has " + std::to_string(j) +
                               " non-degenerate ones");
  p.vertices = std::move(om.vertices);
  p.face_line = scan.facet_line;
  return p;
}

Polygons load_stl(const std::string& path, std::string& bytes, const LoadOptions& options) {
  const detail::StlScan scan = detail::scan_stl(path, bytes);
  if (!scan.nonfinite.empty()) {
    const NonFiniteCoord& n = scan.nonfinite.front();
    if (!options.allow_nonfinite)
      throw InputError(path, n.line, "facet " + std::to_string(n.vertex / 3) + " has a non-finite coordinate (" +
                                         std::to_string(n.value) + "); allow_nonfinite keeps such triangles as never-hit degenerates");
    return stl_from_scan(scan);
  }
  if (!scan.binary) {
    // OpenMesh reads the lines after `outer loop` as the three vertices, so a
    // blank line there (legal) failed the load (review of 2026-12-07). The
    // pre-scan has run and kept its line numbers: hand OpenMesh the text
    // without blank lines.
    std::string compact;
    compact.reserve(bytes.size());
    for (std::size_t at = 0; at < bytes.size();) {
      const std::size_t end = std::min(bytes.find('\n', at), bytes.size());
      const std::string_view line(bytes.data() + at, end - at);
      if (line.find_first_not_of(" \t\r\v\f") != std::string_view::npos) compact.append(line).push_back('\n');
      at = end + 1;
    }
    bytes = std::move(compact);
  }
  OpenMeshResult om = detail::openmesh_read(path, bytes, "stl", scan.binary);
  // OpenMesh's read is the cross-check of the pre-pass (every facet it keeps
  // must be the file's). The corners themselves come from the pre-pass:
  // OpenMesh merges corners closer than FLT_MIN, which moved (1e-39, 0, 0) to
  // the origin and made a real triangle degenerate, while the same triangles
  // from an OBJ kept their corners (review of 2026-12-07). Only bit-identical
  // corners share a vertex.
  Polygons checked = stl_from_openmesh(path, scan, om);
  Polygons p = stl_from_scan(scan);
  p.face_line = std::move(checked.face_line);
  return p;
}

// ---------------------------------------------------------------------------
// Common tail: triangulate, non-finite policy, degeneracy, report

/// Fan triangulation (v0, vj, vj+1), j = 1..k-2, faces in file order
/// (shared/formats.md).
void triangulate(const std::string& path, const Polygons& p, TriangleSoup& soup) {
  soup.vertices = p.vertices;
  soup.triangles.reserve(p.corners.size() - 2 * p.face_count());
  for (std::size_t f = 0; f < p.face_count(); ++f) {
    const std::uint32_t* c = &p.corners[p.face_begin[f]];
    const std::size_t k = p.face_begin[f + 1] - p.face_begin[f];
    if (k < 3) throw InputError(path, p.line_of_face(f), "face " + std::to_string(f) + " has fewer than 3 vertices");
    for (std::size_t j = 0; j < k; ++j)
      if (c[j] >= p.vertices.size()) throw InputError(path, p.line_of_face(f), "face vertex index out of range");
    for (std::size_t j = 1; j + 1 < k; ++j) soup.triangles.push_back({c[0], c[j], c[j + 1]});
  }
}

/// Counts triangles with a non-finite corner; throws unless allowed.
std::size_t apply_nonfinite_policy(const std::string& path, const Polygons& p, const TriangleSoup& soup,
                                   const LoadOptions& options) {
  std::size_t count = 0;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    for (std::uint32_t v : soup.triangles[t]) {
      if (is_finite(soup.vertices[v])) continue;
      if (!options.allow_nonfinite)
        throw InputError(path, p.line_of_vertex(v), "vertex #" + std::to_string(v) + " (0-based) " + describe(soup.vertices[v]) +
                                                        " is not finite and triangle " + std::to_string(t) +
                                                        " uses it; allow_nonfinite keeps such triangles as never-hit degenerates");
      ++count;
      break;
    }
  }
  return count;
}


}  // namespace

TriangleSoup load_mesh(const std::string& path, const LoadOptions& options, LoadReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const std::string ext = lower_extension(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a mesh file");
  if (ext != "obj" && ext != "ply" && ext != "off" && ext != "stl")
    throw InputError(path, "unknown mesh file extension '" + ext + "' (expected .obj, .ply, .off or .stl)");
  std::string bytes = read_file(path);
  Polygons polygons = ext == "obj" ? load_obj(path, bytes)
                      : ext == "stl" ? load_stl(path, bytes, options)
                                     : load_elements(path, bytes, ext);
  TriangleSoup soup;
  triangulate(path, polygons, soup);
  if (soup.triangles.empty()) throw InputError(path, "the file has no triangles");
  const std::size_t nonfinite = apply_nonfinite_policy(path, polygons, soup, options);
  const std::size_t degenerate = classify_degenerate(soup);
  if (report) {
    report->format = ext;
    report->vertices = soup.vertices.size();
    report->unreferenced_vertices = soup.unreferenced_vertex_count();
    report->faces = polygons.face_count();
    report->triangles = soup.triangles.size();
    report->degenerate = degenerate;
    report->nonfinite_triangles = nonfinite;
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return soup;
}

}  // namespace bsprt
