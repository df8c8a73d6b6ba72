/// \file verify_file.cpp
/// Tree file → VerifyInput (verify_file.h).
#include "builder/verify_file.h"

#include "builder/bsp_file.h"
#include "builder/bsp_flat_io.h"
#include "bsprt/error.h"

namespace bsprt {

static_assert(sizeof(VerifyNode) == sizeof(BspNode), "VerifyNode mirrors BspNode");

VerifyInput read_verify_input(const TreeFileReader& r, const TriangleSoup& soup) {
  if (r.kind() != TreeKind::Bsp) throw InputError(r.path(), "not a BSP tree file");
  r.check_scene(soup);
  VerifyInput in;
  const std::vector<BspHeaderRecord> h = r.array<BspHeaderRecord>(kBspHeaderTag);
  if (h.size() != 1) throw InputError(r.path(), "section BHDR must hold exactly one record");
  for (int a = 0; a < 3; ++a) {
    in.root_box.lo[a] = h[0].root_lo[a];
    in.root_box.hi[a] = h[0].root_hi[a];
  }
  in.membership = h[0].membership;
  in.coplanar_to_both = (h[0].flags & 1u) != 0;
  in.planes = r.array<PlaneDef>(kBspPlanesTag);
  in.nodes = r.array<VerifyNode>(kBspNodesTag);
  in.refs = r.array<std::uint32_t>(kBspRefsTag);
  in.has_flat = has_flat_bsp_sections(r);
  if (in.has_flat) {
    const std::vector<FlatBspHeaderRecord> fh = r.array<FlatBspHeaderRecord>(kFlatBspHeaderTag);
    if (fh.size() != 1) throw InputError(r.path(), "section FHDR must hold exactly one record");
    for (int a = 0; a < 3; ++a) {
      in.flat_box.lo[a] = fh[0].root_lo[a];
      in.flat_box.hi[a] = fh[0].root_hi[a];
    }
    in.flat_triangle_count = fh[0].triangle_count;
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
