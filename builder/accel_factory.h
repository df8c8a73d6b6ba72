#pragma once
/// \file accel_factory.h
/// The one table of accelerators (`--accel` names): what each mode is, which
/// options it takes, and how to make it over a scene from a tree file, from a
/// tree held in memory, or by building one. The CLI, `bsprt bench`, the tests
/// and the public API (include/bsprt/) all read it; adding a mode adds a row.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "builder/bsp/bsp_config.h"
#include "builder/tree_file.h"

#include "geometry/core/triangle_soup.h"
#include "traverse/accelerator.h"
#include "traverse/bsp/bsp_traverse.h"

namespace bsprt {

/// Options for building an accelerator in memory or loading one from a file.
struct AccelOptions {
  std::string tree_path;  ///< load this tree file instead of building (kd, bsp)
  /// A tree file already read (or held in memory): used instead of building,
  /// and instead of `tree_path`.
  std::shared_ptr<const TreeFileReader> tree_file;
  int threads = 0;        ///< 0 = all cores
  /// Called with (done, total) during long builds (the CLI draws a bar).
  std::function<void(double, double)> progress;
  BspConfig bsp;          ///< settings of an in-memory BSP build
  /// bsp-top, bsp-bvh8 and their -float forms: largest BSP subtree (in 8-byte
  /// slots) under one box of the top (traverse/bsp/bsp_boxtop.h); 0 takes the
  /// top's default, 1024 for bsp-top, 1 for bsp-bvh8 (each leaf cell its own
  /// piece; pieces of at most four triangles become triangle leaves).
  std::uint32_t top_slots = 0;
  /// bsp, bsp-zero-eps: how batches of single rays run (traverse/bsp_traverse.h).
  BspSingleRays single_rays = BspSingleRays::Auto;
  /// bsp, bsp-float, bsp-zero-eps: whether packets of incoherent rays run as
  /// single rays (Auto) or every packet through the packet kernel (Always,
  /// for tests of the kernel); traverse/bsp_traverse.h.
  BspPackets bsp_packets = BspPackets::Auto;

  bool has_tree() const { return tree_file || !tree_path.empty(); }
};

/// Which tree file a mode traces (or builds in memory when given none).
enum class AccelTree { None, Kd, Bsp };

/// One row of the accelerator table.
struct AccelInfo {
  std::string_view name;  ///< the `--accel` name
  std::string_view what;  ///< one line for --help and docs
  AccelTree tree;         ///< tree kind it takes (None: takes no tree)
  bool certified;         ///< hits equal the exact reference's bit for bit
  bool packets;           ///< trace_batch uses SIMD packets when asked
  bool slow;              ///< visits every triangle: benchmarks time it on a subset only
  bool embree_domain;     ///< traces only rays Embree accepts (embree_cannot_trace)
  bool uses_single_rays;  ///< takes AccelOptions::single_rays (--single-rays)
  bool uses_top_slots;    ///< takes AccelOptions::top_slots (--top-slots)
  /// Makes the mode over `soup` (which must outlive it). The tree, if any, is
  /// AccelOptions::tree_file, else tree_path, else built in memory.
  std::unique_ptr<Accelerator> (*make)(const TriangleSoup& soup, const AccelOptions& options);
};

/// Every accelerator, in the order --help and the docs list them.
std::span<const AccelInfo> accel_table();

/// The row named `name`; throws UsageError naming the accepted names otherwise.
const AccelInfo& accel_info(std::string_view name);

/// Accelerator names `make_tracer` accepts, in table order.
std::vector<std::string> accel_names();

/// Builds (or loads) the named accelerator over `soup`, which must outlive it.
/// Throws UsageError for an unknown name or a tree given to a mode that takes
/// none, InputError for a bad tree file.
std::unique_ptr<Accelerator> make_tracer(const std::string& accel, const TriangleSoup& soup,
                                         const AccelOptions& options = {});

/// Why the tracers refuse the BSP tree file `file` for `soup`, or "" when they
/// load it. The exact certificate (verify/) checks the geometry, independently
/// of the loaders, and not their layout rules (each leaf-list entry used once,
/// normals of unit length, depth below kBspMaxDepth, ...): `bsprt verify` and
/// bsprt::verify run this after it, so that CERTIFIED also means the file can
/// be traced. Found by a review (2026-12-07) that made verify certify files
/// `bsprt trace --tree` refused; regression test "verify: a certified BSP file
/// the tracers refuse is not certified" (tests/test_regressions.cpp).
std::string bsp_tree_load_problem(const TriangleSoup& soup, std::shared_ptr<const TreeFileReader> file);

}  // namespace bsprt
