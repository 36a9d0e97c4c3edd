#include "tool/video.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/postprocess.h"
#include "motion/rig_roles.h"

namespace stylus::tool {
namespace {

constexpr char kFont[] = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr double kAzimuth = 0.6;     // Radians off the side view.
constexpr double kElevation = 0.25;  // Radians above the horizon.
constexpr Rgb kBackground{250, 250, 247}, kGrid{214, 214, 208}, kLeft{200, 50, 50},
    kRight{50, 70, 200}, kCentre{50, 50, 50}, kPlanted{30, 170, 60}, kLifted{150, 150, 150};

// Letters, digits and a few signs: what ffmpeg's drawtext gets without escaping.
std::string SafeText(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) ||
                    std::string(" ._/,()=+-").find(c) != std::string::npos;
    out += ok ? c : ' ';
  }
  return out;
}

}  // namespace

absl::Status RunFfmpeg(std::vector<std::string> args, int frames,
                       const std::function<Image(int)>& frame) {
  int pipe_fd[2];
  if (pipe(pipe_fd) != 0) return absl::InternalError("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) return absl::InternalError("fork failed");
  if (pid == 0) {
    dup2(pipe_fd[0], 0);
    close(pipe_fd[0]);
    close(pipe_fd[1]);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp("ffmpeg", argv.data());
    std::fprintf(stderr, "cannot run ffmpeg: install Debian's ffmpeg (apt-get install ffmpeg)\n");
    _exit(127);
  }
  close(pipe_fd[0]);
  std::signal(SIGPIPE, SIG_IGN);
  bool write_failed = false;
  for (int k = 0; k < frames && !write_failed; ++k) {
    const Image image = frame(k);
    const std::vector<uint8_t>& bytes = image.bytes();
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = write(pipe_fd[1], bytes.data() + done, bytes.size() - done);
      if (n <= 0) {
        write_failed = true;
        break;
      }
      done += static_cast<size_t>(n);
    }
  }
  close(pipe_fd[1]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || write_failed) {
    return absl::FailedPreconditionError(absl::StrCat(
        "ffmpeg failed (exit ", WIFEXITED(status) ? WEXITSTATUS(status) : -1,
        WIFEXITED(status) && WEXITSTATUS(status) == 127 ? ": not installed" : "", ")"));
  }
  return absl::OkStatus();
}

std::string DrawTextFilter(const std::vector<TextLabel>& labels) {
  std::string filter;
  if (!std::filesystem::exists(kFont)) return filter;
  for (const TextLabel& l : labels) {
    absl::StrAppendFormat(&filter,
                          ",drawtext=fontfile=%s:text='%s':x=%s:y=%s:fontsize=%d:fontcolor=%s",
                          kFont, SafeText(l.text), l.x, l.y, l.size, l.colour);
  }
  return filter;
}

absl::Status WritePng(const Image& image, const std::vector<TextLabel>& labels,
                      const std::string& path) {
  std::vector<std::string> args = {"ffmpeg",    "-loglevel",
                                   "error",     "-y",
                                   "-f",        "rawvideo",
                                   "-pix_fmt",  "rgb24",
                                   "-s",        absl::StrCat(image.width(), "x", image.height()),
                                   "-i",        "-",
                                   "-vf",       "format=rgb24" + DrawTextFilter(labels),
                                   "-frames:v", "1",
                                   "-update",   "1",
                                   path};
  return RunFfmpeg(args, 1, [&image](int) { return image; });
}

struct VideoScene::Panel {
  std::string title;
  int frames = 0;
  std::vector<std::vector<motion::Vec3>> positions;  // Y up, in leg lengths.
  std::vector<int> parent;
  std::vector<Rgb> colour;
  std::vector<bool> hidden;
  std::array<int, 4> feet{};
  std::vector<std::array<bool, 4>> planted;
  std::vector<motion::Vec3> target;  // Smoothed pelvis on the floor: the camera follows it.
};

