// A small RGB rasterizer for stylus-tool's videos: anti-aliased thick lines
// and discs on an 8-bit RGB image, no dependencies.
#ifndef STYLUS_TOOL_RASTER_H_
#define STYLUS_TOOL_RASTER_H_

#include <cstdint>
#include <vector>

namespace stylus::tool {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
};

class Image {
 public:
  Image(int width, int height, Rgb fill);
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<uint8_t>& bytes() const { return rgb_; }  // Row-major RGB.

  // A segment `width` pixels wide with round ends, edges anti-aliased.
  void Line(double x0, double y0, double x1, double y1, double width, Rgb colour);
  void Disc(double x, double y, double radius, Rgb colour);
  // Copies `src` with its top-left corner at (x, y), clipped to this image.
  void Paste(const Image& src, int x, int y);
  // Fills the rectangle [x0, x1) x [y0, y1).
  void Fill(int x0, int y0, int x1, int y1, Rgb colour);

 private:
  void Blend(int x, int y, Rgb c, double alpha);
  int width_, height_;
  std::vector<uint8_t> rgb_;
};

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_RASTER_H_
