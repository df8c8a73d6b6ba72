// consumer MESH: loads a mesh with the installed bsprt, builds the exact BSP,
// verifies it, traces a grid of rays towards the scene's centre in certified
// mode and compares them with the exact reference, and lists every crossing
// of the same rays (MeshQuery), none of which may lie before the nearest hit.
// Exit 0 when certified and equal, 1 otherwise.
#include <bsprt/bsprt.h>

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer MESH\n");
    return 2;
  }
  try {
    const bsprt::Scene scene = bsprt::Scene::load(argv[1]);
    const bsprt::Tree tree = bsprt::build(scene);
    const bsprt::Certificate cert = bsprt::verify(scene, tree);
    const bsprt::Box3f b = scene.bounds();
    const bsprt::Vec3f c = (b.lo + b.hi) * 0.5f, d = b.hi - b.lo;
    std::vector<bsprt::Ray> rays;
    for (int i = 0; i < 64; ++i)
      for (int j = 0; j < 64; ++j) {
        bsprt::Ray r;
        r.org = {c.x + d.x * (float(i) / 63.0f - 0.5f), c.y + d.y * (float(j) / 63.0f - 0.5f), c.z + 2.0f * d.z};
        r.dir = {0.0f, 0.0f, -1.0f};
        rays.push_back(r);
      }
    std::vector<bsprt::Hit> hits(rays.size()), ref(rays.size());
    bsprt::Tracer(scene, tree, "certified").intersect(rays, hits);
    bsprt::Tracer::exact(scene).intersect(rays, ref);
    const bsprt::HitComparison cmp = bsprt::compare_hits(ref, hits);
    const std::vector<bsprt::Crossing> crossings = bsprt::MeshQuery(scene).all_hits(rays);
    bool ordered = true;  // a crossing is a hit, so never nearer than the nearest one
    for (const bsprt::Crossing& x : crossings) ordered = ordered && ref[x.ray].hit() && x.t >= ref[x.ray].t;
    std::printf("bsprt %s: %zu triangles, tree %s, %llu rays, %llu hit, lost %llu, farther %llu, %zu crossings\n",
                bsprt::version(), scene.triangle_count(), cert.certified ? "CERTIFIED" : cert.failure.c_str(),
                (unsigned long long)cmp.rays, (unsigned long long)(cmp.rays - cmp.both_miss),
                (unsigned long long)cmp.lost, (unsigned long long)cmp.farther, crossings.size());
    return cert.certified && cmp.agrees() && cmp.same_triangle + cmp.both_miss == cmp.rays && ordered ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
