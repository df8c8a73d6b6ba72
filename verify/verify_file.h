#pragma once
/// \file verify_file.h
/// Reads a BSP tree file's sections into the verifier's raw input
/// (robust/verify.h) without validating them: `bsprt verify` must see the file
/// as written, so inconsistencies become counter-examples, not read errors.
/// Only the container (magic, version, CRC, sizes) and the scene fingerprint
/// are checked here.

#include <string>

#include "builder/tree_file.h"
#include "verify/verify.h"

namespace bsprt {

/// The raw sections of `r` (TreeKind::Bsp). Throws InputError when the file is
/// not a BSP tree file for `soup` or a section is missing or mis-sized.
VerifyInput read_verify_input(const TreeFileReader& r, const TriangleSoup& soup);

/// Opens `path` and reads it with read_verify_input.
VerifyInput read_verify_input(const std::string& path, const TriangleSoup& soup);

}  // namespace bsprt
