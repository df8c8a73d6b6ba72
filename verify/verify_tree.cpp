/// \file verify_tree.cpp
/// The verifier's exact walk (verify.h): cells cut down the tree, triangle
/// pieces clipped down the tree, leaf lists checked against the rule, flat
/// nodes checked against their exact nodes. Subtrees run as oneTBB tasks.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "geometry/core/fp_env.h"
#include "verify/verify_cell.h"
#include "verify/verify_detail.h"

namespace bsprt {
namespace vfy {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

/// Per-thread sums.
struct Local {
  Counters c;
  std::uint64_t pairs = 0, required = 0, extra = 0, boundary = 0, flat_plane = 0, flat_kd = 0;
  double max_eps_use = 0.0;
  IT leaf_volume = IT(0.0);
};

struct Walk {
  const TriangleSoup& soup;
  const VerifyInput& in;
  const VerifyConfig& opt;
  const Structure& st;
  const PlaneTable& pt;
  FailureSink& sink;
  bool area_rule;
  std::unique_ptr<std::atomic<std::uint8_t>[]> flat_seen;
  std::atomic<std::uint64_t> leaves_done{0};
  tbb::enumerable_thread_specific<Local> local;

  void fail(const std::string& what, std::uint32_t node, std::uint32_t tri, std::uint32_t flat,
            const Vtx* witness) {
    VerifyFailure f;
    f.what = what;
    f.node = node;
    f.triangle = tri;
    f.flat_node = flat;
    if (witness) {
      const auto a = witness->approx();
      f.witness = Vec3d{a[0], a[1], a[2]};
    }
    sink.fail(std::move(f));
  }

  bool mark_flat(std::uint32_t f, std::uint32_t node) {
    if (f >= in.flat_nodes.size() || flat_seen[f].exchange(1) != 0) {
      fail("flat node index out of range or reached twice", node, kNone, f, nullptr);
      return false;
    }
    return true;
  }

