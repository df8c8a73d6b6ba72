/// \file build_device.cpp
/// shared_build_device and build_lock (build_device.h).
#include "traverse/embree/build_device.h"

#include <stdexcept>

namespace bsprt::detail {

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

}  // namespace bsprt::detail
