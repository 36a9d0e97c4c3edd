#include "motion/cadence.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_format.h"
#include "motion/kinematics.h"
#include "motion/resample.h"

namespace stylus::motion {

absl::StatusOr<Cadence> FindCadence(const Motion& clip, const HumanoidRoles& roles) {
  const int frames = clip.num_frames;
  const double dt = clip.frame_time;
  const int min_lag = std::max(2, static_cast<int>(std::lround(kMinPeriodS / dt)));
  const int max_lag =
      std::min(static_cast<int>(std::lround(kMaxPeriodS / dt)), (frames - 1) / 2);
  if (max_lag <= min_lag + 1) {
    return absl::NotFoundError(absl::StrFormat(
        "%d frames (%.2f s) are too short to show a repeating motion twice", frames, frames * dt));
  }
  const int up = roles.up_axis;
  // Joint positions relative to the pelvis's floor point, per frame.
  std::vector<std::vector<Vec3>> rel(frames);
  for (int f = 0; f < frames; ++f) {
    const GlobalPose g = ForwardKinematics(clip.skeleton, PoseAt(clip, f));
    Vec3 floor = g.positions[roles.pelvis];
    (up == 0 ? floor.x : up == 1 ? floor.y : floor.z) = 0;
    rel[f].reserve(g.positions.size());
    for (const Vec3& p : g.positions) rel[f].push_back(p - floor);
  }
  std::vector<double> speed(frames - 1, 0);
  for (int f = 0; f + 1 < frames; ++f) {
    for (size_t j = 0; j < rel[f].size(); ++j) speed[f] += Norm(rel[f + 1][j] - rel[f][j]);
  }
  const int n = static_cast<int>(speed.size());
  double mean = 0;
  for (double s : speed) mean += s;
  mean /= n;
  double energy = 0;
  for (double& s : speed) {
    s -= mean;
    energy += s * s;
  }
  if (energy <= 1e-12) return absl::NotFoundError("the clip does not move");
  // The biased estimate: longer lags overlap fewer frames and weigh less,
  // so a multiple of the period does not win by noise.
  std::vector<double> r(max_lag + 2, 0);
  for (int lag = 0; lag <= max_lag + 1 && lag < n; ++lag) {
    double sum = 0;
    for (int t = 0; t + lag < n; ++t) sum += speed[t] * speed[t + lag];
    r[lag] = sum / energy;
  }
  std::vector<int> peaks;
  double best = 0;
  for (int lag = min_lag; lag <= max_lag; ++lag) {
    if (r[lag] >= r[lag - 1] && r[lag] > r[lag + 1]) {
      peaks.push_back(lag);
      best = std::max(best, r[lag]);
    }
  }
  if (peaks.empty() || best < kMinCadenceStrength) {
    return absl::NotFoundError(absl::StrFormat(
        "the motion does not repeat (autocorrelation %.2f at best, %.2f needed)", best,
        kMinCadenceStrength));
  }
  std::sort(peaks.begin(), peaks.end(), [&](int a, int b) { return r[a] > r[b]; });
  // A parabola through each peak and its neighbours.
  auto period_at = [&](int lag) {
    const double a = r[lag - 1], b = r[lag], c = r[lag + 1];
    const double denom = a - 2 * b + c;
    const double shift =
        std::abs(denom) > 1e-12 ? std::clamp(0.5 * (a - c) / denom, -0.5, 0.5) : 0;
    return (lag + shift) * dt;
  };
  Cadence out{period_at(peaks[0]), std::min(1.0, r[peaks[0]]), {}};
  for (int p : peaks) {
    if (r[p] >= 0.5 * best) out.candidates_s.push_back(period_at(p));
  }
  return out;
}

double NearestPeriod(const std::vector<double>& candidates_s, double period_s) {
  double best = candidates_s.empty() ? 0 : candidates_s.front();
  for (double c : candidates_s) {
    if (std::abs(std::log(c / period_s)) < std::abs(std::log(best / period_s)) - 1e-12) best = c;
  }
  return best;
}

Motion TimeWarp(const Motion& clip, double ratio) {
  if (clip.num_frames < 2) return clip;
  Motion stretched = clip;
  stretched.frame_time = clip.frame_time * ratio;
  const int frames = static_cast<int>(std::lround((clip.num_frames - 1) * ratio)) + 1;
  Motion out = Resample(stretched, clip.frame_time, frames);
  out.frame_time = clip.frame_time;
  return out;
}

}  // namespace stylus::motion
