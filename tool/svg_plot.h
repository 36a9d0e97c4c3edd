// Pieces shared by the offline commands that draw SVG plots of a model's
// transfers beside the models they are compared with (trajectories, gait).
#ifndef STYLUS_TOOL_SVG_PLOT_H_
#define STYLUS_TOOL_SVG_PLOT_H_

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace stylus::tool {

// The colour of the i-th model of a plot (the main model first).
const char* ModelColour(size_t i);

// One row of keys, (label, colour) each, from x = 10 at height `y`; sets
// *right to where the row ends.
std::string SvgLegend(const std::vector<std::pair<std::string, std::string>>& keys, double y,
                      double* right);

// A whole SVG document: a white page of `width` x `height` around `body`.
std::string SvgDocument(double width, double height, const std::string& body);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_SVG_PLOT_H_
