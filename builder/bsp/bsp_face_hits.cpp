/// \file bsp_face_hits.cpp
/// Which face-plane splits prove hits (exact), and which hits they prove.
#include "builder/bsp/bsp_face_hits.h"

#include <algorithm>
#include <chrono>

#include "robust/cell.h"
#include "robust/exact_side.h"

namespace bsprt {

namespace {

/// True when every vertex of `half` lying on `face` (the cross-section of the
/// split cell) is inside triangle `tri`: on the non-negative side of its three
/// edge planes, whose normals point into the triangle (plane.h). The
/// cross-section is convex, so its vertices inside T put all of it inside T.
bool cross_section_inside(const TriangleSoup& soup, const Cell& half, PlaneDef face, std::uint32_t tri) {
  std::size_t on = 0;
  for (const CellVertex& v : half.vertices()) {
    if (!std::binary_search(v.facets.begin(), v.facets.end(), face)) continue;
    ++on;
    for (int k = 0; k < 3; ++k)
      if (exact_side_at(soup, PlaneDef::edge(tri, k), v.point.def) < 0) return false;
  }
  return on >= 3;  // a split that was accepted always leaves a polygon
}

}  // namespace

FaceHitLocator::FaceHitLocator(const BspTree& tree, const TriangleSoup& soup)
    : tree_(tree), soup_(soup), proves_(tree.nodes().size(), 0) {
  const auto start = std::chrono::steady_clock::now();
  approx_.reserve(tree.planes().size());
  for (PlaneDef p : tree.planes()) approx_.push_back(approx_plane(soup, p));
  ExactStats exact;
  tree.for_each_cell(
      soup,
      [&](std::uint32_t i, const Cell& cell) {
        const BspNode& n = tree.nodes()[i];
        if (n.is_leaf()) return;
        ++stats_.inner_nodes;
        const PlaneDef p = tree.plane_of(i);
        if (p.kind != PlaneKind::Face) return;
        ++stats_.face_nodes;
        Cell left, right;
        RoundingGuard g;
        const PreparedPlane pp = prepare_plane(g, soup, p);
        if (cell.split(g, soup, pp, left, right, exact) && cross_section_inside(soup, left, p, p.tri())) {
          proves_[i] = 1;
          ++stats_.proving_nodes;
        }
      },
      &exact);
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::uint32_t FaceHitLocator::proving_node(const Hit& hit) const {
  if (!hit.hit() || hit.prim >= soup_.size() || tree_.empty()) return kNone;
  const Vec3d a(soup_.corner(hit.prim, 0)), b(soup_.corner(hit.prim, 1)), c(soup_.corner(hit.prim, 2));
  return descend(0, a + (b - a) * double(hit.u) + (c - a) * double(hit.v), PlaneDef::face(hit.prim));
}

std::uint32_t FaceHitLocator::descend(std::uint32_t i, const Vec3d& p, PlaneDef own) const {
  while (!tree_.nodes()[i].is_leaf()) {
    const BspNode& n = tree_.nodes()[i];
    if (tree_.planes()[n.plane] == own && proves_[i]) return i;
    const double value = approx_[n.plane].eval(p);
    if (value == 0.0) {  // on the plane: in both closed children
      const std::uint32_t left = descend(n.a, p, own);
      return left != kNone ? left : descend(n.b, p, own);
    }
    i = value < 0.0 ? n.a : n.b;
  }
  return kNone;
}

}  // namespace bsprt
