#pragma once
/// \file box_top_build.h
/// Building the box top of traverse/bsp/bsp_boxtop.h with Embree's BVH builder
/// (rtcBuildBVH): the one part of the box top that needs Embree, so it lives in
/// the library bsprt::embree, above bsprt::traverse.

#include <cstdint>
#include <span>

#include "traverse/bsp/bsp_boxtop.h"
#include "traverse/bsp/bsp_traverse.h"

namespace bsprt {

/// Builds the 4-wide top over `subtrees` with Embree's BVH builder (SAH,
/// rtcBuildBVH); each leaf holds one subtree.
BoxTop build_box_top(std::span<const BspSubtreeBox> subtrees);

/// Puts `tracer` under a box top of subtrees of at most `max_slots` slots:
/// tracer.set_box_top(build_box_top(tracer.subtree_boxes(max_slots))).
void add_box_top(BspTracer& tracer, std::uint32_t max_slots);

}  // namespace bsprt
