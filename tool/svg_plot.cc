#include "tool/svg_plot.h"

#include "absl/strings/str_format.h"

namespace stylus::tool {

const char* ModelColour(size_t i) {
  static const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e"};
  return kColours[i % 5];
}

std::string SvgLegend(const std::vector<std::pair<std::string, std::string>>& keys, double y,
                      double* right) {
  std::string legend;
  double x = 10;
  for (const auto& [label, colour] : keys) {
    absl::StrAppendFormat(&legend,
                          "<rect x='%.1f' y='%.1f' width='14' height='4' fill='%s'/>"
                          "<text x='%.1f' y='%.1f' font-size='12'>%s</text>\n",
                          x, y, colour, x + 18, y + 6, label);
    x += 30 + 7.0 * label.size();
  }
  *right = x;
  return legend;
}

std::string SvgDocument(double width, double height, const std::string& body) {
  return absl::StrFormat(
      "<svg xmlns='http://www.w3.org/2000/svg' width='%.0f' height='%.0f' "
      "font-family='sans-serif'>\n<rect width='100%%' height='100%%' fill='white'/>\n%s</svg>\n",
      width, height, body);
}

}  // namespace stylus::tool
