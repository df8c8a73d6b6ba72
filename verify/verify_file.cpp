/// \file verify_file.cpp
/// Tree file → VerifyInput (verify_file.h).
#include "verify/verify_file.h"

#include "builder/bsp/bsp_file.h"
#include "builder/bsp/bsp_flat_io.h"
#include "bsprt/error.h"

namespace bsprt {

static_assert(sizeof(VerifyNode) == sizeof(BspNode), "VerifyNode mirrors BspNode");

VerifyInput read_verify_input(const TreeFileReader& r, const TriangleSoup& soup) {
  if (r.kind() != TreeKind::Bsp) throw InputError(r.path(), "not a BSP tree file");
  r.check_scene(soup);
  VerifyInput in;
  const BspHeaderRecord h = r.record<BspHeaderRecord>(kBspHeaderTag);
  for (int a = 0; a < 3; ++a) {
    in.root_box.lo[a] = h.root_lo[a];
    in.root_box.hi[a] = h.root_hi[a];
  }
  in.membership = h.membership;
  in.coplanar_to_both = (h.flags & 1u) != 0;
  in.planes = r.array<PlaneDef>(kBspPlanesTag);
  in.nodes = r.array<VerifyNode>(kBspNodesTag);
  in.refs = r.array<std::uint32_t>(kBspRefsTag);
  in.has_flat = has_flat_bsp_sections(r);
  if (in.has_flat) {
    const FlatBspHeaderRecord fh = r.record<FlatBspHeaderRecord>(kFlatBspHeaderTag);
    if (fh.version != kFlatBspVersion)  // read_flat_bsp_sections refuses it too: no traversal could load it
      throw InputError(r.path(), "flat BSP layout version " + std::to_string(fh.version) + ", expected " +
                                     std::to_string(kFlatBspVersion));
    for (int a = 0; a < 3; ++a) {
      in.flat_box.lo[a] = fh.root_lo[a];
      in.flat_box.hi[a] = fh.root_hi[a];
    }
    in.flat_triangle_count = fh.triangle_count;
    in.flat_nodes = r.array<FlatBspNode>(kFlatBspNodesTag);
    in.flat_prims = r.array<std::uint32_t>(kFlatBspPrimsTag);
  }
  return in;
}

VerifyInput read_verify_input(const std::string& path, const TriangleSoup& soup) {
  const TreeFileReader r(path);
  return read_verify_input(r, soup);
}

}  // namespace bsprt
