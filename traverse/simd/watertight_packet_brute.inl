/// \file watertight_packet_brute.inl
/// The one source of the brute-force packet kernel, included by the per-ISA
/// translation units watertight_packet_{sse42,avx2,avx512}.cpp, each with its
/// own compile flags and width. Not a header: include it once per kernel TU.

#include <cstdint>

#include "traverse/simd/watertight_packet.h"
#include "traverse/simd/watertight_packet_brute.h"

namespace bsprt::simd {
inline namespace BSPRT_ISA_NAMESPACE {
namespace {

/// Brute force over packets of W rays: every triangle of `live` (the
/// non-degenerate ones, in order) is tested against every packet, so ties keep
/// the first triangle. Uses raw arrays only: std:: templates instantiated here
/// would be compiled for this ISA and could be merged into baseline code.
template <int W>
void brute_force_packets(const TriangleSoup& soup, std::span<const std::uint32_t> live,
                         std::span<const Ray> rays, std::span<Hit> hits, RayCounters* counters) {
  const Vec3f* vertices = soup.vertices.data();
  const TriIndices* triangles = soup.triangles.data();
  std::uint64_t valid_rays = 0;
  for (std::size_t base = 0; base < rays.size(); base += W) {
    const std::size_t count = rays.size() - base < std::size_t(W) ? rays.size() - base : std::size_t(W);
    const WatertightPacket<W> pre = watertight_precompute_packet<W>(rays.subspan(base, count));
    PacketHit<W> hit = packet_miss<W>();
    if (any<W>(pre.valid)) {
      for (const std::uint32_t i : live) {
        const TriIndices& tri = triangles[i];
        intersect_packet<W>(pre, vertices[tri[0]], vertices[tri[1]], vertices[tri[2]], i, hit,
                            pre.valid);
      }
    }
    valid_rays += std::uint64_t(__builtin_popcount(movemask<W>(pre.valid)));
    store_hits<W>(hit, hits.subspan(base, count));
  }
  if (counters) {
    counters->rays += rays.size();
    counters->triangle_tests += valid_rays * live.size();
  }
}

}  // namespace
}  // namespace BSPRT_ISA_NAMESPACE
}  // namespace bsprt::simd
