// `bsprt compare REFERENCE.hits TESTED.hits`: ray-by-ray comparison with the
// categories of shared/formats.md; exits 1 when anything is lost or misplaced.
#include <fmt/core.h>

#include <memory>

#include "apps/cli_common.h"
#include "bsprt/compare.h"
#include "bsprt/io.h"

namespace bsprt::cli {
namespace {

struct CompareArgs {
  std::string reference, tested;
  double tolerance = 1e-5;
  bool json = false;
};

int run(const CompareArgs& a) {
  const std::vector<Hit> reference = read_hits(a.reference), tested = read_hits(a.tested);
  if (reference.size() != tested.size())
    throw UsageError(a.reference + " holds " + std::to_string(reference.size()) + " hits, " + a.tested + " " +
                     std::to_string(tested.size()) + ": they are not hits of the same rays");
  const HitComparison c = compare_hits(reference, tested, a.tolerance);
  if (a.json) {
    fmt::print("{{\"rays\": {}, \"both_miss\": {}, \"same_triangle\": {}, \"t_off\": {}, \"tie\": {}, "
               "\"lost\": {}, \"extra\": {}, \"farther\": {}, \"nearer\": {}, \"max_t_ulps\": {}}}\n",
               c.rays, c.both_miss, c.same_triangle, c.t_off, c.tie, c.lost, c.extra, c.farther, c.nearer,
               c.max_t_ulps);
  } else {
    fmt::print("rays {}: both miss {}, same triangle {}, same triangle at a t beyond tolerance {}, tie {}, lost {}, "
               "extra {}, farther {}, nearer {}; max t error {} ulps\n",
               c.rays, c.both_miss, c.same_triangle, c.t_off, c.tie, c.lost, c.extra, c.farther, c.nearer,
               c.max_t_ulps);
    if (!c.agrees()) fmt::print("first disagreement at ray {}\n", c.first_bad_ray);
  }
  return c.agrees() ? 0 : 1;
}

}  // namespace

void register_compare(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand("compare", "compare two .hits files ray by ray (reference first)");
  cmd->add_option("REFERENCE", args->reference, "reference .hits file")->required()->check(CLI::ExistingFile);
  cmd->add_option("TESTED", args->tested, "tested .hits file")->required()->check(CLI::ExistingFile);
  cmd->add_option("--tolerance", args->tolerance, "relative t tolerance of ties and of t on the same triangle")
      ->capture_default_str()->check(number_at_least(0.0));
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->callback([args] {
    if (run(*args) != 0) throw CompareFailed();
  });
}

}  // namespace bsprt::cli