absl::StatusOr<VideoScene> VideoScene::Create(const std::vector<VideoPanel>& panels, int width,
                                              int height) {
  if (panels.empty()) return absl::InvalidArgumentError("no clip to draw");
  if (width < 64 || height < 64 || width > 7680 || height > 4320 || width % 2 || height % 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture size ", width, "x", height, ": even numbers from 64 to 7680x4320"));
  }
  VideoScene scene;
  scene.width_ = width;
  scene.height_ = height;
  for (const VideoPanel& vp : panels) {
    const motion::Motion& m = vp.clip;
    if (m.num_frames == 0) return absl::InvalidArgumentError(vp.title + ": no frames");
    const motion::Skeleton& sk = m.skeleton;
    const auto world = motion::ForwardKinematics(sk, motion::PoseAt(m, 0));
    absl::StatusOr<motion::RigRoles> roles = motion::FindRigRoles(sk, world);
    if (!roles.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(vp.title, ": ", roles.status().message()));
    }
    absl::StatusOr<motion::HumanoidRoles> humanoid = motion::HumanoidRolesOf(m);
    if (!humanoid.ok()) return humanoid.status();
    auto p = std::make_shared<Panel>();
    p->title = vp.title;
    p->frames = m.num_frames;
    const motion::Quat up_turn = motion::RotationBetween(roles->up, {0, 1, 0});
    const double leg = std::max(motion::LegLength(sk, *roles), 1e-9);
    std::vector<std::vector<motion::Vec3>> y_up = motion::GlobalPositions(m);
    for (auto& frame : y_up) {
      for (auto& v : frame) v = motion::Rotate(up_turn, v);
    }
    const auto spans = motion::DetectContactSpans(y_up, *humanoid, m.fps());
    p->feet = motion::FootJoints(*humanoid);
    p->planted.assign(m.num_frames, {});
    for (int k = 0; k < 4; ++k) {
      for (const motion::ContactSpan& s : spans[k]) {
        for (int f = s.begin; f < s.end; ++f) p->planted[f][k] = true;
      }
    }
    p->positions = y_up;
    for (auto& frame : p->positions) {
      for (auto& v : frame) v = (1.0 / leg) * v;
    }
    const int n = sk.num_joints(), pelvis = (*roles)[motion::Role::kPelvis];
    p->parent.resize(n);
    p->hidden.assign(n, false);
    for (int j = sk.joint(pelvis).parent; j >= 0; j = sk.joint(j).parent) p->hidden[j] = true;
    p->colour.assign(n, kCentre);
    const std::pair<motion::Role, Rgb> sides[] = {
        {motion::Role::kLeftThigh, kLeft},      {motion::Role::kLeftUpperArm, kLeft},
        {motion::Role::kLeftClavicle, kLeft},   {motion::Role::kRightThigh, kRight},
        {motion::Role::kRightUpperArm, kRight}, {motion::Role::kRightClavicle, kRight}};
    for (int j = 0; j < n; ++j) {
      p->parent[j] = sk.joint(j).parent;
      for (int a = j; a >= 0; a = sk.joint(a).parent) {
        bool found = false;
        for (const auto& [role, c] : sides) {
          if (roles->has(role) && (*roles)[role] == a) p->colour[j] = c, found = true;
        }
        if (found) break;
      }
    }
    // The camera follows the pelvis on the floor, smoothed over +-0.5 s.
    const int half = std::max(1, static_cast<int>(std::lround(0.5 * m.fps())));
    for (int f = 0; f < m.num_frames; ++f) {
      motion::Vec3 sum;
      int count = 0;
      for (int g = std::max(0, f - half); g <= std::min(m.num_frames - 1, f + half); ++g, ++count) {
        sum = sum + p->positions[g][pelvis];
      }
      motion::Vec3 t = (1.0 / count) * sum;
      t.y = 0;
      p->target.push_back(t);
    }
    scene.panels_.push_back(std::move(p));
  }
  scene.frames_ = scene.panels_.back()->frames;
  return scene;
}

bool VideoScene::Planted(int p, int f, int k) const { return panels_[p]->planted[f][k]; }

