#include "geometry/core/read_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "bsprt/error.h"

namespace bsprt {

std::string read_file_bytes(const std::string& path, const std::string& what) {
  if (path.empty()) throw InputError("(empty path)", "expected the path of a " + what);
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (st.type() == std::filesystem::file_type::not_found)
    throw InputError(path, "no such file (expected a " + what + ")");
  if (st.type() == std::filesystem::file_type::directory) throw InputError(path, "is a directory, not a " + what);
  if (ec || st.type() != std::filesystem::file_type::regular)
    throw InputError(path, "not a regular file (expected a " + what + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open the " + what + " for reading");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad() || s.bad()) throw InputError(path, "error while reading the " + what);
  return std::move(s).str();
}

}  // namespace bsprt
