#include "tool/raster.h"

#include <algorithm>
#include <cmath>

namespace stylus::tool {

Image::Image(int width, int height, Rgb fill)
    : width_(width), height_(height), rgb_(static_cast<size_t>(width) * height * 3) {
  Fill(0, 0, width, height, fill);
}

void Image::Fill(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(0, y0); y < std::min(height_, y1); ++y) {
    for (int x = std::max(0, x0); x < std::min(width_, x1); ++x) Blend(x, y, c, 1);
  }
}

void Image::Paste(const Image& src, int x, int y) {
  for (int row = 0; row < src.height_; ++row) {
    const int ty = y + row;
    if (ty < 0 || ty >= height_) continue;
    const int x0 = std::max(0, x), x1 = std::min(width_, x + src.width_);
    if (x0 >= x1) continue;
    std::copy_n(&src.rgb_[(static_cast<size_t>(row) * src.width_ + (x0 - x)) * 3], (x1 - x0) * 3,
                &rgb_[(static_cast<size_t>(ty) * width_ + x0) * 3]);
  }
}

void Image::Blend(int x, int y, Rgb c, double alpha) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_ || alpha <= 0) return;
  alpha = std::min(alpha, 1.0);
  uint8_t* p = &rgb_[(static_cast<size_t>(y) * width_ + x) * 3];
  p[0] = static_cast<uint8_t>(std::lround(p[0] + (c.r - p[0]) * alpha));
  p[1] = static_cast<uint8_t>(std::lround(p[1] + (c.g - p[1]) * alpha));
  p[2] = static_cast<uint8_t>(std::lround(p[2] + (c.b - p[2]) * alpha));
}

void Image::Line(double x0, double y0, double x1, double y1, double width, Rgb c) {
  if (!std::isfinite(x0 + y0 + x1 + y1)) return;
  const double r = width / 2;
  const int xa = static_cast<int>(std::floor(std::min(x0, x1) - r - 1));
  const int xb = static_cast<int>(std::ceil(std::max(x0, x1) + r + 1));
  const int ya = static_cast<int>(std::floor(std::min(y0, y1) - r - 1));
  const int yb = static_cast<int>(std::ceil(std::max(y0, y1) + r + 1));
  const double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
  for (int y = std::max(0, ya); y <= std::min(height_ - 1, yb); ++y) {
    for (int x = std::max(0, xa); x <= std::min(width_ - 1, xb); ++x) {
      const double px = x + 0.5 - x0, py = y + 0.5 - y0;
      const double t = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0;
      const double d = std::hypot(px - t * dx, py - t * dy);
      Blend(x, y, c, r + 0.5 - d);  // Coverage of a pixel near the edge.
    }
  }
}

void Image::Disc(double x, double y, double radius, Rgb c) { Line(x, y, x, y, 2 * radius, c); }

}  // namespace stylus::tool
