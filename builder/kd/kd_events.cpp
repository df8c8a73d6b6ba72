#include "builder/kd/kd_events.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "builder/kd/kd_clip.h"

namespace bsprt::kd_detail {
namespace {

enum Side : std::uint8_t { kBoth = 0, kLower = 1, kUpper = 2 };

/// Surface area of `cell` with its extent on axis k replaced by `extent_k`.
double area_with(const Box3f& cell, int k, double extent_k) {
  double d[3] = {double(cell.hi.x) - cell.lo.x, double(cell.hi.y) - cell.lo.y,
                 double(cell.hi.z) - cell.lo.z};
  d[k] = extent_k;
  return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

/// SAH cost of a split (W&H Sec. 3, with the empty-space bonus lambda).
double sah(const KdConfig& c, double pl, double pr, std::size_t nl, std::size_t nr) {
  const double lambda = (nl == 0 || nr == 0) ? c.empty_bonus : 1.0;
  return lambda * (c.traversal_cost + c.intersection_cost * (pl * double(nl) + pr * double(nr)));
}

/// Evaluates the plane x_k = p with N_L, N_R triangles on the sides and
/// n_planar lying in it (tried on either side), updating `best`.
void evaluate(const Box3f& cell, int k, float p, std::size_t left, std::size_t right,
              std::size_t n_planar, const KdConfig& config, double inv_area, SplitChoice& best) {
  const double lo = cell.lo[k], hi = cell.hi[k];
  if (!(p > lo && p < hi)) return;  // only planes that shrink the cell
  const double pl = area_with(cell, k, double(p) - lo) * inv_area;
  const double pr = area_with(cell, k, hi - double(p)) * inv_area;
  const double c_lo = sah(config, pl, pr, left + n_planar, right);
  const double c_hi = n_planar ? sah(config, pl, pr, left, right + n_planar) : c_lo;
  const double c = std::min(c_lo, c_hi);
  if (best.axis < 0 || c < best.cost) best = {k, p, c_lo <= c_hi, c};
}

/// Sweeps the sorted events of axis k (W&H Sec. 4.3), updating `best`.
/// Closed cells: a triangle touching the plane goes to both sides, except those
/// lying in it, which go to the cheaper side (Sec. 4.2). Because touching
/// counts on both sides, the planes one float below and above each event
/// position are tried too: they separate the triangles ending at p from those
/// starting at p, which W&H get by sending touching triangles to one side.
void sweep_axis(const NodeEvents& node, const Box3f& cell, int k, const KdConfig& config,
                double inv_area, SplitChoice& best) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const std::vector<Event>& e = node.ev[k];
  std::size_t nl = 0, nr = node.size();
  float prev = -kInf;
  for (std::size_t i = 0; i < e.size();) {
    const float p = e[i].pos;
    std::size_t n_start = 0, n_end = 0, n_planar = 0;
    for (; i < e.size() && e[i].pos == p; ++i) {
      switch (e[i].type()) {
        case EventType::End: ++n_end; break;
        case EventType::Planar: ++n_planar; break;
        case EventType::Start: ++n_start; break;
      }
    }
    const float next = i < e.size() ? e[i].pos : kInf;
    // nl = #(lo < p), nr = #(hi >= p), planar ones included.
    // Not near 0: planes at denormal positions make the watertight test's
    // products underflow, so it could report hits exact geometry does not have.
    const bool offsets = !(std::abs(p) < 0x1p-60f);
    const float below = std::nextafter(p, -kInf), above = std::nextafter(p, kInf);
    if (offsets && below > prev) evaluate(cell, k, below, nl, nr, 0, config, inv_area, best);
    evaluate(cell, k, p, nl + n_start, nr - n_planar, n_planar, config, inv_area, best);
    if (offsets && above < next)
      evaluate(cell, k, above, nl + n_start + n_planar, nr - n_end - n_planar, 0, config, inv_area, best);
    nl += n_start + n_planar;
    nr -= n_end + n_planar;
    prev = p;
  }
}

/// Sets scratch.side for every triangle of the node (W&H "ClassifyLeftRightBoth").
void classify(const NodeEvents& node, const SplitChoice& s, SplitScratch& scratch) {
  for (std::uint32_t t : node.tris) scratch.side[t] = kBoth;
  for (const Event& e : node.ev[s.axis]) {
    const std::uint32_t t = e.tri();
    switch (e.type()) {
      case EventType::End:
        if (e.pos < s.pos) scratch.side[t] = kLower;
        break;
      case EventType::Start:
        if (e.pos > s.pos) scratch.side[t] = kUpper;
        break;
      case EventType::Planar:
        if (e.pos < s.pos || (e.pos == s.pos && s.planar_left)) scratch.side[t] = kLower;
        else scratch.side[t] = kUpper;
        break;
    }
  }
}

/// Collects the current (clipped) bounds of the straddling triangles from their events.
void gather_bounds(const NodeEvents& node, SplitScratch& scratch) {
  for (int k = 0; k < 3; ++k) {
    for (const Event& e : node.ev[k]) {
      const std::uint32_t t = e.tri();
      if (scratch.side[t] != kBoth) continue;
      Box3f& b = scratch.bounds[t];
      if (e.type() != EventType::End) b.lo[k] = e.pos;
      if (e.type() != EventType::Start) b.hi[k] = e.pos;
    }
  }
}

/// Bounds of triangle t within `child` (conservative), or false if it misses it.
bool child_bounds(std::uint32_t t, const Box3f& child, const Box3f& current,
                  const std::vector<std::array<Vec3f, 3>>& triangles, bool perfect, Box3f& out) {
  Box3f limit;
  limit.lo = max(child.lo, current.lo);
  limit.hi = min(child.hi, current.hi);
  if (limit.empty()) return false;
  if (!perfect) {
    out = limit;
    return true;
  }
  return clip_triangle_bounds(triangles[t], limit, out);
}

/// Sorts the events of the clipped straddlers and merges them into `dst`.
void merge_new(std::vector<Event>& dst, std::vector<Event>& fresh) {
  std::sort(fresh.begin(), fresh.end());
  const std::size_t mid = dst.size();
  dst.insert(dst.end(), fresh.begin(), fresh.end());
  std::inplace_merge(dst.begin(), dst.begin() + std::ptrdiff_t(mid), dst.end());
}

}  // namespace

void NodeEvents::add(std::uint32_t tri, const Box3f& b) {
  for (int k = 0; k < 3; ++k) {
    if (b.lo[k] == b.hi[k]) {
      ev[k].push_back(Event::make(b.lo[k], tri, EventType::Planar));
    } else {
      ev[k].push_back(Event::make(b.lo[k], tri, EventType::Start));
      ev[k].push_back(Event::make(b.hi[k], tri, EventType::End));
    }
  }
  tris.push_back(tri);
}

SplitChoice find_best_split(const NodeEvents& node, const Box3f& cell, const KdConfig& config) {
  SplitChoice best;
  const double area = cell.area();
  if (!(area > 0)) return best;
  for (int k = 0; k < 3; ++k) sweep_axis(node, cell, k, config, 1.0 / area, best);
  if (best.axis >= 0 && !(best.cost < config.intersection_cost * double(node.size()))) best.axis = -1;
  return best;
}

SplitCounts split_events(NodeEvents& node, const Box3f& cell, const SplitChoice& split,
                         const std::vector<std::array<Vec3f, 3>>& triangles, bool perfect_splits,
                         SplitScratch& scratch, NodeEvents& lower, NodeEvents& upper) {
  classify(node, split, scratch);
  gather_bounds(node, scratch);
  // One-sided triangles keep their events, in order (no re-sorting).
  for (int k = 0; k < 3; ++k) {
    for (const Event& e : node.ev[k]) {
      const std::uint8_t s = scratch.side[e.tri()];
      if (s == kLower) lower.ev[k].push_back(e);
      else if (s == kUpper) upper.ev[k].push_back(e);
    }
    std::vector<Event>().swap(node.ev[k]);
  }
  Box3f lo_cell = cell, hi_cell = cell;
  lo_cell.hi[split.axis] = split.pos;
  hi_cell.lo[split.axis] = split.pos;
  SplitCounts counts;
  NodeEvents fresh_lo, fresh_hi;
  for (std::uint32_t t : node.tris) {
    const std::uint8_t s = scratch.side[t];
    if (s == kLower) { lower.tris.push_back(t); continue; }
    if (s == kUpper) { upper.tris.push_back(t); continue; }
    Box3f b;
    counts.clipped += 2;
    if (child_bounds(t, lo_cell, scratch.bounds[t], triangles, perfect_splits, b)) fresh_lo.add(t, b);
    else ++counts.dropped;
    if (child_bounds(t, hi_cell, scratch.bounds[t], triangles, perfect_splits, b)) fresh_hi.add(t, b);
    else ++counts.dropped;
  }
  std::vector<std::uint32_t>().swap(node.tris);
  for (int k = 0; k < 3; ++k) {
    merge_new(lower.ev[k], fresh_lo.ev[k]);
    merge_new(upper.ev[k], fresh_hi.ev[k]);
  }
  lower.tris.insert(lower.tris.end(), fresh_lo.tris.begin(), fresh_lo.tris.end());
  upper.tris.insert(upper.tris.end(), fresh_hi.tris.begin(), fresh_hi.tris.end());
  return counts;
}

}  // namespace bsprt::kd_detail
