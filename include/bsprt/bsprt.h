#pragma once
/// \file bsprt.h
/// The whole public API of bsprt (docs/api.md): scenes, trees (build, save,
/// load, verify), tracers (nearest hit, occluded), the exact reference, and
/// ray-by-ray comparison. Only bsprt's own types and the standard library
/// appear here: no CGAL, Embree or TBB header is reachable from include/bsprt/.

#include "bsprt/compare.h"
#include "bsprt/error.h"
#include "bsprt/io.h"
#include "bsprt/query.h"
#include "bsprt/ray.h"
#include "bsprt/scene.h"
#include "bsprt/tracer.h"
#include "bsprt/tree.h"
#include "bsprt/vec3.h"
#include "bsprt/version.h"
