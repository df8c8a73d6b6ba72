#pragma once
/// \file build_device.h
/// Our own rtcBuildBVH builds (the box top, bsp_boxtop.h, and the BVH8,
/// bvh8_build.h) in one place: one Embree device for the process (making a
/// device starts Embree's worker threads, which would dominate a small build),
/// builds on it serialized (Embree promises thread safety only for calls on
/// different objects), and the BVH object whose memory holds the recorded
/// nodes released when the caller has copied them.

#include <embree3/rtcore.h>

#include <cstddef>
#include <mutex>
#include <vector>

namespace bsprt::detail {

/// What differs between our builds; the rest is Embree's medium-quality SAH build.
struct EmbreeBuildSettings {
  unsigned branching = 4;         ///< maxBranchingFactor
  unsigned max_depth = 64;        ///< maxDepth
  unsigned max_leaf_size = 1;     ///< maxLeafSize
  unsigned min_leaf_size = 1;     ///< minLeafSize: nodes of at most this many primitives are not split
  unsigned sah_block_size = 1;    ///< sahBlockSize: a leaf costs intersection_cost per started block
  float traversal_cost = 1.0f;    ///< SAH cost of a node
  float intersection_cost = 1.0f;  ///< SAH cost of a primitive
  RTCCreateNodeFunction create_node = nullptr;
  RTCSetNodeChildrenFunction set_children = nullptr;
  RTCSetNodeBoundsFunction set_bounds = nullptr;
  RTCCreateLeafFunction create_leaf = nullptr;
};

/// One rtcBuildBVH run over prims[0..count) (prims may be larger: spare
/// capacity for the builder). Holds the build lock and the BVH object (whose
/// memory holds what the callbacks allocated) until destroyed. Throws
/// std::runtime_error when Embree fails. Our callbacks take no bounds from
/// Embree (set_bounds ignores them; boxes are recomputed from the primitives),
/// so when the boxes reach beyond 2^60 they are first scaled by a power of two
/// to at most that: Embree's SAH computes box areas in float, and an area
/// that overflows to inf fails an assertion inside Embree (an abort, found on
/// a finite scene spanning ±3e38). The SAH is scale-invariant, so the tree
/// is the one the unscaled boxes would give, up to rounding.
class EmbreeBuild {
 public:
  EmbreeBuild(std::vector<RTCBuildPrimitive>& prims, std::size_t count, const EmbreeBuildSettings& settings);
  ~EmbreeBuild();
  EmbreeBuild(const EmbreeBuild&) = delete;
  EmbreeBuild& operator=(const EmbreeBuild&) = delete;
  /// What create_node / create_leaf returned for the root.
  const void* root() const { return root_; }

 private:
  std::lock_guard<std::mutex> lock_;
  RTCBVH bvh_ = nullptr;
  const void* root_ = nullptr;
};

}  // namespace bsprt::detail
