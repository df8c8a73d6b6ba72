/// \file public_symbols.cpp
/// Public functions whose definitions live in the internal libraries
/// (include/bsprt/io.h and compare.h: geometry/ray_io.cpp, hit_compare.cpp).
/// Naming them here makes the linker put them into libbsprt, where they are
/// exported; tests/test_api.cpp calls each through the installed library.
#include "bsprt/compare.h"
#include "bsprt/io.h"

namespace bsprt {
namespace {

[[gnu::used]] const void* const kPublicFunctions[] = {
    reinterpret_cast<const void*>(&read_rays),    reinterpret_cast<const void*>(&write_rays),
    reinterpret_cast<const void*>(&read_hits),    reinterpret_cast<const void*>(&write_hits),
    reinterpret_cast<const void*>(&compare_hits), reinterpret_cast<const void*>(&ulp_distance),
};

}  // namespace
}  // namespace bsprt
