/// \file embree_tracer.cpp
/// Embree 3 behind the Accelerator interface.
///
/// Degenerate triangles: Embree's own handling of zero-area triangles is not
/// documented, so they are not given to Embree at all. The index buffer holds
/// the non-degenerate triangles only and `prim_of_` maps Embree's primID back to
/// our triangle number (left empty, the identity, when nothing was dropped).
///
/// Barycentrics: Embree's hit point is (1-u-v) p0 + u p1 + v p2, the same
/// convention as the hit format, so u and v are copied through.
#include "traverse/embree/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsprt/error.h"

namespace bsprt {

namespace {
/// Everything the tracer holds; a plain struct so the Embree callbacks below
/// can reach it (EmbreeTracer::Impl is private).
struct EmbreeState {
  EmbreeConfig config;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<std::uint32_t> prim_of_;  ///< Embree primID -> triangle number (empty = identity)
  std::atomic<std::int64_t> bytes{0};   ///< net bytes Embree allocated (memory monitor)
  std::string last_error;               ///< message of the last Embree error

  ~EmbreeState() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  std::uint32_t prim(unsigned prim_id) const {
    return prim_of_.empty() ? prim_id : prim_of_[prim_id];
  }
  /// Throws std::runtime_error when Embree reported an error during `what`.
  void check(const char* what) const {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE || !last_error.empty())
      throw std::runtime_error(std::string("embree: ") + what + " failed: " +
                               (last_error.empty() ? "error code " + std::to_string(int(e)) : last_error));
  }
};

void on_error(void* user, RTCError code, const char* message) {
  auto* impl = static_cast<EmbreeState*>(user);
  impl->last_error = std::string(message ? message : "unknown error") + " (code " + std::to_string(int(code)) + ")";
}

/// Counts Embree's allocations of one device: this is how memory_bytes knows
/// the size of the BVH and buffers (exact, not an estimate).
bool on_memory(void* user, ssize_t bytes, bool /*post*/) {
  static_cast<EmbreeState*>(user)->bytes += bytes;
  return true;
}

/// Copies the soup into a new Embree triangle geometry (float3 vertices,
/// uint3 indices of the non-degenerate triangles) attached to `scene`.
void add_geometry(EmbreeState& impl, const TriangleSoup& soup) {
  std::vector<std::uint32_t> live;
  live.reserve(soup.size());
  for (std::uint32_t i = 0; i < soup.size(); ++i)
    if (!soup.is_degenerate(i)) live.push_back(i);
  if (live.size() != soup.size()) impl.prim_of_ = live;

  RTCGeometry geom = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  impl.check("rtcNewGeometry");
  const std::size_t nv = soup.vertices.empty() ? 1 : soup.vertices.size();
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), nv));
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), live.size()));
  impl.check("rtcSetNewGeometryBuffer");
  for (std::size_t i = 0; i < soup.vertices.size(); ++i) {
    vb[3 * i] = soup.vertices[i].x, vb[3 * i + 1] = soup.vertices[i].y, vb[3 * i + 2] = soup.vertices[i].z;
  }
  if (soup.vertices.empty()) vb[0] = vb[1] = vb[2] = 0.0f;
  for (std::size_t j = 0; j < live.size(); ++j)
    for (int k = 0; k < 3; ++k) ib[3 * j + k] = soup.triangles[live[j]][k];
  if (impl.config.high_quality) rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl.scene, geom);
  rtcReleaseGeometry(geom);
  impl.check("geometry setup");
}

