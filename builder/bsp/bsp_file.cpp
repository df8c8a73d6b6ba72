/// \file bsp_file.cpp
/// Exact BSP tree <-> tree file (bsp_file.h).
#include "builder/bsp/bsp_file.h"

#include <cmath>
#include <stdexcept>

#include "bsprt/error.h"
#include "robust/exact_side.h"

namespace bsprt {

void add_bsp_sections(TreeFileWriter& w, const BspTree& tree) {
  const Box3f& b = tree.root_box();
  const BspHeaderRecord h{{b.lo.x, b.lo.y, b.lo.z},
                          {b.hi.x, b.hi.y, b.hi.z},
                          static_cast<std::uint32_t>(tree.membership()),
                          tree.coplanar_to_both() ? 1u : 0u};
  w.add_array(kBspHeaderTag, std::vector<BspHeaderRecord>{h});
  w.add_array(kBspPlanesTag, tree.planes());
  w.add_array(kBspNodesTag, tree.nodes());
  w.add_array(kBspRefsTag, tree.triangle_refs());
}

BspTree read_bsp_sections(const TreeFileReader& r, const TriangleSoup& soup) {
  const BspHeaderRecord h = r.record<BspHeaderRecord>(kBspHeaderTag);
  Box3f box;
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(h.root_lo[a]) && std::isfinite(h.root_hi[a]) && h.root_lo[a] < h.root_hi[a]))
      throw InputError(r.path(), "BSP root box is empty, flat or not finite");
    box.lo[a] = h.root_lo[a];
    box.hi[a] = h.root_hi[a];
  }
  if (h.membership > 1 || h.flags > 1) throw InputError(r.path(), "BSP header has unknown membership or flags");
  std::vector<PlaneDef> planes = r.array<PlaneDef>(kBspPlanesTag);
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const PlaneDef p = planes[i];
    if (!plane_in_range(soup, p) || (!p.is_kd() && triangle_degenerate_exact(soup, p.tri())))
      throw InputError(r.path(), "BSP plane " + std::to_string(i) +
                                     " is out of range or lies on a degenerate triangle");
  }
  BspTree tree(box, std::move(planes), r.array<BspNode>(kBspNodesTag),
               r.array<std::uint32_t>(kBspRefsTag), static_cast<BspMembership>(h.membership),
               (h.flags & 1u) != 0);
  try {
    tree.validate(soup.size(), &soup);
  } catch (const std::logic_error& e) {
    throw InputError(r.path(), e.what());
  }
  return tree;
}

void write_bsp_file(const std::string& path, const TriangleSoup& soup, const BspTree& tree) {
  TreeFileWriter w(TreeKind::Bsp, soup);
  add_bsp_sections(w, tree);
  w.write(path);
}

BspTree read_bsp_file(const std::string& path, const TriangleSoup& soup) {
  const TreeFileReader r(path);
  if (r.kind() != TreeKind::Bsp) throw InputError(path, "not a BSP tree file (it holds another tree kind)");
  r.check_scene(soup);
  return read_bsp_sections(r, soup);
}

}  // namespace bsprt
