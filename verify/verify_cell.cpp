/// \file verify_cell.cpp
/// Cells and triangle pieces of the verifier (verify_cell.h).
#include "verify/verify_cell.h"

#include <stdexcept>

namespace bsprt::vfy {
namespace {

/// A cell edge crossed by the cut: endpoints, the planes of its two facets,
/// and the index of the new vertex.
struct Crossing {
  std::uint32_t u, w;
  std::uint32_t pa = 0, pb = 0;
  int seen = 0;
  std::uint32_t index = 0;
};

Crossing* find_crossing(std::vector<Crossing>& cs, std::uint32_t u, std::uint32_t w) {
  for (Crossing& c : cs)
    if ((c.u == u && c.w == w) || (c.u == w && c.w == u)) return &c;
  return nullptr;
}

/// Collects crossed edges with both facet planes, then builds the new vertices.
std::vector<Crossing> crossings(const PlaneTable& pt, const VCell& cell, const std::vector<int>& s,
                                std::uint32_t plane) {
  std::vector<Crossing> cs;
  for (const Facet& f : cell.facets) {
    const std::size_t n = f.loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t u = f.loop[i], w = f.loop[(i + 1) % n];
      if (s[u] * s[w] != -1) continue;
      Crossing* c = find_crossing(cs, u, w);
      if (!c) {
        cs.push_back(Crossing{u, w});
        c = &cs.back();
      }
      (c->seen == 0 ? c->pa : c->pb) = f.plane;
      ++c->seen;
    }
  }
  for (Crossing& c : cs)
    if (c.seen != 2) throw std::logic_error("verify: cell edge not shared by two facets");
  (void)pt;
  (void)plane;
  return cs;
}

/// One child: vertices with sign·s ≤ 0, clipped facets, and the cap on the cut.
void build_child(const PlaneTable& pt, const VCell& cell, const std::vector<int>& s, int sign,
                 std::uint32_t plane, std::vector<Crossing>& cs, const std::vector<Vtx>& fresh,
                 VCell& out) {
  out.verts.clear();
  out.facets.clear();
  std::vector<std::uint32_t> remap(cell.verts.size(), 0xFFFFFFFFu);
  std::vector<std::uint8_t> on_cut;
  for (std::uint32_t i = 0; i < cell.verts.size(); ++i) {
    if (sign * s[i] > 0) continue;
    remap[i] = std::uint32_t(out.verts.size());
    out.verts.push_back(cell.verts[i]);
    on_cut.push_back(s[i] == 0);
  }
  for (std::size_t k = 0; k < cs.size(); ++k) {
    cs[k].index = std::uint32_t(out.verts.size());
    out.verts.push_back(fresh[k]);
    on_cut.push_back(1);
  }
  std::vector<std::uint32_t> next(out.verts.size(), 0xFFFFFFFFu);
  std::size_t cap_edges = 0;
  for (const Facet& f : cell.facets) {
    Facet g{f.plane, {}};
    const std::size_t n = f.loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t u = f.loop[i], w = f.loop[(i + 1) % n];
      if (sign * s[u] <= 0) g.loop.push_back(remap[u]);
      if (s[u] * s[w] == -1) g.loop.push_back(find_crossing(cs, u, w)->index);
    }
    if (g.loop.size() < 3) continue;
    const std::size_t m = g.loop.size();
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint32_t a = g.loop[i], b = g.loop[(i + 1) % m];
      if (!on_cut[a] || !on_cut[b]) continue;
      if (next[b] != 0xFFFFFFFFu) throw std::logic_error("verify: cap vertex with two successors");
      next[b] = a;  // the cap runs against the facet's edge
      ++cap_edges;
    }
    out.facets.push_back(std::move(g));
  }
  Facet cap{plane, {}};
  std::uint32_t start = 0;
  while (start < next.size() && next[start] == 0xFFFFFFFFu) ++start;
  if (start == next.size()) throw std::logic_error("verify: empty cap");
  std::uint32_t v = start;
  do {
    cap.loop.push_back(v);
    v = next[v];
    if (v == 0xFFFFFFFFu || cap.loop.size() > cap_edges) throw std::logic_error("verify: open cap loop");
  } while (v != start);
  if (cap.loop.size() != cap_edges || cap.loop.size() < 3) throw std::logic_error("verify: broken cap");
  out.facets.push_back(std::move(cap));
  (void)pt;
}

}  // namespace

