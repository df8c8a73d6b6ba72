#pragma once
/// \file openmesh_import.h
/// Internal to load_mesh: runs one of OpenMesh's readers over a file's bytes
/// with an importer that records every vertex and face exactly as the reader
/// delivers them (no halfedge mesh, so nothing is dropped on our side), and
/// with OpenMesh's console output captured instead of printed.

#include <cstdint>
#include <string>
#include <vector>

#include "bsprt/vec3.h"

namespace bsprt::detail {

/// What an OpenMesh reader delivered, in delivery order.
struct OpenMeshResult {
  std::vector<Vec3f> vertices;             ///< add_vertex / set_point values
  std::vector<std::int64_t> corners;       ///< face vertex handles, all faces back to back
  std::vector<std::size_t> face_begin;     ///< face f uses corners[face_begin[f] .. face_begin[f+1])
  std::string log;                         ///< whatever OpenMesh printed (omerr/omlog/omout/std::cerr)

  std::size_t face_count() const { return face_begin.empty() ? 0 : face_begin.size() - 1; }
  std::size_t face_size(std::size_t f) const { return face_begin[f + 1] - face_begin[f]; }
  std::int64_t corner(std::size_t f, std::size_t k) const { return corners[face_begin[f] + k]; }
};

/// Runs OpenMesh::IO::IOManager().read on `bytes` as a file of extension `ext`
/// ("obj", "ply", "off", "stl"); `stl_binary` selects the binary STL reader
/// (OpenMesh cannot tell from a stream). Serialized by a global mutex, because
/// OpenMesh's readers are singletons with per-read state and its log streams
/// are global. Throws InputError (naming `path` and quoting OpenMesh's log)
/// when the reader reports failure.
OpenMeshResult openmesh_read(const std::string& path, const std::string& bytes,
                             const std::string& ext, bool stl_binary = false);

}  // namespace bsprt::detail
