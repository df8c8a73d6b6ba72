// bsprt: the command-line tool. Each subcommand lives in its own cmd_*.cpp;
// this file only dispatches and turns errors into messages and exit codes.
#include <fmt/core.h>

#include <exception>

#include "apps/cli_common.h"
#include "bsprt/error.h"

int main(int argc, char** argv) {
  CLI::App app{"bsprt: ray tracing with general BSP trees, built exactly, traversed with certified epsilons"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "bsprt 0.1.0");
  bsprt::cli::register_trace(app);
  bsprt::cli::register_render(app);
  bsprt::cli::register_info(app);
  bsprt::cli::register_inside(app);
  bsprt::cli::register_gen_rays(app);
  bsprt::cli::register_compare(app);
  bsprt::cli::register_build(app);
  bsprt::cli::register_bench(app);
  bsprt::cli::register_gen(app);
  bsprt::cli::register_verify(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 prints the message (or the help); its own codes (105, 106, ...)
    // become the documented usage code 2.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const bsprt::cli::CompareFailed&) {
    return 1;
  } catch (const bsprt::InputError& e) {
    fmt::print(stderr, "bsprt: error: {}\n", e.what());
    return 1;
  } catch (const bsprt::UsageError& e) {
    fmt::print(stderr, "bsprt: usage error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "bsprt: internal error: {}\n", e.what());
    return 3;
  }
  return 0;
}