VCell root_cell(const PlaneTable& pt) {
  VCell c;
  for (std::uint32_t i = 0; i < 8; ++i)
    c.verts.push_back(make_three(pt, pt.box_plane(0, int(i & 1)), pt.box_plane(1, int((i >> 1) & 1)),
                                 pt.box_plane(2, int((i >> 2) & 1))));
  // Corner i = x + 2y + 4z; loops outward counter-clockwise.
  c.facets = {{pt.box_plane(0, 0), {0, 4, 6, 2}}, {pt.box_plane(0, 1), {1, 3, 7, 5}},
              {pt.box_plane(1, 0), {0, 1, 5, 4}}, {pt.box_plane(1, 1), {2, 6, 7, 3}},
              {pt.box_plane(2, 0), {0, 2, 3, 1}}, {pt.box_plane(2, 1), {4, 5, 7, 6}}};
  return c;
}

CutResult cut_cell(const PlaneTable& pt, VCell& cell, std::uint32_t plane, VCell& left, VCell& right,
                   Counters& c) {
  std::vector<int> s(cell.verts.size());
  bool neg = false, pos = false;
  CutResult r;
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i] = side(pt, plane, cell.verts[i], c);
    neg = neg || s[i] < 0;
    pos = pos || s[i] > 0;
  }
  if (!neg || !pos) {
    r.witness = 0;
    return r;
  }
  std::vector<Crossing> cs = crossings(pt, cell, s, plane);
  std::vector<Vtx> fresh;
  fresh.reserve(cs.size());
  for (const Crossing& x : cs) fresh.push_back(make_three(pt, x.pa, x.pb, plane));
  build_child(pt, cell, s, 1, plane, cs, fresh, left);
  build_child(pt, cell, s, -1, plane, cs, fresh, right);
  r.ok = true;
  return r;
}

IT volume(const VCell& cell) {
  const Vtx& o = cell.verts.front();
  if (!o.box_ok) return IT::largest();
  IT sum(0.0);
  for (const Facet& f : cell.facets) {
    const Vtx& a = cell.verts[f.loop[0]];
    for (std::size_t i = 1; i + 1 < f.loop.size(); ++i) {
      const Vtx& b = cell.verts[f.loop[i]];
      const Vtx& d = cell.verts[f.loop[i + 1]];
      if (!a.box_ok || !b.box_ok || !d.box_ok) return IT::largest();
      std::array<IT, 3> x, y, z;
      for (int k = 0; k < 3; ++k) {
        x[k] = a.box[k] - o.box[k];
        y[k] = b.box[k] - o.box[k];
        z[k] = d.box[k] - o.box[k];
      }
      sum += x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) +
             x[2] * (y[0] * z[1] - y[1] * z[0]);
    }
  }
  return sum / IT(6.0);
}

Piece root_piece(const TriangleSoup& soup, std::uint32_t tri) {
  Piece p;
  p.tri = tri;
  for (int k = 0; k < 3; ++k) {
    p.v.push_back(make_corner(soup, tri, k));
    p.label.push_back(kTriEdge | std::uint32_t(k));
  }
  return p;
}

ClipResult clip_piece(const PlaneTable& pt, Piece& p, std::uint32_t plane, Piece& left, Piece& right,
                      Counters& c) {
  const std::size_t n = p.v.size();
  std::vector<int> s(n);
  bool neg = false, pos = false, zero = false;
  for (std::size_t i = 0; i < n; ++i) {
    s[i] = side(pt, plane, p.v[i], c);
    neg = neg || s[i] < 0;
    pos = pos || s[i] > 0;
    zero = zero || s[i] == 0;
  }
  ClipResult r;
  r.coplanar = !neg && !pos;
  r.left = neg || zero;
  r.right = pos || zero;
  r.left_area = p.area && (neg || r.coplanar);
  r.right_area = p.area && (pos || r.coplanar);
  left = Piece{p.tri, p.required, r.left_area, {}, {}};
  right = Piece{p.tri, p.required, r.right_area, {}, {}};
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const std::uint32_t lab = p.label[i];
    const bool cross = s[i] * s[j] == -1;
    Vtx x;
    if (cross) {
      x = (lab & kTriEdge) ? make_seg(pt, p.tri, int(lab & 3u), plane)
                           : make_three(pt, pt.face(p.tri), lab, plane);
    }
    for (int side_sign : {1, -1}) {
      Piece& out = side_sign == 1 ? left : right;
      const int si = side_sign * s[i], sj = side_sign * s[j];
      if (si <= 0) {
        out.v.push_back(p.v[i]);
        out.label.push_back(sj <= 0 ? lab : (si < 0 ? lab : plane));
        if (si < 0 && sj > 0) {
          out.v.push_back(x);
          out.label.push_back(plane);
        }
      } else if (sj < 0) {
        out.v.push_back(x);
        out.label.push_back(lab);
      }
    }
  }
  return r;
}

}  // namespace bsprt::vfy
