#pragma once
/// \file kd_file.h
/// kd-trees in tree files (tree_file.h, TreeKind::Kd): the nodes, the leaf
/// triangle lists, the root bounds and the build config, bound to the scene.

#include <string>

#include "builder/kd/kd_build.h"
#include "builder/tree_file.h"

namespace bsprt {

/// Section tags of a kd tree file.
inline constexpr std::uint32_t kKdNodesTag = tree_tag("KNOD");   ///< KdNode[]
inline constexpr std::uint32_t kKdPrimsTag = tree_tag("KPRM");   ///< uint32 triangle numbers
inline constexpr std::uint32_t kKdBoundsTag = tree_tag("KBND");  ///< float lo[3], hi[3]
inline constexpr std::uint32_t kKdConfigTag = tree_tag("KCFG");  ///< KdConfig fields (see kd_file.cpp)

/// Writes `tree`, built for `soup` with `config`, to `path`. Throws InputError
/// when the file cannot be written.
void write_kd_tree(const std::string& path, const KdTree& tree, const TriangleSoup& soup,
                   const KdConfig& config = {});

/// Reads a kd tree file built for `soup`; `config` (if non-null) receives the
/// build config stored in it. Throws InputError naming the file when it is
/// truncated, corrupt, of another version or kind, built for another scene, or
/// holds a tree that fails KdTree::validate() or is too deep to traverse.
KdTree read_kd_tree(const std::string& path, const TriangleSoup& soup, KdConfig* config = nullptr);

/// The kd sections of `file` as a validated tree over `triangle_count`
/// triangles, without the scene check (`bsprt stats` has no scene).
KdTree read_kd_sections(const TreeFileReader& file, std::uint32_t triangle_count, KdConfig* config = nullptr);

/// read_kd_tree on a file already opened (or held in memory).
KdTree read_kd_tree(const TreeFileReader& file, const TriangleSoup& soup, KdConfig* config = nullptr);

/// The complete kd tree file of `tree`, ready to write or to keep in memory.
TreeFileWriter kd_tree_file(const KdTree& tree, const TriangleSoup& soup, const KdConfig& config = {});

}  // namespace bsprt
