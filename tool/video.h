// Pictures that move: clips drawn as stick figures side by side (content,
// style, output), encoded by Debian's ffmpeg as MP4 and/or PNG frames.
//
// Each panel has a fixed camera (three-quarter view, slightly above) that
// follows its clip's pelvis across a ground grid; bones are red on the left,
// blue on the right; a foot joint turns green while planted. Any humanoid
// rig (motion/rig_roles.h), any up axis.
#ifndef STYLUS_TOOL_VIDEO_H_
#define STYLUS_TOOL_VIDEO_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "motion/motion.h"
#include "tool/raster.h"

namespace stylus::tool {

struct VideoPanel {
  std::string title;  // Drawn above the panel ("content", "style", "output").
  motion::Motion clip;
};

struct VideoOptions {
  int width = 960, height = 400;  // The whole picture.
  double fps = 30;                // At most the clips' rate; frames are sampled.
  std::string caption;            // Drawn along the bottom.
  std::string mp4;                // Output paths; either may be empty.
  std::string png_dir;            // DIR/frame_0001.png ...
};

// Every frame of the last panel's clip (the output; the others loop), at
// most options.fps of them per second; writes the
// MP4 and/or PNGs. FAILED_PRECONDITION when ffmpeg is missing or fails.
absl::Status RenderVideo(const std::vector<VideoPanel>& panels, const VideoOptions& options,
                         int* frames_written);

// Text ffmpeg's drawtext puts on a picture (positions are its expressions,
// e.g. "10", "h-th-8"); letters, digits and " ._/,()=+-" only.
struct TextLabel {
  std::string text, x, y;
  int size = 16;
  std::string colour = "0x333333";
};
// The drawtext filters for `labels` (",drawtext=..."; empty without the font).
std::string DrawTextFilter(const std::vector<TextLabel>& labels);
// Pipes `frames` RGB images (frame(k)) to ffmpeg run with `args`.
// FAILED_PRECONDITION when ffmpeg is missing or fails.
absl::Status RunFfmpeg(std::vector<std::string> args, int frames,
                       const std::function<Image(int)>& frame);
// One picture as PNG, with text.
absl::Status WritePng(const Image& image, const std::vector<TextLabel>& labels,
                      const std::string& path);

// One frame of the picture, for tests and for RenderVideo.
class VideoScene {
 public:
  static absl::StatusOr<VideoScene> Create(const std::vector<VideoPanel>& panels, int width,
                                           int height);
  int num_frames() const { return frames_; }
  Image Draw(int frame) const;
  // Whether foot joint k (left ankle, left toe, right ankle, right toe) of
  // panel p is planted in its frame f.
  bool Planted(int p, int f, int k) const;

 private:
  struct Panel;
  std::vector<std::shared_ptr<const Panel>> panels_;
  int width_ = 0, height_ = 0, frames_ = 0;
};

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_VIDEO_H_