/// An Embree ray for a valid ray of ours.
RTCRayHit to_embree(const Ray& r) {
  RTCRayHit rh{};
  rh.ray.org_x = r.org.x, rh.ray.org_y = r.org.y, rh.ray.org_z = r.org.z;
  rh.ray.dir_x = r.dir.x, rh.ray.dir_y = r.dir.y, rh.ray.dir_z = r.dir.z;
  rh.ray.tnear = r.tnear, rh.ray.tfar = r.tfar;
  rh.ray.time = 0.0f, rh.ray.mask = ~0u, rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID, rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

/// Traces rays.size() <= N rays with rtcIntersectN (RH = RTCRayHit4/8/16).
template <int N, typename RH>
void trace_packet(const EmbreeState& impl, std::span<const Ray> rays, std::span<Hit> hits,
                  RTCIntersectContext* ctx) {
  alignas(64) RH rh{};
  alignas(64) int valid[N] = {};
  for (int i = 0; i < N; ++i) {
    const bool ok = std::size_t(i) < rays.size() && is_valid(rays[i]);
    valid[i] = ok ? -1 : 0;
    // Invalid lanes get a harmless ray, never NaNs (Embree may still read them).
    const Ray r = ok ? rays[i] : Ray{{0, 0, 0}, 0.0f, {0, 0, 1}, 0.0f};
    rh.ray.org_x[i] = r.org.x, rh.ray.org_y[i] = r.org.y, rh.ray.org_z[i] = r.org.z;
    rh.ray.dir_x[i] = r.dir.x, rh.ray.dir_y[i] = r.dir.y, rh.ray.dir_z[i] = r.dir.z;
    rh.ray.tnear[i] = r.tnear, rh.ray.tfar[i] = r.tfar;
    rh.ray.mask[i] = ~0u;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  }
  if constexpr (N == 4) rtcIntersect4(valid, impl.scene, ctx, &rh);
  else if constexpr (N == 8) rtcIntersect8(valid, impl.scene, ctx, &rh);
  else rtcIntersect16(valid, impl.scene, ctx, &rh);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Hit h;
    if (valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID)
      h = Hit{rh.ray.tfar[i], impl.prim(rh.hit.primID[i]), rh.hit.u[i], rh.hit.v[i]};
    hits[i] = h;
  }
}

/// Embree's FLT_LARGE (common/sys/platform.h): RayK::valid() asserts |org| and
/// |dir| components at most this.
constexpr float kEmbreeLarge = 1.844E18f;

/// The cheap test the batch loop runs first (about a tenth of
/// embree_cannot_trace's instructions): tnear >= 0 and every origin and
/// direction component at most kEmbreeLarge in magnitude, decided on the bits
/// (|x| as an unsigned integer orders like |x|; NaN and inf compare above).
/// False only sends the ray to the full check.
inline bool surely_in_domain(const Ray& r) {
  const std::uint32_t large = std::bit_cast<std::uint32_t>(kEmbreeLarge);
  std::uint32_t m = 0;
  for (float f : {r.org.x, r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z})
    m = std::max(m, std::bit_cast<std::uint32_t>(f) & 0x7FFFFFFFu);
  return m <= large && r.tnear >= 0.0f;
}

/// Throws UsageError naming ray `index` of a batch (or "the ray" for a
/// single one, index < 0) when Embree cannot trace it.
void check_embree_domain(const Ray& r, std::ptrdiff_t index) {
  if (const char* why = embree_cannot_trace(r))
    throw UsageError("embree: " + (index < 0 ? std::string("the ray") : "ray " + std::to_string(index)) + " has " +
                     why + "; such a ray is valid (formats.md): kd, bsp, brute and exact trace it");
}

}  // namespace

const char* embree_cannot_trace(const Ray& r) {
  if (!is_valid(r)) return nullptr;
  if (!(r.tnear >= 0.0f)) return "tnear < 0 (Embree traces only tnear >= 0)";
  for (int k = 0; k < 3; ++k)
    if (std::fabs(r.org[k]) > kEmbreeLarge || std::fabs(r.dir[k]) > kEmbreeLarge)
      return "an origin or direction component above 1.844e18 in magnitude (Embree's limit)";
  return nullptr;
}

struct EmbreeTracer::Impl : EmbreeState {};