  void run(std::uint32_t node, std::uint32_t flat, VCell cell, std::vector<Piece> pieces);
  void leaf(std::uint32_t node, std::uint32_t flat, VCell& cell, std::vector<Piece>& pieces);
  bool flat_leaf(std::uint32_t node, std::uint32_t flat);
  bool flat_inner(std::uint32_t node, std::uint32_t flat, VCell& left, VCell& right, bool& swap);
  bool eps_covers(std::uint32_t node, std::uint32_t flat, VCell& left, VCell& right);
  void clip_all(std::uint32_t node, std::vector<Piece>& pieces, std::vector<Piece>& l,
                std::vector<Piece>& r);
};

bool Walk::flat_leaf(std::uint32_t node, std::uint32_t flat) {
  if (!in.has_flat) return true;
  if (!mark_flat(flat, node)) return false;
  const FlatBspNode& f = in.flat_nodes[flat];
  const VerifyNode& n = in.nodes[node];
  if (!f.is_leaf() || f.prim_count() != n.b ||
      std::uint64_t(f.prim_offset()) + f.prim_count() > in.flat_prims.size() ||
      !std::equal(in.refs.begin() + n.a, in.refs.begin() + n.a + n.b,
                  in.flat_prims.begin() + f.prim_offset())) {
    fail("flat leaf differs from its exact leaf (kind or triangle list)", node, kNone, flat, nullptr);
    return false;
  }
  return true;
}

/// The eps check (docs/verify.md §c): with m = 1 + 2^-20 and c = 2^-23·|d|,
/// (F(x) + c)·m ≤ eps on the left child's vertices and (−F(x) + c)·m ≤ eps on
/// the right child's, exactly.
bool Walk::eps_covers(std::uint32_t node, std::uint32_t flat, VCell& left, VCell& right) {
  const FlatBspNode& h = in.flat_nodes[flat];
  const FlatBspNode& t = in.flat_nodes[flat + 1];
  const double d = t.tail_d(), eps = t.tail_eps();
  const std::array<double, 3> n{h.normal(0), h.normal(1), h.normal(2)};
  const IT l1 = CGAL::abs(IT(n[0])) + CGAL::abs(IT(n[1])) + CGAL::abs(IT(n[2]));
  if (!std::isfinite(d) || !std::isfinite(eps) || !(eps >= 0) || !std::isfinite(l1.sup()) ||
      l1.sup() > 1.7321) {
    fail("flat plane node has a non-finite plane, negative eps or |n|_1 > 1.7321", node, kNone, flat,
         nullptr);
    return false;
  }
  const double m = 1.0 + std::ldexp(1.0, -20), c = std::ldexp(std::fabs(d), -23) * m;
  Local& loc = local.local();
  for (int sgn : {1, -1}) {
    VCell& cell = sgn == 1 ? left : right;
    const std::array<double, 3> nn{sgn * n[0] * m, sgn * n[1] * m, sgn * n[2] * m};
    for (Vtx& v : cell.verts) {
      if (affine_sign(pt, nn, {sgn * d * m, c, -eps}, v, loc.c) > 0) {
        fail(std::string("flat plane eps does not cover the float plane at a vertex of the ") +
                 (sgn == 1 ? "left" : "right") + " child cell",
             node, kNone, flat, &v);
        return false;
      }
      if (eps > 0) loc.max_eps_use = std::max(loc.max_eps_use, affine_sup(nn, {sgn * d * m, c, 0.0}, v) / eps);
    }
  }
  ++loc.flat_plane;
  return true;
}

/// Flat inner node `flat` ↔ exact node `node` (builder/bsp_flatten.cpp): an
/// exact Kd plane → the same kd node; a face/edge plane whose exact normal is
/// a multiple of e_k with a float offset → kd node x_k = offset, children
/// swapped iff the multiple is negative; any other → plane node + tail.
bool Walk::flat_inner(std::uint32_t node, std::uint32_t flat, VCell& left, VCell& right, bool& swap) {
  swap = false;
  if (!in.has_flat) return true;
  if (!mark_flat(flat, node)) return false;
  const FlatBspNode& f = in.flat_nodes[flat];
  const PlaneDef def = in.planes[in.nodes[node].plane];
  const VPlane& p = pt[in.nodes[node].plane];
  if (f.is_plane()) {
    if (def.is_kd()) {
      fail("flat plane node for an exact kd plane", node, kNone, flat, nullptr);
      return false;
    }
    return mark_flat(flat + 1, node) && eps_covers(node, flat, left, right);
  }
  if (!f.is_kd()) {
    fail("flat node is a leaf (or unknown kind) where the exact node is inner", node, kNone, flat, nullptr);
    return false;
  }
  const int k = f.axis();
  const double s = f.split();
  bool same = CGAL::sign(p.e[k]) != CGAL::ZERO && std::isfinite(s);
  for (int a = 0; a < 3; ++a)
    if (a != k) same = same && CGAL::sign(p.e[a]) == CGAL::ZERO;
  same = same && CGAL::sign(p.e[k] * ET(s) + p.e[3]) == CGAL::ZERO;
  if (!same) {
    fail("flat kd node's plane differs from the exact plane", node, kNone, flat, nullptr);
    return false;
  }
  swap = CGAL::sign(p.e[k]) == CGAL::NEGATIVE;
  ++local.local().flat_kd;
  return true;
}

void Walk::clip_all(std::uint32_t node, std::vector<Piece>& pieces, std::vector<Piece>& l,
                    std::vector<Piece>& r) {
  const std::uint32_t plane = in.nodes[node].plane;
  Counters& c = local.local().c;
  for (Piece& p : pieces) {
    Piece a, b;
    const ClipResult cr = clip_piece(pt, p, plane, a, b, c);
    if (cr.coplanar && p.required && !in.coplanar_to_both) {
      // One side suffices: the side whose subtree lists it (left if both or none).
      const bool on_left = listed_in_subtree(st, p.tri, in.nodes[node].a) ||
                           !listed_in_subtree(st, p.tri, in.nodes[node].b);
      (on_left ? b : a).required = false;
    }
    if (area_rule) {
      a.required = a.required && cr.left_area;
      b.required = b.required && cr.right_area;
    }
    if (cr.left) l.push_back(std::move(a));
    if (cr.right) r.push_back(std::move(b));
  }
}

void Walk::leaf(std::uint32_t node, std::uint32_t flat, VCell& cell, std::vector<Piece>& pieces) {
  Local& loc = local.local();
  loc.leaf_volume += volume(cell);
  const VerifyNode& n = in.nodes[node];
  std::vector<std::uint32_t> listed(in.refs.begin() + n.a, in.refs.begin() + n.a + n.b);
  std::sort(listed.begin(), listed.end());
  std::vector<std::uint8_t> touched(listed.size(), 0);
  for (Piece& p : pieces) {
    ++loc.pairs;
    const auto it = std::lower_bound(listed.begin(), listed.end(), p.tri);
    const bool is_listed = it != listed.end() && *it == p.tri;
    if (p.required) ++loc.required;
    if (is_listed) {
      touched[std::size_t(it - listed.begin())] |= p.required ? 2 : 1;
    } else if (p.required) {
      fail(std::string("leaf does not list a triangle that ") +
               (area_rule ? "meets its cell with positive area" : "touches its closed cell"),
           node, p.tri, flat, &p.v.front());
      return;
    }
  }
  for (std::size_t i = 0; i < listed.size(); ++i) {
    if (touched[i] == 0) {
      ++loc.extra;
      if (opt.strict_extras) {
        fail("leaf lists a triangle that does not touch its closed cell", node, listed[i], flat, nullptr);
        return;
      }
    } else if (touched[i] == 1) {
      ++loc.boundary;
    }
  }
  if (!flat_leaf(node, flat)) return;
  const std::uint64_t done = leaves_done.fetch_add(1, std::memory_order_relaxed) + 1;
  if (opt.progress && (done % 1024 == 0 || done == st.leaves)) opt.progress(done, st.leaves);
}

void Walk::run(std::uint32_t node, std::uint32_t flat, VCell cell, std::vector<Piece> pieces) {
  if (sink.stopped()) return;
  CGAL::Protect_FPU_rounding<true> guard;
  try {
    const VerifyNode& n = in.nodes[node];
    if (n.plane == VerifyNode::kLeaf) return leaf(node, flat, cell, pieces);
    VCell left, right;
    const CutResult cut = cut_cell(pt, cell, n.plane, left, right, local.local().c);
    if (!cut.ok) {
      fail("split plane does not cut the node's cell (all its vertices lie on one closed side)", node,
           kNone, flat, &cell.verts[cut.witness]);
      return;
    }
    bool swap = false;
    if (!flat_inner(node, flat, left, right, swap)) return;
    std::vector<Piece> lp, rp;
    clip_all(node, pieces, lp, rp);
    pieces.clear();
    pieces.shrink_to_fit();
    const std::uint32_t first = flat + (in.has_flat ? in.flat_nodes[flat].slots() : 0);
    const std::uint32_t second = in.has_flat ? in.flat_nodes[flat].second_child() : 0;
    const std::uint32_t fl = swap ? second : first, fr = swap ? first : second;
    if (lp.size() + rp.size() >= opt.parallel_min_pieces) {
      tbb::task_group g;
      auto job = std::make_shared<std::pair<VCell, std::vector<Piece>>>(std::move(left), std::move(lp));
      g.run([this, job, a = n.a, fl] { run(a, fl, std::move(job->first), std::move(job->second)); });
      run(n.b, fr, std::move(right), std::move(rp));
      g.wait();
    } else {
      run(n.a, fl, std::move(left), std::move(lp));
      run(n.b, fr, std::move(right), std::move(rp));
    }
  } catch (const std::logic_error& e) {
    fail(std::string("internal inconsistency: ") + e.what(), node, kNone, flat, nullptr);
  }
}

}  // namespace
}  // namespace vfy

