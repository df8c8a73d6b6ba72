/// \file verify_geometry.cpp
/// The verifier's planes, points and filtered side tests (verify_geometry.h).
#include "verify/verify_geometry.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace bsprt::vfy {
namespace {

using E3 = std::array<ET, 3>;

E3 exact_of(const Vec3f& p) { return {ET(double(p.x)), ET(double(p.y)), ET(double(p.z))}; }
E3 sub(const E3& a, const E3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
E3 cross(const E3& a, const E3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
ET dot(const E3& a, const E3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Tight intervals of the exact coefficients (conversion is exact-rounded outward).
void fill_intervals(VPlane& p) {
  for (int k = 0; k < 4; ++k) p.i[k] = IT(CGAL::to_interval(p.e[k]));
  p.valid = !(CGAL::sign(p.e[0]) == CGAL::ZERO && CGAL::sign(p.e[1]) == CGAL::ZERO &&
              CGAL::sign(p.e[2]) == CGAL::ZERO);
}

VPlane plane_through(const E3& n, const E3& r) {
  VPlane p;
  p.e = {n[0], n[1], n[2], -dot(n, r)};
  fill_intervals(p);
  return p;
}

int sign_of(const IT& v) {
  if (v.inf() > 0) return 1;
  if (v.sup() < 0) return -1;
  if (v.inf() == 0 && v.sup() == 0) return 0;
  return 2;  // undecided
}

template <typename T>
T det3(const T& a, const T& b, const T& c, const T& d, const T& e, const T& f, const T& g, const T& h,
       const T& i) {
  return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

/// Cramer's rule, homogeneous: rows a·x = −d of three planes.
template <typename T>
std::array<T, 4> cramer(const std::array<T, 4>& p, const std::array<T, 4>& q, const std::array<T, 4>& r) {
  const T D = det3(p[0], p[1], p[2], q[0], q[1], q[2], r[0], r[1], r[2]);
  const T mp = -p[3], mq = -q[3], mr = -r[3];
  const T X = det3(mp, p[1], p[2], mq, q[1], q[2], mr, r[1], r[2]);
  const T Y = det3(p[0], mp, p[2], q[0], mq, q[2], r[0], mr, r[2]);
  const T Z = det3(p[0], p[1], mp, q[0], q[1], mq, r[0], r[1], mr);
  return {X, Y, Z, D};
}

/// Edge k of triangle t ∩ plane: X = P(p)·q − P(q)·p, W = P(p) − P(q).
template <typename T, typename P3>
std::array<T, 4> seg_point(const P3& p, const P3& q, const std::array<T, 4>& pl) {
  const T fp = pl[0] * p[0] + pl[1] * p[1] + pl[2] * p[2] + pl[3];
  const T fq = pl[0] * q[0] + pl[1] * q[1] + pl[2] * q[2] + pl[3];
  return {fp * q[0] - fq * p[0], fp * q[1] - fq * p[1], fp * q[2] - fq * p[2], fp - fq};
}

void set_box(Vtx& v, const std::array<IT, 4>& h) {
  v.box_ok = h[3].inf() > 0 || h[3].sup() < 0;
  if (!v.box_ok) return;
  for (int k = 0; k < 3; ++k) {
    v.box[k] = h[k] / h[3];
    if (!std::isfinite(v.box[k].inf()) || !std::isfinite(v.box[k].sup())) v.box_ok = false;
  }
}

std::array<IT, 3> ipoint(const Vec3f& p) { return {IT(double(p.x)), IT(double(p.y)), IT(double(p.z))}; }

}  // namespace

VPlane make_plane(const TriangleSoup& soup, PlaneDef def) {
  if (def.is_kd()) {
    E3 n{ET(0.0), ET(0.0), ET(0.0)};
    n[def.axis()] = ET(1.0);
    E3 r{ET(0.0), ET(0.0), ET(0.0)};
    r[def.axis()] = ET(double(def.coord()));
    return plane_through(n, r);
  }
  const std::uint32_t t = def.tri();
  const E3 p0 = exact_of(soup.corner(t, 0)), p1 = exact_of(soup.corner(t, 1)),
           p2 = exact_of(soup.corner(t, 2));
  const E3 nf = cross(sub(p1, p0), sub(p2, p0));
  if (def.kind == PlaneKind::Face) return plane_through(nf, p0);
  const int k = def.edge_index();
  const E3 pk = exact_of(soup.corner(t, k)), pk1 = exact_of(soup.corner(t, (k + 1) % 3));
  return plane_through(cross(nf, sub(pk1, pk)), pk);
}

bool degenerate_exact(const TriangleSoup& soup, std::uint32_t t) {
  for (int k = 0; k < 3; ++k) {
    const Vec3f& c = soup.corner(t, k);
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) return true;
  }
  const VPlane f = make_plane(soup, PlaneDef::face(t));
  return !f.valid;
}

PlaneTable::PlaneTable(const TriangleSoup& soup, const std::vector<PlaneDef>& planes, const Box3f& box)
    : soup_(&soup) {
  faces_ = std::uint32_t(planes.size());
  boxes_ = faces_ + std::uint32_t(soup.size());
  planes_.resize(std::size_t(boxes_) + 6);
  tbb::parallel_for(std::size_t(0), std::size_t(boxes_), [&](std::size_t i) {
    if (i < faces_) {
      planes_[i] = make_plane(soup, planes[i]);
    } else {
      const std::uint32_t t = std::uint32_t(i - faces_);
      bool finite = true;
      for (int k = 0; k < 3; ++k) {
        const Vec3f& c = soup.corner(t, k);
        finite = finite && std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
      }
      if (finite) planes_[i] = make_plane(soup, PlaneDef::face(t));
    }
  });
  for (int a = 0; a < 3; ++a) {
    planes_[box_plane(a, 0)] = make_plane(soup, PlaneDef::kd(a, box.lo[a]));
    planes_[box_plane(a, 1)] = make_plane(soup, PlaneDef::kd(a, box.hi[a]));
  }
}

std::array<double, 3> Vtx::approx() const {
  std::array<double, 3> r{};
  if (exact) {
    for (int k = 0; k < 3; ++k)
      r[k] = CGAL::to_double((*exact)[k]) / CGAL::to_double((*exact)[3]);
  } else {
    for (int k = 0; k < 3; ++k) r[k] = box_ok ? 0.5 * (box[k].inf() + box[k].sup()) : std::nan("");
  }
  return r;
}

Vtx make_corner(const TriangleSoup& soup, std::uint32_t tri, int k) {
  Vtx v;
  v.kind = VKind::Corner;
  v.id = {tri, std::uint32_t(k), 0};
  v.box = ipoint(soup.corner(tri, k));
  v.box_ok = true;
  return v;
}

Vtx make_seg(const PlaneTable& pt, std::uint32_t tri, int k, std::uint32_t plane) {
  Vtx v;
  v.kind = VKind::Seg;
  v.id = {tri, std::uint32_t(k), plane};
  const TriangleSoup& s = pt.soup();
  set_box(v, seg_point(ipoint(s.corner(tri, k)), ipoint(s.corner(tri, (k + 1) % 3)), pt[plane].i));
  return v;
}

Vtx make_three(const PlaneTable& pt, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  Vtx v;
  v.kind = VKind::Three;
  v.id = {a, b, c};
  set_box(v, cramer(pt[a].i, pt[b].i, pt[c].i));
  return v;
}

const EPoint& exact_of(const PlaneTable& pt, Vtx& v, Counters& c) {
  if (v.exact) return *v.exact;
  ++c.points;
  EPoint h;
  const TriangleSoup& s = pt.soup();
  if (v.kind == VKind::Corner) {
    const E3 p = exact_of(s.corner(v.id[0], int(v.id[1])));
    h = {p[0], p[1], p[2], ET(1.0)};
  } else if (v.kind == VKind::Seg) {
    h = seg_point(exact_of(s.corner(v.id[0], int(v.id[1]))),
                  exact_of(s.corner(v.id[0], int(v.id[1] + 1) % 3)), pt[v.id[2]].e);
  } else {
    h = cramer(pt[v.id[0]].e, pt[v.id[1]].e, pt[v.id[2]].e);
  }
  if (CGAL::sign(h[3]) == CGAL::ZERO) throw std::logic_error("verify: degenerate point construction");
  v.exact = std::make_shared<const EPoint>(std::move(h));
  return *v.exact;
}

int side(const PlaneTable& pt, std::uint32_t plane, Vtx& v, Counters& c) {
  const VPlane& p = pt[plane];
  if (v.box_ok) {
    ++c.filter;
    const int s = sign_of(p.i[0] * v.box[0] + p.i[1] * v.box[1] + p.i[2] * v.box[2] + p.i[3]);
    if (s != 2) return s;
  }
  ++c.exact;
  const EPoint& h = exact_of(pt, v, c);
  const ET val = p.e[0] * h[0] + p.e[1] * h[1] + p.e[2] * h[2] + p.e[3] * h[3];
  return int(CGAL::sign(val)) * int(CGAL::sign(h[3]));
}

int affine_sign(const PlaneTable& pt, const std::array<double, 3>& n, const std::array<double, 3>& k,
                Vtx& v, Counters& c) {
  if (v.box_ok) {
    ++c.filter;
    const IT val = IT(n[0]) * v.box[0] + IT(n[1]) * v.box[1] + IT(n[2]) * v.box[2] + IT(k[0]) +
                   IT(k[1]) + IT(k[2]);
    const int s = sign_of(val);
    if (s != 2) return s;
  }
  ++c.exact;
  const EPoint& h = exact_of(pt, v, c);
  const ET val = ET(n[0]) * h[0] + ET(n[1]) * h[1] + ET(n[2]) * h[2] +
                 (ET(k[0]) + ET(k[1]) + ET(k[2])) * h[3];
  return int(CGAL::sign(val)) * int(CGAL::sign(h[3]));
}

double affine_sup(const std::array<double, 3>& n, const std::array<double, 3>& k, const Vtx& v) {
  if (!v.box_ok) return std::numeric_limits<double>::infinity();
  const IT val = IT(n[0]) * v.box[0] + IT(n[1]) * v.box[1] + IT(n[2]) * v.box[2] + IT(k[0]) + IT(k[1]) +
                 IT(k[2]);
  return val.sup();
}

}  // namespace bsprt::vfy