EmbreeTracer::EmbreeTracer(const TriangleSoup& soup, const EmbreeConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->config = config;
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw std::runtime_error("embree: rtcNewDevice failed (error code " +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  EmbreeState* state = impl_.get();
  rtcSetDeviceErrorFunction(impl_->device, on_error, state);
  rtcSetDeviceMemoryMonitorFunction(impl_->device, on_memory, state);
  impl_->scene = rtcNewScene(impl_->device);
  impl_->check("rtcNewScene");
  rtcSetSceneFlags(impl_->scene, config.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(impl_->scene, config.high_quality ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  add_geometry(*impl_, soup);
  rtcCommitScene(impl_->scene);
  impl_->check("rtcCommitScene");
}

EmbreeTracer::~EmbreeTracer() = default;

std::string EmbreeTracer::name() const { return impl_->config.robust ? "embree" : "embree-fast"; }

namespace {

/// One ray already checked (valid or not, inside Embree's domain), with a context made once per batch.
inline Hit trace_checked(const EmbreeState& impl, const Ray& ray, RTCIntersectContext* ctx) {
  if (!is_valid(ray)) return Hit{};
  RTCRayHit rh = to_embree(ray);
  rtcIntersect1(impl.scene, ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return Hit{};
  return Hit{rh.ray.tfar, impl.prim(rh.hit.primID), rh.hit.u, rh.hit.v};
}

}  // namespace

Hit EmbreeTracer::trace(const Ray& ray, RayCounters* counters) const {
  if (counters) ++counters->rays;
  check_embree_domain(ray, -1);  // nullptr for invalid rays: they miss below
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  return trace_checked(*impl_, ray, &ctx);
}

bool EmbreeTracer::occluded(const Ray& ray, RayCounters* counters) const {
  if (counters) ++counters->rays;
  check_embree_domain(ray, -1);
  if (!is_valid(ray)) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = to_embree(ray);
  rtcOccluded1(impl_->scene, &ctx, &rh.ray);
  return rh.ray.tfar == -std::numeric_limits<float>::infinity();  // Embree's mark of an occluded ray
}

void EmbreeTracer::trace_batch(std::span<const Ray> rays, std::span<Hit> hits, int packet_width,
                               RayCounters* counters) const {
  if (hits.size() != rays.size())
    throw UsageError("EmbreeTracer::trace_batch: " + std::to_string(rays.size()) + " rays but " +
                     std::to_string(hits.size()) + " hits");
  if (packet_width != 1 && packet_width != 4 && packet_width != 8 && packet_width != 16)
    throw UsageError("packet width must be 1, 4, 8 or 16, not " + std::to_string(packet_width));
  for (std::size_t i = 0; i < rays.size(); ++i)  // before any ray is traced
    if (!surely_in_domain(rays[i])) check_embree_domain(rays[i], std::ptrdiff_t(i));
  if (packet_width == 1) {  // each ray checked once (above), one context for the batch
    if (counters) counters->rays += rays.size();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = trace_checked(*impl_, rays[i], &ctx);
    return;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  const std::size_t w = std::size_t(packet_width);
  for (std::size_t base = 0; base < rays.size(); base += w) {
    const std::size_t n = rays.size() - base < w ? rays.size() - base : w;
    const auto r = rays.subspan(base, n);
    const auto h = hits.subspan(base, n);
    if (packet_width == 4) trace_packet<4, RTCRayHit4>(*impl_, r, h, &ctx);
    else if (packet_width == 8) trace_packet<8, RTCRayHit8>(*impl_, r, h, &ctx);
    else trace_packet<16, RTCRayHit16>(*impl_, r, h, &ctx);
  }
  if (counters) counters->rays += rays.size();
}

std::size_t EmbreeTracer::memory_bytes() const {
  const std::int64_t b = impl_->bytes.load();
  return b > 0 ? std::size_t(b) : 0;
}

}  // namespace bsprt
