/// \file build_device.cpp
/// EmbreeBuild (build_device.h): the shared device, the lock, one rtcBuildBVH run.
#include "traverse/embree/build_device.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bsprt::detail {
namespace {

RTCDevice shared_build_device() {
  struct Holder {
    RTCDevice device = rtcNewDevice(nullptr);
    ~Holder() {
      if (device) rtcReleaseDevice(device);
    }
  };
  static const Holder holder;
  if (!holder.device) throw std::runtime_error("embree: rtcNewDevice failed");
  return holder.device;
}

std::mutex& build_lock() {
  static std::mutex m;
  return m;
}

}  // namespace

EmbreeBuild::EmbreeBuild(std::vector<RTCBuildPrimitive>& prims, std::size_t count, const EmbreeBuildSettings& s)
    : lock_(build_lock()) {
  float big = 0.0f;
  for (std::size_t i = 0; i < count; ++i) {
    const RTCBuildPrimitive& p = prims[i];
    for (const float v : {p.lower_x, p.lower_y, p.lower_z, p.upper_x, p.upper_y, p.upper_z})
      big = std::max(big, std::fabs(v));
  }
  if (big > 0x1p60f) {
    const int shift = std::ilogb(big) - 60;  // exact scaling by 2^-shift (tiny values may round: topology only)
    for (std::size_t i = 0; i < count; ++i) {
      RTCBuildPrimitive& p = prims[i];
      for (float* v : {&p.lower_x, &p.lower_y, &p.lower_z, &p.upper_x, &p.upper_y, &p.upper_z})
        *v = std::ldexp(*v, -shift);
    }
  }
  const RTCDevice device = shared_build_device();
  bvh_ = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = s.branching;
  args.maxDepth = s.max_depth;
  args.minLeafSize = s.min_leaf_size;
  args.sahBlockSize = s.sah_block_size;
  args.maxLeafSize = s.max_leaf_size;
  args.traversalCost = s.traversal_cost;
  args.intersectionCost = s.intersection_cost;
  args.bvh = bvh_;
  args.primitives = prims.data();
  args.primitiveCount = count;
  args.primitiveArrayCapacity = prims.size();
  args.createNode = s.create_node;
  args.setNodeChildren = s.set_children;
  args.setNodeBounds = s.set_bounds;
  args.createLeaf = s.create_leaf;
  root_ = rtcBuildBVH(&args);
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE || root_ == nullptr) {
    rtcReleaseBVH(bvh_);
    throw std::runtime_error("embree: rtcBuildBVH failed (code " + std::to_string(int(err)) + ")");
  }
}

EmbreeBuild::~EmbreeBuild() { rtcReleaseBVH(bvh_); }

}  // namespace bsprt::detail
