#pragma once
/// \file verify_geometry.h
/// The verifier's own exact geometry (verify.h): planes a·x + b·y + c·z + d
/// with exact coefficients re-derived from the input floats, points as
/// homogeneous exact coordinates (X, Y, Z, W) built directly from stored data
/// (a triangle corner, a triangle edge ∩ a plane, three planes: never from an
/// earlier construction), and filtered side tests: an interval evaluation
/// (CGAL::Interval_nt<false>, the caller holds a Protect_FPU_rounding guard)
/// and, only when it cannot decide, exact CGAL::Mpzf ring arithmetic
/// (sign(a·X + b·Y + c·Z + d·W)·sign(W): no division). Internal to robust/.

#include <CGAL/Interval_nt.h>
#include <CGAL/Mpzf.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry/core/triangle_soup.h"
#include "robust/plane.h"

namespace bsprt::vfy {

using IT = CGAL::Interval_nt<false>;  ///< filter (needs upward rounding)
using ET = CGAL::Mpzf;                ///< exact dyadic ring arithmetic
using EPoint = std::array<ET, 4>;     ///< homogeneous exact point, W = [3] != 0

/// Work counters of one thread (merged into VerifyReport).
struct Counters {
  std::uint64_t filter = 0;  ///< interval side tests
  std::uint64_t exact = 0;   ///< side tests decided exactly
  std::uint64_t points = 0;  ///< points constructed exactly
  void add(const Counters& o) { filter += o.filter; exact += o.exact; points += o.points; }
};

/// A plane with exact and interval coefficients (a, b, c, d).
struct VPlane {
  std::array<ET, 4> e;
  std::array<IT, 4> i;
  bool valid = false;  ///< false: a degenerate triangle's plane (zero normal)
};

/// Every plane the verifier uses: the file's plane table, then each
/// triangle's face plane, then the six planes of the root box.
class PlaneTable {
 public:
  /// Derives all coefficients (parallel). `planes` must be in range for `soup`.
  PlaneTable(const TriangleSoup& soup, const std::vector<PlaneDef>& planes, const Box3f& box);
  const VPlane& operator[](std::uint32_t id) const { return planes_[id]; }
  /// Face plane of triangle t (normal (p1−p0)×(p2−p0)).
  std::uint32_t face(std::uint32_t t) const { return faces_ + t; }
  /// Root box plane: axis a, side 0 = x_a = lo (value x − lo), 1 = x_a = hi.
  std::uint32_t box_plane(int axis, int side) const { return boxes_ + std::uint32_t(2 * axis + side); }
  const TriangleSoup& soup() const { return *soup_; }

 private:
  const TriangleSoup* soup_;
  std::uint32_t faces_ = 0, boxes_ = 0;
  std::vector<VPlane> planes_;
};

/// Exact plane from its defining data (plane.h orientation), computed here
/// from the corners: Kd n = e_a, d = −c; Face n = (p1−p0)×(p2−p0), d = −n·p0;
/// Edge k n = n_face × (p_{k+1} − p_k), d = −n·p_k.
VPlane make_plane(const TriangleSoup& soup, PlaneDef def);

/// True when triangle t is degenerate: a non-finite corner, or exactly zero
/// normal (collinear or repeated corners), decided with Mpzf.
bool degenerate_exact(const TriangleSoup& soup, std::uint32_t t);

/// How a point is defined.
enum class VKind : std::uint8_t {
  Corner,  ///< corner id[1] of triangle id[0]
  Seg,     ///< edge id[1] (corner k → k+1) of triangle id[0] ∩ plane id[2]
  Three,   ///< planes id[0] ∩ id[1] ∩ id[2]
};

/// A point with an interval enclosure and a lazily computed exact value.
struct Vtx {
  VKind kind = VKind::Three;
  std::array<std::uint32_t, 3> id{};
  std::array<IT, 3> box;
  bool box_ok = false;  ///< false: the filter could not enclose it (use exact)
  std::shared_ptr<const EPoint> exact;  ///< set once computed (shared by copies)
  /// Double approximation (witnesses only).
  std::array<double, 3> approx() const;
};

/// Builds a point and its interval enclosure (no exact work).
Vtx make_corner(const TriangleSoup& soup, std::uint32_t tri, int k);
Vtx make_seg(const PlaneTable& pt, std::uint32_t tri, int k, std::uint32_t plane);
Vtx make_three(const PlaneTable& pt, std::uint32_t a, std::uint32_t b, std::uint32_t c);

/// The exact homogeneous coordinates of `v` (computed and cached on first use).
/// Throws std::logic_error if the definition is degenerate (W = 0).
const EPoint& exact_of(const PlaneTable& pt, Vtx& v, Counters& c);

/// Side of `v` against plane `plane`: −1, 0, +1, filtered, exact when needed.
int side(const PlaneTable& pt, std::uint32_t plane, Vtx& v, Counters& c);

/// Sign of n·v + k0 + k1 + k2 for double n and k (the eps check, whose
/// constants are exact doubles but whose sum is not): filtered, exact when needed.
int affine_sign(const PlaneTable& pt, const std::array<double, 3>& n, const std::array<double, 3>& k,
                Vtx& v, Counters& c);

/// Upper bound of n·v + k0 + k1 + k2 (interval; +inf when the box is unknown).
double affine_sup(const std::array<double, 3>& n, const std::array<double, 3>& k, const Vtx& v);

}  // namespace bsprt::vfy
