// Bar charts as PNG images (tool/raster.h, written through ffmpeg), for
// reports: `stylus-tool eval` draws its accuracies with them.
#ifndef STYLUS_TOOL_CHARTS_H_
#define STYLUS_TOOL_CHARTS_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "tool/raster.h"

namespace stylus::tool {

struct BarSeries {
  std::string name;
  Rgb colour;
  std::vector<double> values;  // One per group, in [0, 1].
};

// Grouped bars: one group per label along the bottom, one bar per series in
// each, a 0-1 scale with grid lines at quarters, a legend and a title.
absl::Status WriteBarChart(const std::string& title, const std::vector<std::string>& groups,
                           const std::vector<BarSeries>& series, const std::string& path);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_CHARTS_H_
