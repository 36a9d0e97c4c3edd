#include "tool/style_map.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace stylus::model {
namespace {

using Vec = std::vector<double>;

// Leading eigenvector of the symmetric matrix `c` (n x n), orthogonal to `skip`.
Vec PowerIteration(const std::vector<Vec>& c, const Vec* skip) {
  const size_t n = c.size();
  Vec v(n);
  for (size_t i = 0; i < n; ++i)
    v[i] = 1.0 + 0.01 * static_cast<double>(i % 7);  // Deterministic start.
  for (int it = 0; it < 500; ++it) {
    if (skip) {
      double d = 0;
      for (size_t i = 0; i < n; ++i) d += v[i] * (*skip)[i];
      for (size_t i = 0; i < n; ++i) v[i] -= d * (*skip)[i];
    }
    Vec w(n, 0);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) w[i] += c[i][j] * v[j];
    double norm = 0;
    for (double x : w) norm += x * x;
    norm = std::sqrt(norm);
    if (norm < 1e-30) break;
    for (size_t i = 0; i < n; ++i) v[i] = w[i] / norm;
  }
  return v;
}

}  // namespace

absl::StatusOr<std::string> StyleMapSvg(const std::vector<StylePoint>& points,
                                        const std::string& title) {
  if (points.size() < 3) return absl::InvalidArgumentError("need at least 3 style codes for a map");
  const size_t n = points[0].code.size();
  for (const StylePoint& p : points) {
    if (p.code.size() != n) return absl::InvalidArgumentError("style codes of unequal length");
  }
  Vec mean(n, 0);
  for (const StylePoint& p : points)
    for (size_t i = 0; i < n; ++i) mean[i] += p.code[i] / points.size();
  std::vector<Vec> cov(n, Vec(n, 0));
  for (const StylePoint& p : points)
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) cov[i][j] += (p.code[i] - mean[i]) * (p.code[j] - mean[j]);
  const Vec pc1 = PowerIteration(cov, nullptr);
  const Vec pc2 = PowerIteration(cov, &pc1);
  std::vector<std::pair<double, double>> xy;
  for (const StylePoint& p : points) {
    double a = 0, b = 0;
    for (size_t i = 0; i < n; ++i)
      a += (p.code[i] - mean[i]) * pc1[i], b += (p.code[i] - mean[i]) * pc2[i];
    xy.push_back({a, b});
  }
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (auto [a, b] : xy)
    x0 = std::min(x0, a), x1 = std::max(x1, a), y0 = std::min(y0, b), y1 = std::max(y1, b);
  const double w = 640, h = 480, margin = 40, legend = 170;
  auto sx = [&](double a) {
    return margin + (a - x0) / std::max(x1 - x0, 1e-12) * (w - 2 * margin);
  };
  auto sy = [&](double b) {
    return h - margin - (b - y0) / std::max(y1 - y0, 1e-12) * (h - 2 * margin);
  };
  std::map<std::string, int> colour_of;
  for (const StylePoint& p : points) colour_of.emplace(p.label, 0);
  int k = 0;
  for (auto& [label, c] : colour_of) c = k++;
  auto colour = [&](int c) {
    return absl::StrFormat("hsl(%d,70%%,45%%)", (c * 360) / std::max(1, k));
  };
  std::string svg = absl::StrFormat(
      "<svg xmlns='http://www.w3.org/2000/svg' width='%d' height='%d' font-family='sans-serif' "
      "font-size='11'>\n"
      "<rect width='100%%' height='100%%' fill='white'/>\n<text x='%d' y='20' "
      "font-size='13'>%s</text>\n",
      static_cast<int>(w + legend), static_cast<int>(h), static_cast<int>(margin), title);
  for (size_t i = 0; i < points.size(); ++i) {
    absl::StrAppendFormat(&svg,
                          "<circle cx='%.1f' cy='%.1f' r='4' fill='%s' fill-opacity='0.8'/>\n",
                          sx(xy[i].first), sy(xy[i].second), colour(colour_of[points[i].label]));
  }
  int row = 0;
  for (const auto& [label, c] : colour_of) {
    const double y = 40 + 16 * row++;
    absl::StrAppendFormat(
        &svg, "<circle cx='%.0f' cy='%.0f' r='5' fill='%s'/><text x='%.0f' y='%.0f'>%s</text>\n",
        w + 10, y, colour(c), w + 20, y + 4, label);
  }
  absl::StrAppendFormat(
      &svg, "<text x='%.0f' y='%.0f'>PC1</text><text x='8' y='%.0f'>PC2</text>\n</svg>\n", w / 2,
      h - 10, h / 2);
  return svg;
}

}  // namespace stylus::model
