/// \file verify_structure.cpp
/// The verifier's structural pass (verify_detail.h): property (d) and the
/// preorder/listing tables the exact walk uses.
#include <algorithm>
#include <cmath>
#include <string>

#include "verify/verify_detail.h"

namespace bsprt {

std::string VerifyFailure::describe() const {
  std::string s = what;
  if (node != 0xFFFFFFFFu) s += "; node " + std::to_string(node);
  if (flat_node != 0xFFFFFFFFu) s += "; flat node " + std::to_string(flat_node);
  if (triangle != 0xFFFFFFFFu) s += "; triangle " + std::to_string(triangle);
  if (witness) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "; witness point (%.17g, %.17g, %.17g)", witness->x, witness->y,
                  witness->z);
    s += buf;
  }
  return s;
}

namespace vfy {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;
constexpr std::uint32_t kMaxDepth = 1024;

VerifyFailure failure(std::string what, std::uint32_t node = kNone, std::uint32_t tri = kNone) {
  VerifyFailure f;
  f.what = std::move(what);
  f.node = node;
  f.triangle = tri;
  return f;
}

bool plane_ok(const TriangleSoup& soup, const std::vector<std::uint8_t>& degen, PlaneDef p) {
  if (p.kind == PlaneKind::Kd) return p.sub <= 2 && std::isfinite(p.coord());
  if (p.kind != PlaneKind::Face && p.kind != PlaneKind::Edge) return false;
  if (p.kind == PlaneKind::Face && p.sub != 0) return false;
  if (p.sub > 2 || p.tri() >= soup.size()) return false;
  return degen[p.tri()] == 0;
}

bool check_header(const TriangleSoup& soup, const VerifyInput& in, const Structure& st, FailureSink& sink) {
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(in.root_box.lo[a]) && std::isfinite(in.root_box.hi[a]) &&
          in.root_box.lo[a] < in.root_box.hi[a])) {
      sink.fail(failure("root box is empty, flat or not finite"));
      return false;
    }
  if (in.membership > 1) {
    sink.fail(failure("unknown membership rule " + std::to_string(in.membership)));
    return false;
  }
  for (std::uint32_t t = 0; t < soup.size(); ++t) {
    if (st.degenerate[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const Vec3f& c = soup.corner(t, k);
      for (int a = 0; a < 3; ++a)
        if (!(c[a] >= in.root_box.lo[a] && c[a] <= in.root_box.hi[a])) {
          VerifyFailure f = failure("triangle sticks out of the root box (its points outside lie in no leaf)",
                                    0, t);
          f.witness = Vec3d{double(c.x), double(c.y), double(c.z)};
          sink.fail(f);
          return false;
        }
    }
  }
  for (std::size_t i = 0; i < in.planes.size(); ++i)
    if (!plane_ok(soup, st.degenerate, in.planes[i])) {
      sink.fail(failure("plane " + std::to_string(i) +
                        " is out of range or lies on a degenerate triangle"));
      return false;
    }
  return true;
}

/// Leaf `node`: its refs in range, triangles in range, non-degenerate, unique.
bool check_leaf(const TriangleSoup& soup, const VerifyInput& in, const Structure& st, std::uint32_t node,
                FailureSink& sink) {
  const VerifyNode& n = in.nodes[node];
  if (std::uint64_t(n.a) + n.b > in.refs.size()) {
    sink.fail(failure("leaf list [" + std::to_string(n.a) + ", +" + std::to_string(n.b) +
                          ") runs past the reference list", node));
    return false;
  }
  std::vector<std::uint32_t> ids(in.refs.begin() + n.a, in.refs.begin() + n.a + n.b);
  for (std::uint32_t t : ids) {
    if (t >= soup.size()) {
      sink.fail(failure("leaf lists triangle " + std::to_string(t) + " but the scene has " +
                        std::to_string(soup.size()), node));
      return false;
    }
    if (st.degenerate[t]) {
      sink.fail(failure("leaf lists a degenerate triangle", node, t));
      return false;
    }
  }
  std::sort(ids.begin(), ids.end());
  const auto dup = std::adjacent_find(ids.begin(), ids.end());
  if (dup != ids.end()) {
    sink.fail(failure("leaf lists a triangle twice", node, *dup));
    return false;
  }
  return true;
}

