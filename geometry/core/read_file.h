#pragma once
/// \file read_file.h
/// Reading a whole input file, with the checks every reader needs first: a
/// missing path, a directory or device, an unreadable file and a failed read
/// are each an InputError naming the file, never a stream exception or a
/// silently empty read.

#include <string>

namespace bsprt {

/// The bytes of the file at `path` (possibly none). `what` names the kind of
/// file in messages ("tree file", "camera file").
std::string read_file_bytes(const std::string& path, const std::string& what);

}  // namespace bsprt
