// render: a filmstrip of stick figures as SVG, for looking at a clip without a
// 3D package.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "formats/scene_file.h"
#include "motion/bvh.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "tool/cli_support.h"
#include "tool/video.h"

namespace stylus::tool {

namespace {

// render -o OUT.mp4 and/or --png-dir: the video (tool/video.h).
int RenderVideoCommand(const Args& args) {
  std::vector<VideoPanel> panels;
  for (const auto& [flag, title] :
       {std::pair<std::string, std::string>{"content", "content"}, {"style", "style"}}) {
    if (!args.Has(flag)) continue;
    absl::StatusOr<motion::Motion> m = formats::ReadMotionFile(args.Get(flag));
    if (!m.ok()) return Fail("render", m.status());
    panels.push_back({title, *std::move(m)});
  }
  absl::StatusOr<motion::Motion> clip = formats::ReadMotionFile(args.positional[0]);
  if (!clip.ok()) return Fail("render", clip.status());
  // The clip itself last: the video runs for its frames; the others loop.
  panels.push_back({panels.empty() ? "clip" : "output", *std::move(clip)});
  VideoOptions o;
  o.caption = args.Get("caption");
  o.png_dir = args.Get("png-dir");
  if (absl::EndsWith(args.Get("out"), ".mp4")) o.mp4 = args.Get("out");
  const std::string size = args.Get("size", absl::StrCat(320 * panels.size(), "x400"));
  if (std::sscanf(size.c_str(), "%dx%d", &o.width, &o.height) != 2) {
    return Fail("render", absl::InvalidArgumentError("--size must be WIDTHxHEIGHT, e.g. 960x400"));
  }
  absl::StatusOr<int> fps = args.GetInt("fps", 30);
  if (!fps.ok() || *fps < 1 || *fps > 120) {
    return Fail("render", absl::InvalidArgumentError("--fps must be from 1 to 120"));
  }
  o.fps = *fps;
  int written = 0;
  if (absl::Status s = RenderVideo(panels, o, &written); !s.ok()) return Fail("render", s);
  std::string what = o.mp4;
  if (!o.png_dir.empty())
    absl::StrAppend(&what, what.empty() ? "" : " and ", o.png_dir, "/frame_*.png");
  absl::PrintF("wrote %s (%d frames, %.2f s, %dx%d", what, written, written / o.fps, o.width,
               o.height);
  if (!o.mp4.empty()) {
    std::error_code ec;
    absl::PrintF(", %.0f kB", std::filesystem::file_size(o.mp4, ec) / 1024.0);
  }
  absl::PrintF(")\n");
  return 0;
}

}  // namespace

int Render(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool render FILE -o OUT.svg [--frames N] [--view side|front|top]\n"
      "       stylus-tool render FILE -o OUT.mp4 [--content C.bvh] [--style S.bvh]\n"
      "                         [--caption TEXT] [--png-dir DIR] [--size WxH] [--fps N]\n\n"
      "SVG: N evenly spaced frames (default 8) of a BVH clip as stick figures side\n"
      "by side, seen from the side (x = forward along Z), front or top, each frame\n"
      "centred on its root, with the floor line and the frame number.\n\n"
      "MP4 (Debian's ffmpeg) and/or PNG frames (--png-dir DIR, alone or with an\n"
      "MP4): the clip moving, with --content and --style drawn beside it (content,\n"
      "style, output; the others loop to the clip's length). Each panel has a fixed\n"
      "three-quarter camera that follows its pelvis over a ground grid; left bones\n"
      "red, right blue; feet green while planted. Any humanoid rig, any up axis.\n"
      "--caption TEXT runs along the bottom (e.g. the model and style). --size\n"
      "defaults to 320 pixels wide per panel by 400; --fps to 30 (at most the\n"
      "clip's rate). FILE and the panels may be BVH, FBX, glTF or COLLADA files.\n";
  int code = 0;
  auto args = ParseOrExit(
      "render", argv,
      {{"out", "frames", "view", "content", "style", "caption", "png-dir", "size", "fps"}, {}},
      kHelp, &code);
  if (!args) return code;
  const bool video = absl::EndsWith(args->Get("out"), ".mp4") || args->Has("png-dir");
  if (args->positional.size() != 1 || (!args->Has("out") && !video)) {
    std::fprintf(stderr, "stylus-tool render: expected FILE and -o OUT.svg|OUT.mp4\n\n%s", kHelp);
    return 2;
  }
  if (video) return RenderVideoCommand(*args);
  absl::StatusOr<int> frames = args->GetInt("frames", 8);
  if (!frames.ok() || *frames <= 0 || *frames > 200) {
    return Fail("render", absl::InvalidArgumentError("--frames must be from 1 to 200"));
  }
  const std::string view = args->Get("view", "side");
  int hx = 2, vy = 1;  // Horizontal and vertical axes of the drawing.
  if (view == "front") {
    hx = 0;
  } else if (view == "top") {
    hx = 0, vy = 2;
  } else if (view != "side") {
    return Fail("render", absl::InvalidArgumentError("--view must be side, front or top"));
  }
  absl::StatusOr<motion::Motion> m = formats::ReadMotionFile(args->positional[0]);
  if (!m.ok()) return Fail("render", m.status());
  const auto positions = motion::GlobalPositions(*m);
  // Centre on the pelvis and leave out the joints above it (often a static
  // "root" at the origin); a non-humanoid rig is drawn whole about its root.
  absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(m->skeleton);
  const int center = roles.ok() ? roles->pelvis : 0;
  std::vector<bool> hidden(m->skeleton.num_joints(), false);
  for (int j = m->skeleton.joint(center).parent; j >= 0; j = m->skeleton.joint(j).parent)
    hidden[j] = true;
  double extent = 1;  // Half-size of a cell: the largest spread about the centre joint.
  for (const auto& frame : positions) {
    for (int j = 0; j < static_cast<int>(frame.size()); ++j) {
      if (hidden[j]) continue;
      const motion::Vec3& p = frame[j];
      extent = std::max({extent, std::fabs(p[hx] - frame[center][hx]),
                         vy == 1 ? p.y / 2 : std::fabs(p[vy] - frame[center][vy])});
    }
  }
  const double cell = 160, scale = cell / (2.4 * extent);
  const int n = std::min(*frames, m->num_frames);
  std::string svg = absl::StrFormat(
      "<svg xmlns='http://www.w3.org/2000/svg' width='%d' height='%d' font-family='sans-serif' "
      "font-size='11'>\n<rect width='100%%' height='100%%' fill='white'/>\n",
      static_cast<int>(cell * n), static_cast<int>(cell + 20));
  for (int i = 0; i < n; ++i) {
    const int f = n == 1 ? 0 : static_cast<int>(std::lround(i * (m->num_frames - 1.0) / (n - 1)));
    const auto& p = positions[f];
    const double ox = cell * i + cell / 2 - p[center][hx] * scale;
    const double oy = vy == 1 ? cell - 10 : cell / 2 + p[center][vy] * scale;
    auto X = [&](const motion::Vec3& v) { return ox + v[hx] * scale; };
    auto Y = [&](const motion::Vec3& v) { return oy - v[vy] * scale; };
    if (vy == 1) {
      absl::StrAppendFormat(&svg, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#bbb'/>\n",
                            cell * i + 5, oy, cell * (i + 1) - 5, oy);
    }
    for (int j = 1; j < m->skeleton.num_joints(); ++j) {
      const int parent = m->skeleton.joint(j).parent;
      if (hidden[parent]) continue;
      const std::string& name = m->skeleton.joint(j).name;
      const bool left = absl::EndsWith(name, "_L") || absl::StartsWith(name, "Left");
      const bool right = absl::EndsWith(name, "_R") || absl::StartsWith(name, "Right");
      const char* colour = left ? "#c33" : (right ? "#33c" : "#333");  // Left red, right blue.
      absl::StrAppendFormat(
          &svg, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='%s' stroke-width='2'/>\n",
          X(p[parent]), Y(p[parent]), X(p[j]), Y(p[j]), colour);
    }
    absl::StrAppendFormat(&svg, "<text x='%.1f' y='%.1f'>frame %d</text>\n", cell * i + 5,
                          cell + 15, f);
  }
  svg += "</svg>\n";
  std::ofstream out(args->Get("out"));
  out << svg;
  if (!out) return Fail("render", absl::InternalError(args->Get("out") + ": write failed"));
  absl::PrintF("wrote %s (%d frames, %s view)\n", args->Get("out"), n, view);
  return 0;
}

}  // namespace stylus::tool
