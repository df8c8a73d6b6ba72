#pragma once
// Helpers shared by the test programs: paths to shared scenes and temp files.
#include <filesystem>
#include <string>

namespace bsprt::test {

/// Absolute path of a mesh in ../shared/scenes.
inline std::string scene_path(const std::string& name) { return std::string(BSPRT_SCENES_DIR) + "/" + name; }

/// A fresh file path under the system temp folder (not created).
inline std::string temp_path(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / "bsprt_tests";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

}  // namespace bsprt::test
