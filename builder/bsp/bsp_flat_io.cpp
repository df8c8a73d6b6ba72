/// \file bsp_flat_io.cpp
/// Flat BSP tree <-> tree file sections.
#include "builder/bsp/bsp_flat_io.h"

#include <stdexcept>
#include <vector>

#include "builder/bsp/bsp_file.h"
#include "builder/root_box.h"
#include "bsprt/error.h"

namespace bsprt {

void add_flat_bsp_sections(TreeFileWriter& w, const FlatBspTree& flat) {
  const FlatBspHeaderRecord h{{flat.bounds.lo.x, flat.bounds.lo.y, flat.bounds.lo.z},
                              {flat.bounds.hi.x, flat.bounds.hi.y, flat.bounds.hi.z},
                              kFlatBspVersion,
                              flat.triangle_count};
  w.add_array(kFlatBspHeaderTag, std::vector<FlatBspHeaderRecord>{h});
  w.add_array(kFlatBspNodesTag, flat.nodes);
  w.add_array(kFlatBspPrimsTag, flat.prims);
}

bool has_flat_bsp_sections(const TreeFileReader& r) {
  try {
    (void)r.section(kFlatBspHeaderTag);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

FlatBspTree read_flat_bsp_sections(const TreeFileReader& r, const TriangleSoup& soup) {
  const FlatBspHeaderRecord h = r.record<FlatBspHeaderRecord>(kFlatBspHeaderTag);
  if (h.version != kFlatBspVersion)
    throw InputError(r.path(), "flat BSP layout version " + std::to_string(h.version) +
                                   ", expected " + std::to_string(kFlatBspVersion));
  if (h.triangle_count != soup.size())
    throw InputError(r.path(), "flat BSP tree is for " + std::to_string(h.triangle_count) +
                                   " triangles, scene has " + std::to_string(soup.size()));
  FlatBspTree flat;
  flat.bounds.lo = {h.root_lo[0], h.root_lo[1], h.root_lo[2]};
  flat.bounds.hi = {h.root_hi[0], h.root_hi[1], h.root_hi[2]};
  flat.triangle_count = h.triangle_count;
  check_root_box(r.path(), "flat BSP root box", flat.bounds, soup);
  flat.nodes = r.array<FlatBspNode>(kFlatBspNodesTag);
  flat.prims = r.array<std::uint32_t>(kFlatBspPrimsTag);
  try {
    flat.validate();
  } catch (const std::logic_error& e) {
    throw InputError(r.path(), std::string("invalid flat BSP tree: ") + e.what());
  }
  if (flat_bsp_stats(flat).max_depth >= kBspMaxDepth)
    throw InputError(r.path(), "flat BSP tree deeper than " + std::to_string(kBspMaxDepth) + " levels");
  return flat;
}

TreeFileWriter bsp_tree_file(const TriangleSoup& soup, const BspTree& exact, const FlatBspTree& flat,
                             const BspReportRecord* report) {
  TreeFileWriter w(TreeKind::Bsp, soup);
  add_bsp_sections(w, exact);
  add_flat_bsp_sections(w, flat);
  if (report) w.add_section(kBspReportTag, std::as_bytes(std::span<const BspReportRecord>(report, 1)));
  return w;
}

void write_bsp_file_with_flat(const std::string& path, const TriangleSoup& soup,
                              const BspTree& exact, const FlatBspTree& flat,
                              const BspReportRecord* report) {
  bsp_tree_file(soup, exact, flat, report).write(path);
}

}  // namespace bsprt
