#pragma once
/// \file mesh_scan.h
/// Internal to load_mesh: light pre-passes over a mesh file's bytes that run
/// before OpenMesh's reader. OpenMesh parses; these passes find what OpenMesh
/// would silently drop or misread (see the table at the top of load_mesh.cpp),
/// check the structure against the header's counts, and give error messages a
/// line number. Where OpenMesh would trip over a token that is legal for us
/// (a non-finite coordinate, a comment, an extra value), the pass overwrites
/// it in `bytes` with blanks or "0" of the same length (line numbers stay
/// valid) and records what it was.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "bsprt/vec3.h"

namespace bsprt::detail {

/// A vertex coordinate that is NaN or +-Inf in the file.
struct NonFiniteCoord {
  std::size_t vertex = 0;   ///< vertex (OBJ/PLY/OFF) or facet corner 3*f+k (STL)
  int axis = 0;             ///< 0, 1, 2 = x, y, z
  float value = 0;          ///< NaN or +-Inf
  std::int64_t line = -1;   ///< 1-based line, -1 in binary files
};

/// What a text token holds when read as a coordinate.
enum class NumberKind { finite, nonfinite, malformed };

/// Reads a decimal number the way C's strtod would, accepting also nan/inf
/// (any case, optional sign) and MSVC's spellings 1.#IND, 1.#INF, 1.#QNAN.
/// Overflow beyond float range counts as +-Inf.
NumberKind parse_coordinate(std::string_view token, float& value);

/// OBJ pre-pass: every `v` line's coordinates are checked (non-finite ones
/// recorded and replaced by "0" in `bytes`), and every `f` line's vertex
/// indices are read (negative ones resolved, range checked), because
/// OpenMesh's OBJ reader skips `v` lines it cannot parse (shifting all later
/// indices) and removes repeated indices from a face (which changes the
/// fan triangulation, and drops a face with fewer than 3 distinct corners).
struct ObjScan {
  std::size_t vertices = 0;                 ///< `v` lines
  std::vector<std::int64_t> face_line;      ///< 1-based line of each `f`
  std::vector<std::uint32_t> corners;       ///< resolved 0-based indices, faces back to back
  std::vector<std::size_t> face_begin{0};   ///< face f = corners[face_begin[f] .. face_begin[f+1])
  std::vector<std::int64_t> vertex_line;    ///< 1-based line of each `v`
  std::vector<NonFiniteCoord> nonfinite;
  std::size_t face_count() const { return face_line.size(); }
};
ObjScan scan_obj(const std::string& path, std::string& bytes);

/// PLY and OFF pre-pass: the header, then a walk over every element and
/// property (text tokens or binary bytes) that checks the file holds exactly
/// what the header declares, that every face has >= 3 in-range indices, and
/// (text files) what each vertex's coordinates are, for a cross-check of what
/// OpenMesh delivers.
struct ElementScan {
  bool binary = false;
  std::size_t vertices = 0;                 ///< declared vertex count
  std::size_t faces = 0;                    ///< declared face count
  std::size_t corners = 0;                  ///< sum of face sizes
  std::uint64_t index_sum = 0;              ///< sum of all face indices (mod 2^64), cross-check
  std::vector<Vec3f> coords;                ///< the pass's own reading (text: non-finite as 0)
  std::vector<std::int64_t> vertex_line;    ///< text files: 1-based line of each vertex
  std::vector<NonFiniteCoord> nonfinite;    ///< every non-finite x/y/z (text: blanked to 0)
  /// OpenMesh reads `openmesh_header` followed by bytes[body_offset..] (PLY:
  /// a rebuilt header; OFF: the file as is).
  std::string openmesh_header;
  std::size_t body_offset = 0;
};
ElementScan scan_ply(const std::string& path, std::string& bytes);
ElementScan scan_off(const std::string& path, std::string& bytes);

/// STL pre-pass: binary vs ascii (by size, as OpenMesh does, but a size that
/// fits neither is an error), and every facet's three corners, because
/// OpenMesh's STL reader merges equal corners and then drops facets whose
/// corners merged (so facet numbering would shift). Ascii: the solid's name
/// is blanked (OpenMesh starts a facet at any line containing "outer").
struct StlScan {
  bool binary = false;
  std::vector<Vec3f> corners;               ///< 3 per facet, non-finite as read
  std::vector<std::int64_t> facet_line;     ///< ascii: 1-based line of each `facet`
  std::vector<NonFiniteCoord> nonfinite;    ///< vertex = 3*facet + corner
  std::size_t facet_count() const { return corners.size() / 3; }
};
StlScan scan_stl(const std::string& path, std::string& bytes);

}  // namespace bsprt::detail
