#pragma once
/// \file tree.h
/// Building, saving, loading and verifying acceleration trees.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bsprt/scene.h"
#include "bsprt/tree_kind.h"

namespace bsprt {

class TreeFileReader;

/// Which triangles a BSP leaf lists (docs/bsp-build.md).
enum class Membership {
  Area,    ///< triangles meeting the leaf's cell in positive area (default)
  Closed,  ///< every triangle touching the leaf's closed cell
};

/// Settings of `build`.
struct BuildOptions {
  TreeKind kind = TreeKind::Bsp;          ///< kd-tree or exact BSP
  int threads = 0;                        ///< worker threads; 0 = all cores
  Membership membership = Membership::Area;  ///< BSP only
  /// Called with (done, total) while building, from any thread but never two
  /// at once; the last call is (total, total). kd builds report start and end.
  std::function<void(double done, double total)> progress;
  /// Polled with each progress report; returning true stops the build, which
  /// then throws Cancelled.
  std::function<bool()> cancel;
};

/// Thrown by `build` when BuildOptions::cancel asked it to stop.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("build cancelled") {}
};

/// A built tree, held as the bytes of its tree file (formats.md): saving writes
/// exactly what `bsprt build` writes. Loading checks the container (magic,
/// version, CRC, sizes) and that the file was built for the scene; the tree's
/// own sections are checked when a Tracer is made from it (as `bsprt trace`
/// does) and proven by verify().
class Tree {
 public:
  /// Reads a tree file built for `scene`. Throws InputError naming the file when
  /// it is corrupt, truncated, of another version, or built for another scene.
  static Tree load(const std::string& path, const Scene& scene);
  /// Writes the tree file; throws InputError when it cannot be written.
  void save(const std::string& path) const;

  /// kd or BSP.
  TreeKind kind() const;
  /// The whole tree file image.
  std::span<const std::byte> bytes() const;
  /// Wall time of the build (0 for a loaded tree).
  double build_seconds() const;
  /// The scene it was built for.
  const Scene& scene() const;

  /// bsprt's internal tree-file reader (for bsprt's own tools; not part of the stable API).
  std::shared_ptr<const TreeFileReader> file() const;

 public:
  struct Impl;  ///< the implementation (api/): opaque here

 private:
  explicit Tree(std::shared_ptr<const Impl> impl);
  /// *impl_; a UsageError for an object moved from (whose impl_ is null), not a crash.
  const Impl& impl() const;
  std::shared_ptr<const Impl> impl_;
  friend Tree build(const Scene&, const BuildOptions&);
};

/// Builds a kd-tree or the exact BSP tree over `scene` (degenerate triangles
/// are left out; they are never hit). Throws Cancelled when cancelled.
Tree build(const Scene& scene, const BuildOptions& options = {});

/// The outcome of `verify`: certified, or the first counter-example.
struct Certificate {
  bool certified = false;      ///< every property held (docs/verify.md)
  std::string failure;         ///< the first counter-example in words (empty when certified)
  std::uint32_t node = 0xFFFFFFFFu;      ///< its node, when one applies
  std::uint32_t triangle = 0xFFFFFFFFu;  ///< its triangle, when one applies
  std::optional<Vec3d> witness;          ///< a point showing it, when one applies
  std::uint64_t nodes = 0, leaves = 0;   ///< nodes and leaves checked (BSP)
  std::uint64_t pairs = 0;               ///< (triangle, leaf) pairs decided exactly (BSP)
  std::uint64_t exact_fallbacks = 0;     ///< side tests the interval filter could not decide (BSP)
  double seconds = 0.0;                  ///< wall time
};

/// Settings of `verify`.
struct VerifyOptions {
  int threads = 0;      ///< worker threads; 0 = all cores
  bool strict = false;  ///< BSP trees: listings that do not touch the leaf's cell fail (default: warnings); kd: unused
};

/// Proves `tree` correct for `scene` with exact arithmetic, independently of
/// the builder: what `bsprt verify` prints as CERTIFIED or FAILED.
Certificate verify(const Scene& scene, const Tree& tree, const VerifyOptions& options = {});

}  // namespace bsprt