/// Depth-first walk from the root: ids in range, each node once, preorder.
bool walk(const TriangleSoup& soup, const VerifyInput& in, Structure& st, FailureSink& sink) {
  const std::size_t n = in.nodes.size();
  if (n == 0) {
    sink.fail(failure("the tree has no nodes"));
    return false;
  }
  st.pre.assign(n, kNone);
  st.end.assign(n, kNone);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 0}};  // node, depth
  std::vector<std::uint32_t> order;
  std::uint32_t counter = 0;
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    if (st.pre[i] != kNone) {
      sink.fail(failure("node reached twice (the nodes do not form a tree)", i));
      return false;
    }
    if (depth > kMaxDepth) {
      sink.fail(failure("tree deeper than " + std::to_string(kMaxDepth) + " levels", i));
      return false;
    }
    st.pre[i] = counter++;
    order.push_back(i);
    const VerifyNode& nd = in.nodes[i];
    if (nd.plane == VerifyNode::kLeaf) {
      ++st.leaves;
      if (!check_leaf(soup, in, st, i, sink)) return false;
      continue;
    }
    if (nd.plane >= in.planes.size() || nd.a >= n || nd.b >= n) {
      sink.fail(failure("inner node refers to a plane or child out of range", i));
      return false;
    }
    stack.push_back({nd.b, depth + 1});
    stack.push_back({nd.a, depth + 1});
  }
  for (std::uint32_t i = 0; i < n; ++i)
    if (st.pre[i] == kNone) {
      sink.fail(failure("node not reachable from the root", i));
      return false;
    }
  // Subtree ends, children before parents (reverse preorder).
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const VerifyNode& nd = in.nodes[*it];
    st.end[*it] = nd.plane == VerifyNode::kLeaf ? st.pre[*it] + 1 : st.end[nd.b];
  }
  return true;
}

void index_listings(const TriangleSoup& soup, const VerifyInput& in, Structure& st) {
  st.tri_leaf_start.assign(soup.size() + 1, 0);
  for (const VerifyNode& nd : in.nodes)
    if (nd.plane == VerifyNode::kLeaf)
      for (std::uint32_t k = 0; k < nd.b; ++k) ++st.tri_leaf_start[in.refs[nd.a + k] + 1];
  for (std::size_t t = 0; t < soup.size(); ++t) st.tri_leaf_start[t + 1] += st.tri_leaf_start[t];
  st.tri_leaf_pre.assign(st.tri_leaf_start.back(), 0);
  std::vector<std::uint32_t> fill(st.tri_leaf_start.begin(), st.tri_leaf_start.end() - 1);
  for (std::uint32_t i = 0; i < in.nodes.size(); ++i) {
    const VerifyNode& nd = in.nodes[i];
    if (nd.plane != VerifyNode::kLeaf) continue;
    for (std::uint32_t k = 0; k < nd.b; ++k) st.tri_leaf_pre[fill[in.refs[nd.a + k]]++] = st.pre[i];
  }
  for (std::size_t t = 0; t < soup.size(); ++t)
    std::sort(st.tri_leaf_pre.begin() + st.tri_leaf_start[t], st.tri_leaf_pre.begin() + st.tri_leaf_start[t + 1]);
}

bool check_flat_header(const TriangleSoup& soup, const VerifyInput& in, FailureSink& sink) {
  if (!in.has_flat) return true;
  for (int a = 0; a < 3; ++a)
    if (!(in.flat_box.lo[a] == in.root_box.lo[a] && in.flat_box.hi[a] == in.root_box.hi[a])) {
      sink.fail(failure("flat root box differs from the exact root box"));
      return false;
    }
  if (in.flat_triangle_count != soup.size()) {
    sink.fail(failure("flat header triangle count differs from the scene"));
    return false;
  }
  return true;
}

}  // namespace

bool check_structure(const TriangleSoup& soup, const VerifyInput& in, Structure& st, FailureSink& sink) {
  st.degenerate.assign(soup.size(), 0);
  for (std::uint32_t t = 0; t < soup.size(); ++t) st.degenerate[t] = degenerate_exact(soup, t) ? 1 : 0;
  if (!check_header(soup, in, st, sink) || !walk(soup, in, st, sink) || !check_flat_header(soup, in, sink))
    return false;
  index_listings(soup, in, st);
  return true;
}

bool listed_in_subtree(const Structure& st, std::uint32_t tri, std::uint32_t node) {
  const auto b = st.tri_leaf_pre.begin() + st.tri_leaf_start[tri];
  const auto e = st.tri_leaf_pre.begin() + st.tri_leaf_start[tri + 1];
  const auto it = std::lower_bound(b, e, st.pre[node]);
  return it != e && *it < st.end[node];
}

}  // namespace vfy
}  // namespace bsprt
