#pragma once
/// \file tree_kind.h
/// The kinds of acceleration tree bsprt builds and stores in tree files.

#include <cstdint>

namespace bsprt {

/// What a tree (file) holds; the values are those of the tree-file header.
enum class TreeKind : std::uint32_t {
  Kd = 1,   ///< SAH kd-tree (docs/kd-tree.md)
  Bsp = 2,  ///< the exact general BSP tree and its certified float flattening (docs/bsp-build.md)
};

}  // namespace bsprt
