#pragma once
// Helpers shared by the test programs: paths to shared scenes and temp files.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace bsprt::test {

/// Absolute path of a mesh in ../shared/scenes.
inline std::string scene_path(const std::string& name) { return std::string(BSPRT_SCENES_DIR) + "/" + name; }

/// This process's own folder under the system temp folder, removed at exit.
/// One per process: CTest runs test cases in parallel (and two checkouts may
/// run their tests at once), and several cases use the same file names
/// ("x.hits"); a shared folder made them overwrite each other's files.
inline const std::filesystem::path& temp_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() : path(std::filesystem::temp_directory_path() / ("bsprt_tests_" + std::to_string(::getpid()))) {
      std::filesystem::remove_all(path);  // left by a killed run of the same process id
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// A fresh file path in this process's temp folder (not created).
inline std::string temp_path(const std::string& name) { return (temp_dir() / name).string(); }

/// Exit status and everything printed (stdout and stderr) of one CLI run.
struct CliRun {
  int status;
  std::string output;
};

#ifdef BSPRT_CLI_PATH
/// Runs the real `bsprt ARGS` binary and captures what it prints.
inline CliRun bsprt_cli(const std::string& args) {
  const std::string cmd = std::string(BSPRT_CLI_PATH) + " " + args + " 2>&1";
  CliRun run{0, {}};
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + cmd);
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), int(buf.size()), pipe)) run.output += buf.data();
  const int rc = pclose(pipe);
  run.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return run;
}
#endif

}  // namespace bsprt::test