namespace {
VerifyReport verify_bsp_ieee(const TriangleSoup& soup, const VerifyInput& in, const VerifyConfig& opt) {
  using namespace vfy;
  const auto start = std::chrono::steady_clock::now();
  VerifyReport rep;
  rep.membership = in.membership == 1 ? "area" : "closed";
  rep.coplanar_to_both = in.coplanar_to_both;
  FailureSink sink;
  Structure st;
  if (check_structure(soup, in, st, sink)) {
    const PlaneTable pt(soup, in.planes, in.root_box);
    Walk w{soup, in, opt, st, pt, sink, in.membership == 1, nullptr, {}, {}};
    w.flat_seen = std::make_unique<std::atomic<std::uint8_t>[]>(in.flat_nodes.size());
    std::vector<Piece> pieces;
    for (std::uint32_t t = 0; t < soup.size(); ++t)
      if (!st.degenerate[t]) pieces.push_back(root_piece(soup, t));
    rep.triangles = pieces.size();
    VCell root;
    IT root_volume;
    {
      CGAL::Protect_FPU_rounding<true> guard;
      root = root_cell(pt);
      root_volume = volume(root);
    }
    w.run(0, 0, std::move(root), std::move(pieces));
    Local sum;
    bool volumes_differ = false;
    {
      CGAL::Protect_FPU_rounding<true> guard;
      for (const Local& l : w.local) {
        sum.c.add(l.c);
        sum.pairs += l.pairs, sum.required += l.required, sum.extra += l.extra;
        sum.boundary += l.boundary, sum.flat_plane += l.flat_plane, sum.flat_kd += l.flat_kd;
        sum.max_eps_use = std::max(sum.max_eps_use, l.max_eps_use);
        sum.leaf_volume += l.leaf_volume;
      }
      const IT diff = sum.leaf_volume - root_volume;
      volumes_differ = diff.inf() > 0 || diff.sup() < 0;  // proven different
      rep.volume_rel_error = CGAL::abs(diff).sup() / root_volume.inf();
    }
    if (!sink.stopped() && in.has_flat)
      for (std::size_t f = 0; f < in.flat_nodes.size(); ++f)
        if (!w.flat_seen[f]) {
          VerifyFailure fl;
          fl.what = "flat node not reached from the root";
          fl.flat_node = std::uint32_t(f);
          sink.fail(fl);
          break;
        }
    if (sink.stopped()) rep.volume_rel_error = std::nan("");  // walk cut short
    if (!sink.stopped() && volumes_differ)
    {
      VerifyFailure vf;
      vf.what = "leaf volumes do not add up to the root volume";
      sink.fail(vf);
    }
    rep.pairs = sum.pairs, rep.required_pairs = sum.required, rep.extra_listings = sum.extra;
    rep.boundary_listings = sum.boundary, rep.flat_plane_nodes = sum.flat_plane, rep.flat_kd_nodes = sum.flat_kd;
    rep.max_eps_use = sum.max_eps_use;
    rep.filter_tests = sum.c.filter, rep.exact_fallbacks = sum.c.exact, rep.exact_points = sum.c.points;
  }
  rep.nodes = in.nodes.size();
  rep.leaves = st.leaves;
  rep.degenerate_triangles = std::size_t(std::count(st.degenerate.begin(), st.degenerate.end(), 1));
  if (!in.has_flat) rep.notes.push_back("no flat sections in the file: (c) not applicable");
  rep.failure = sink.best();
  rep.certified = !rep.failure.has_value();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return rep;
}
}  // namespace

VerifyReport verify_bsp(const TriangleSoup& soup, const VerifyInput& in, const VerifyConfig& opt) {
  std::unique_ptr<tbb::global_control> cap;
  if (opt.threads > 0)
    cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                std::size_t(opt.threads));
  // The interval filters and the exact fallbacks assume IEEE arithmetic in every task, whatever
  // the caller's thread or arena holds: a plane table made with DAZ refused valid subnormal trees
  // (fp_env.h).
  return run_ieee(0, [&] { return verify_bsp_ieee(soup, in, opt); });
}

}  // namespace bsprt
