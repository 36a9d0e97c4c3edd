#include "tool/charts.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "tool/video.h"

namespace stylus::tool {

absl::Status WriteBarChart(const std::string& title, const std::vector<std::string>& groups,
                           const std::vector<BarSeries>& series, const std::string& path) {
  if (groups.empty() || series.empty()) return absl::InvalidArgumentError("an empty chart");
  const int group_w = std::max(110, 26 * static_cast<int>(series.size()) + 30);
  const int left = 50, right = 20, top = 70, bottom = 40, plot_h = 260;
  const int width = ((left + right + group_w * static_cast<int>(groups.size())) + 1) / 2 * 2;
  const int height = top + plot_h + bottom;
  Image image(std::max(width, 480), height, {255, 255, 255});
  std::vector<TextLabel> labels = {{title, "10", "10", 18}};
  const auto y_of = [&](double v) { return top + plot_h * (1 - std::clamp(v, 0.0, 1.0)); };
  for (int q = 0; q <= 4; ++q) {
    const double y = y_of(q / 4.0);
    image.Line(left, y, image.width() - right, y, 1, {225, 225, 225});
    labels.push_back({absl::StrFormat("%.2f", q / 4.0), "8", absl::StrCat(static_cast<int>(y) - 7),
                      12, "0x666666"});
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    const int x0 = left + static_cast<int>(g) * group_w + 15;
    for (size_t s = 0; s < series.size(); ++s) {
      const double v = g < series[s].values.size() ? series[s].values[g] : 0;
      const int bx = x0 + static_cast<int>(s) * 26;
      image.Fill(bx, static_cast<int>(y_of(v)), bx + 22, top + plot_h, series[s].colour);
    }
    std::string name = groups[g].substr(0, static_cast<size_t>(group_w / 7));
    labels.push_back({name, absl::StrCat(x0 - 10), absl::StrCat(top + plot_h + 8), 11});
  }
  image.Line(left, top + plot_h, image.width() - right, top + plot_h, 1, {120, 120, 120});
  // The legend: one line under the title.
  int lx = 12;
  for (const BarSeries& b : series) {
    image.Fill(lx, 40, lx + 12, 52, b.colour);
    labels.push_back({b.name, absl::StrCat(lx + 18), "39", 12});
    lx += 18 + 7 * static_cast<int>(b.name.size()) + 24;
  }
  return WritePng(image, labels, path);
}

}  // namespace stylus::tool
