#pragma once
/// \file bsp_file.h
/// The exact BSP tree's decisions in a tree file (tree_file.h, TreeKind::Bsp):
/// the root box, the plane table by defining input data (plane.h), the nodes and
/// the leaf triangle lists — nothing rounded, so `bsprt verify` can re-prove the
/// tree from the file alone. The float flattening (issue 5) adds its own
/// sections to the same file through add_bsp_sections/read_bsp_sections.
///
/// Sections (all little-endian, verbatim structs):
///   BHDR  BspHeaderRecord (32 bytes)
///   BPLN  PlaneDef[]      (8 bytes each)
///   BNOD  BspNode[]       (12 bytes each, node 0 = root)
///   BREF  uint32[]        leaf triangle lists, concatenated

#include <cstdint>
#include <string>

#include "builder/bsp/bsp_tree.h"
#include "builder/tree_file.h"

namespace bsprt {

inline constexpr std::uint32_t kBspHeaderTag = tree_tag("BHDR");  ///< BspHeaderRecord
inline constexpr std::uint32_t kBspPlanesTag = tree_tag("BPLN");  ///< PlaneDef[]
inline constexpr std::uint32_t kBspNodesTag = tree_tag("BNOD");   ///< BspNode[]
inline constexpr std::uint32_t kBspRefsTag = tree_tag("BREF");    ///< uint32 triangle ids
inline constexpr std::uint32_t kBspReportTag = tree_tag("BRPT");  ///< BspReportRecord (optional)

/// How the tree was built (optional section, for `bsprt stats`):
///   offset size field
///   0      8    double build seconds
///   8      8    uint64 side tests evaluated in interval arithmetic
///   16     8    uint64 side tests decided symbolically
///   24     8    uint64 exact fallbacks (side tests the filter could not decide)
///   32     8    uint64 point enclosures recomputed exactly
struct BspReportRecord {
  double seconds = 0;
  std::uint64_t filter_calls = 0;
  std::uint64_t symbolic = 0;
  std::uint64_t exact_fallbacks = 0;
  std::uint64_t exact_points = 0;
};
static_assert(sizeof(BspReportRecord) == 40, "BspReportRecord is written verbatim");

/// Fixed-layout header of a BSP tree file:
///   offset size field
///   0      12   float root_lo[3]
///   12     12   float root_hi[3]
///   24     4    membership (BspMembership)
///   28     4    flags: bit 0 = coplanar triangles listed on both sides
struct BspHeaderRecord {
  float root_lo[3];
  float root_hi[3];
  std::uint32_t membership;
  std::uint32_t flags;
};
static_assert(sizeof(BspHeaderRecord) == 32, "BspHeaderRecord is written verbatim");

/// Adds the exact tree's sections to a writer (TreeKind::Bsp).
void add_bsp_sections(TreeFileWriter& w, const BspTree& tree);

/// Reads the exact tree's sections. Throws InputError naming the file when the
/// data is inconsistent: plane definitions out of range or on degenerate
/// triangles, node/plane/triangle indices out of range, unreachable or shared
/// nodes, leaf lists that do not tile the reference list, a bad root box.
BspTree read_bsp_sections(const TreeFileReader& r, const TriangleSoup& soup);

/// Writes `tree` (built over `soup`) as a complete tree file.
void write_bsp_file(const std::string& path, const TriangleSoup& soup, const BspTree& tree);

/// Reads a BSP tree file for `soup` (checks kind, scene fingerprint, consistency).
BspTree read_bsp_file(const std::string& path, const TriangleSoup& soup);

}  // namespace bsprt
