// A 2-D map of style codes (the paper's Fig. 2 analogue): principal components
// of the codes of labelled clips, drawn as an SVG scatter coloured by style.
#ifndef STYLUS_TOOL_STYLE_MAP_H_
#define STYLUS_TOOL_STYLE_MAP_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace stylus::model {

struct StylePoint {
  std::string label;
  std::vector<float> code;
};

// Projects the codes on their first two principal components (power
// iteration on the covariance, deterministic) and returns the SVG text.
// INVALID_ARGUMENT for fewer than 3 points or codes of unequal length.
absl::StatusOr<std::string> StyleMapSvg(const std::vector<StylePoint>& points,
                                        const std::string& title);

}  // namespace stylus::model

#endif  // STYLUS_TOOL_STYLE_MAP_H_
