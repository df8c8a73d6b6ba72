#pragma once
/// \file heat_map.h
/// Per-pixel cost images (Ize et al., RT 2008, Fig. 6: "pixel intensity = time
/// spent rendering the pixel"): time, node visits or triangle tests of each
/// pixel's primary ray, drawn with a perceptual colour map and a labelled
/// colour bar; and signed difference images between two accelerators.

#include <string>
#include <vector>

#include "apps/image_io.h"
#include "apps/render.h"
#include "traverse/accelerator.h"

namespace bsprt {

/// What a heat map shows.
enum class HeatMetric { Time, Nodes, Tests };

/// "time", "nodes", "tests"; parse throws UsageError for other names.
std::string heat_metric_name(HeatMetric m);
HeatMetric parse_heat_metric(const std::string& name);

/// Cost of each pixel's primary ray (row-major): nanoseconds for Time (the
/// median of `repeats` timings), node visits (kd + BSP) for Nodes, ray/triangle
/// tests for Tests. Parallel over rows; counts are deterministic, times are not.
std::vector<float> pixel_costs(const Accelerator& tracer, const RenderOptions& options, HeatMetric metric, int repeats = 3);

/// Colour-maps `cost` (0 .. scale_max; 0 = use the maximum) and appends a colour
/// bar labelled with `title` and its scale.
Image heat_image(const std::vector<float>& cost, int width, int height, float scale_max, const std::string& title);

/// Signed difference a - b with a diverging map (blue: a cheaper, red: a
/// dearer), symmetric scale, and a colour bar.
Image heat_difference_image(const std::vector<float>& a, const std::vector<float>& b, int width, int height,
                            const std::string& title);

}  // namespace bsprt
