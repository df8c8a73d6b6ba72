#pragma once
/// \file kd_events.h
/// Split events of the O(N log N) kd build (Wald and Havran 2006, Sec. 4.3-4.4):
/// per axis, one sorted list of start / end / planar events of the (clipped)
/// triangle bounds; the SAH sweep that finds the best plane; and the split of a
/// node's event lists into its children's lists without re-sorting.

#include <array>
#include <cstdint>
#include <vector>

#include "builder/kd/kd_build.h"

namespace bsprt::kd_detail {

/// Event kinds, in the order W&H sort them at equal positions.
enum class EventType : std::uint8_t { End = 0, Planar = 1, Start = 2 };

/// One event: a triangle's clipped bound on one axis. 8 bytes: position and the
/// triangle number (30 bits) with the type (2 bits).
struct Event {
  float pos;
  std::uint32_t tri_type;

  static Event make(float p, std::uint32_t tri, EventType t) { return {p, (tri << 2) | std::uint32_t(t)}; }
  std::uint32_t tri() const { return tri_type >> 2; }
  EventType type() const { return EventType(tri_type & 3u); }
  bool operator<(const Event& o) const {
    return pos < o.pos || (pos == o.pos && (tri_type & 3u) < (o.tri_type & 3u));
  }
};

/// The sorted event lists and triangle list of one node.
struct NodeEvents {
  std::array<std::vector<Event>, 3> ev;  ///< per axis, sorted by (pos, type)
  std::vector<std::uint32_t> tris;       ///< triangles of the node

  /// Appends the events of one triangle with (clipped) bounds `b`.
  void add(std::uint32_t tri, const Box3f& b);
  std::size_t size() const { return tris.size(); }
};

/// The chosen plane of a node.
struct SplitChoice {
  int axis = -1;              ///< -1: no split is cheaper than a leaf
  float pos = 0.0f;           ///< plane position, strictly inside the cell
  bool planar_left = true;    ///< triangles lying in the plane go to the lower child
  double cost = 0.0;          ///< SAH cost of the split
};

/// SAH sweep over all three axes (W&H Sec. 4.3, "FindPlane"), with the closed-
/// cell counts N_L = #(lo <= p), N_R = #(hi >= p) and planar triangles at p
/// tried on either side (Sec. 4.2). Only planes strictly inside the cell are
/// candidates, so every split shrinks the cell and the build terminates.
SplitChoice find_best_split(const NodeEvents& node, const Box3f& cell, const KdConfig& config);

/// Per-thread scratch indexed by triangle number (W&H's classification flags).
struct SplitScratch {
  std::vector<std::uint8_t> side;  ///< 0 both, 1 lower only, 2 upper only
  std::vector<Box3f> bounds;       ///< current clipped bounds of straddlers
};

/// Counts of one split (for the build report).
struct SplitCounts {
  std::size_t clipped = 0;  ///< straddling triangles clipped to a child cell
  std::size_t dropped = 0;  ///< clipped triangles that do not touch that child
};

/// Classifies the node's triangles against `split` and moves their events into
/// `lower` and `upper` (W&H Sec. 4.4): events of one-sided triangles keep their
/// order; straddlers are clipped to each child cell (perfect splits) and their
/// new events sorted and merged in. Consumes `node`.
SplitCounts split_events(NodeEvents& node, const Box3f& cell, const SplitChoice& split,
                         const std::vector<std::array<Vec3f, 3>>& triangles, bool perfect_splits,
                         SplitScratch& scratch, NodeEvents& lower, NodeEvents& upper);

}  // namespace bsprt::kd_detail
