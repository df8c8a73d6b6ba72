#pragma once
/// \file build_device.h
/// The one Embree device of the process for our own rtcBuildBVH builds (the
/// box top, bsp_boxtop.h, and the BVH8, bvh8_build.h). Making a device starts
/// Embree's worker threads, which would dominate a small build; builds on it
/// are serialized with build_lock(), since Embree promises thread safety only
/// for calls on different objects.

#include <embree3/rtcore.h>

#include <mutex>

namespace bsprt::detail {

/// The shared device; throws std::runtime_error when Embree cannot make one.
RTCDevice shared_build_device();
/// Held around each build on the shared device.
std::mutex& build_lock();

}  // namespace bsprt::detail