Image VideoScene::Draw(int frame) const {
  Image image(width_, height_, kBackground);
  const int count = static_cast<int>(panels_.size());
  const int panel_w = width_ / count;
  const double scale = height_ / 3.2;  // Pixels per leg length.
  const double ca = std::cos(kAzimuth), sa = std::sin(kAzimuth);
  const double ce = std::cos(kElevation), se = std::sin(kElevation);
  for (int i = 0; i < count; ++i) {
    const Panel& p = *panels_[i];
    const int f = frame % p.frames;
    Image cell(panel_w, height_, kBackground);
    const motion::Vec3 target = p.target[f];
    const double cx = panel_w / 2.0, cy = height_ * 0.78;
    auto project = [&](const motion::Vec3& w, double* x, double* y) {
      const motion::Vec3 d = w - target;
      const double across = d.x * ca - d.z * sa, depth = d.x * sa + d.z * ca;
      *x = cx + scale * across;
      *y = cy - scale * (d.y * ce - depth * se);
    };
    // Ground grid: lines every half leg length around the camera's target.
    const double step = 0.5;
    const double gx0 = std::floor(target.x / step) * step, gz0 = std::floor(target.z / step) * step;
    for (int k = -8; k <= 8; ++k) {
      double x0, y0, x1, y1;
      project({gx0 + k * step, 0, gz0 - 4}, &x0, &y0);
      project({gx0 + k * step, 0, gz0 + 4}, &x1, &y1);
      cell.Line(x0, y0, x1, y1, 1, kGrid);
      project({gx0 - 4, 0, gz0 + k * step}, &x0, &y0);
      project({gx0 + 4, 0, gz0 + k * step}, &x1, &y1);
      cell.Line(x0, y0, x1, y1, 1, kGrid);
    }
    const auto& pos = p.positions[f];
    for (size_t j = 0; j < pos.size(); ++j) {
      const int parent = p.parent[j];
      if (parent < 0 || p.hidden[parent] || p.hidden[j]) continue;
      double x0, y0, x1, y1;
      project(pos[parent], &x0, &y0);
      project(pos[j], &x1, &y1);
      cell.Line(x0, y0, x1, y1, std::max(2.0, height_ / 130.0), p.colour[j]);
    }
    for (int k = 0; k < 4; ++k) {
      double x, y;
      project(pos[p.feet[k]], &x, &y);
      const bool down = p.planted[f][k];
      cell.Disc(x, y, (down ? 1.0 : 0.6) * std::max(3.0, height_ / 80.0),
                down ? kPlanted : kLifted);
    }
    // Into the picture, with a thin separator.
    image.Paste(cell, i * panel_w, 0);
    if (i > 0) image.Fill(i * panel_w, 0, i * panel_w + 1, height_, kGrid);
  }
  return image;
}

absl::Status RenderVideo(const std::vector<VideoPanel>& panels, const VideoOptions& options,
                         int* frames_written) {
  absl::StatusOr<VideoScene> scene = VideoScene::Create(panels, options.width, options.height);
  if (!scene.ok()) return scene.status();
  if (options.mp4.empty() && options.png_dir.empty()) {
    return absl::InvalidArgumentError("nothing to write: give an MP4 path or a PNG directory");
  }
  // Sample the last clip at the video's rate.
  const double clip_fps = panels.back().clip.fps();
  // A clip at (nearly) the video's rate keeps every frame.
  const double fps = options.fps >= clip_fps * (1 - 1e-3) ? clip_fps : options.fps;
  const int out_frames = std::max(
      1, static_cast<int>(std::floor((scene->num_frames() - 1) * fps / clip_fps + 1e-6)) + 1);
  // drawtext: the panel titles and the caption.
  std::vector<TextLabel> labels;
  const int panel_w = options.width / static_cast<int>(panels.size());
  const int size = std::max(10, options.height / 22);
  for (size_t i = 0; i < panels.size(); ++i) {
    labels.push_back(
        {panels[i].title, absl::StrCat(static_cast<int>(i) * panel_w + 10), "8", size});
  }
  if (!options.caption.empty()) {
    labels.push_back({options.caption, "10", "h-th-8", size * 4 / 5, "0x555555"});
  }
  const std::string filter = "format=rgb24" + DrawTextFilter(labels);
  std::vector<std::string> args = {"ffmpeg",   "-loglevel",
                                   "error",    "-y",
                                   "-f",       "rawvideo",
                                   "-pix_fmt", "rgb24",
                                   "-s",       absl::StrCat(options.width, "x", options.height),
                                   "-r",       absl::StrFormat("%.6g", fps),
                                   "-i",       "-"};
  if (!options.mp4.empty()) {
    for (const char* a : {"-map", "0"}) args.push_back(a);
    args.insert(args.end(), {"-vf", filter + ",format=yuv420p", "-c:v", "libx264", "-preset",
                             "medium", "-crf", "23", "-movflags", "+faststart", options.mp4});
  }
  if (!options.png_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.png_dir, ec);
    if (ec) return absl::PermissionDeniedError(options.png_dir + ": " + ec.message());
    args.insert(args.end(), {"-map", "0", "-vf", filter, options.png_dir + "/frame_%04d.png"});
  }
  absl::Status run = RunFfmpeg(args, out_frames, [&](int k) {
    const int f =
        std::min(scene->num_frames() - 1, static_cast<int>(std::lround(k * clip_fps / fps)));
    return scene->Draw(f);
  });
  if (!run.ok()) return run;
  *frames_written = out_frames;
  return absl::OkStatus();
}

}  // namespace stylus::tool
