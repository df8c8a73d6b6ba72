#pragma once
/// \file root_box.h
/// The check every tree loader runs on a root box read from a file: a tree
/// file is bound to its scene by a fingerprint, but its sections can still be
/// edited (and the CRC recomputed), and a root box that leaves out part of a
/// triangle would lose that triangle's hits without any error.

#include <string>

#include "bsprt/vec3.h"
#include "geometry/core/triangle_soup.h"

namespace bsprt {

/// Throws InputError naming `path` unless `box` is finite and not inverted,
/// or is the empty Box3f{} of a tree over no hittable triangle (the part of
/// check_root_box that needs no scene: a loader runs it before the
/// structural checks, which compare splits against the box).
void check_box_finite(const std::string& path, const std::string& what, const Box3f& box);

/// Throws InputError naming `path` unless `box` is finite, not inverted, and
/// holds every corner of every triangle a traversal can hit: not flagged
/// degenerate, with finite corners, not collinear (decided exactly). `what`
/// names the box in the message ("kd-tree root box").
void check_root_box(const std::string& path, const std::string& what, const Box3f& box, const TriangleSoup& soup);

}  // namespace bsprt
