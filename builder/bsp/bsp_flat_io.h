#pragma once
/// \file bsp_flat_io.h
/// The float flattening of a BSP tree (traverse/bsp_node.h) as extra sections
/// of the BSP tree file (bsp_file.h, TreeKind::Bsp), so `--accel bsp --tree`
/// can trace without re-certifying the epsilons (which needs the exact cells).
///
/// Sections (little-endian, verbatim structs):
///   FHDR  FlatBspHeaderRecord (32 bytes)
///   FNOD  FlatBspNode[]       (16-byte slots, node 0 = root; a plane node takes two, layout in bsp_node.h)
///   FPRM  uint32[]            leaf triangle lists, concatenated

#include <cstdint>
#include <string>

#include "builder/bsp/bsp_file.h"
#include "builder/bsp/bsp_tree.h"
#include "builder/tree_file.h"
#include "traverse/bsp/bsp_node.h"

namespace bsprt {

inline constexpr std::uint32_t kFlatBspHeaderTag = tree_tag("FHDR");  ///< FlatBspHeaderRecord
inline constexpr std::uint32_t kFlatBspNodesTag = tree_tag("FNOD");   ///< FlatBspNode[]
inline constexpr std::uint32_t kFlatBspPrimsTag = tree_tag("FPRM");   ///< uint32 triangle ids

/// Version of the flat layout; bump when FlatBspNode or the epsilon rules change.
inline constexpr std::uint32_t kFlatBspVersion = 1;

/// Fixed-layout header of the flat sections:
///   offset size field
///   0      12   float root_lo[3]
///   12     12   float root_hi[3]
///   24     4    flat layout version (kFlatBspVersion)
///   28     4    triangle count of the scene
struct FlatBspHeaderRecord {
  float root_lo[3];
  float root_hi[3];
  std::uint32_t version;
  std::uint32_t triangle_count;
};
static_assert(sizeof(FlatBspHeaderRecord) == 32, "FlatBspHeaderRecord is written verbatim");

/// Adds the flat tree's sections to a writer.
void add_flat_bsp_sections(TreeFileWriter& w, const FlatBspTree& flat);

/// True when the file holds the flat sections.
bool has_flat_bsp_sections(const TreeFileReader& r);

/// Reads the flat sections. Throws InputError naming the file when they are
/// missing, of another layout version or scene, or fail FlatBspTree::validate().
FlatBspTree read_flat_bsp_sections(const TreeFileReader& r, const TriangleSoup& soup);

/// The complete BSP tree file (exact sections, flattening, optional BRPT), ready
/// to write or to keep in memory.
TreeFileWriter bsp_tree_file(const TriangleSoup& soup, const BspTree& exact, const FlatBspTree& flat,
                             const BspReportRecord* report = nullptr);

/// Writes a complete BSP tree file: the exact tree's sections and its flattening.
/// With `report`, the build figures go along in an optional BRPT section.
void write_bsp_file_with_flat(const std::string& path, const TriangleSoup& soup,
                              const BspTree& exact, const FlatBspTree& flat,
                              const BspReportRecord* report = nullptr);

}  // namespace bsprt
