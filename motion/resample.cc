#include "motion/resample.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace stylus::motion {

bool SameRate(double frame_time, double other) {
  return std::fabs(frame_time - other) <= 0.01 * other;
}

absl::Status CheckServedRate(double frame_time, const std::string& what) {
  const double fps = 1.0 / frame_time;
  if (!(fps >= kMinServedFps * 0.999 && fps <= kMaxServedFps * 1.001)) {
    return absl::InvalidArgumentError(absl::StrCat(what, " is at ", fps, " fps; frame rates from ",
                                                   kMinServedFps, " to ", kMaxServedFps,
                                                   " fps are served"));
  }
  return absl::OkStatus();
}

LocalPose BlendPoses(const LocalPose& a, const LocalPose& b, double u) {
  LocalPose out = a;
  for (size_t j = 0; j < a.rotations.size(); ++j) {
    out.translations[j] = a.translations[j] + (b.translations[j] - a.translations[j]) * u;
    out.rotations[j] = Slerp(a.rotations[j], b.rotations[j], u);
  }
  return out;
}

LocalPose PoseAtTime(const Motion& m, double frame) {
  const double t = std::clamp(frame, 0.0, static_cast<double>(m.num_frames - 1));
  const int f0 = static_cast<int>(std::floor(t));
  const double u = t - f0;
  if (u < 1e-9 || f0 + 1 >= m.num_frames) return PoseAt(m, f0);
  return BlendPoses(PoseAt(m, f0), PoseAt(m, f0 + 1), u);
}

Motion Resample(const Motion& m, double frame_time, int frames) {
  if (frames <= 0) {
    const double duration = (m.num_frames - 1) * m.frame_time;
    frames = static_cast<int>(std::floor(duration / frame_time + 1e-6)) + 1;
  }
  Motion out = RestMotion(m.skeleton, frames, frame_time);
  std::vector<Vec3> euler(m.skeleton.num_joints());
  const double ratio = frame_time / m.frame_time;
  for (int k = 0; k < frames; ++k) SetPose(&out, k, PoseAtTime(m, k * ratio), &euler);
  return out;
}

}  // namespace stylus::motion
