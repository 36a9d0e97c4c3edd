#include "motion/cadence.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/resample.h"

namespace stylus::motion {

namespace {

// The step period from the feet, or nullopt when the clip does not step.
std::optional<Cadence> StepCadence(const std::vector<std::vector<Vec3>>& positions,
                                   const HumanoidRoles& roles, double frame_time) {
  const std::vector<std::array<bool, 4>> contacts =
      DetectFootContacts(positions, roles, 1.0 / frame_time);
  // (frame, foot) of every touchdown, in time order.
  std::vector<std::pair<int, int>> touchdowns;
  for (int foot = 0; foot < 2; ++foot) {
    bool was = contacts.empty() ? false : contacts[0][2 * foot] || contacts[0][2 * foot + 1];
    for (size_t f = 1; f < contacts.size(); ++f) {
      const bool planted = contacts[f][2 * foot] || contacts[f][2 * foot + 1];
      if (planted && !was) touchdowns.push_back({static_cast<int>(f), foot});
      was = planted;
    }
  }
  std::sort(touchdowns.begin(), touchdowns.end());
  std::vector<double> steps;
  for (size_t i = 1; i < touchdowns.size(); ++i) {
    if (touchdowns[i].second == touchdowns[i - 1].second) continue;
    const double s = (touchdowns[i].first - touchdowns[i - 1].first) * frame_time;
    if (s >= kMinPeriodS && s <= kMaxPeriodS) steps.push_back(s);
  }
  if (steps.size() < 2) return std::nullopt;
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double period = sorted[sorted.size() / 2];
  int near = 0;
  for (double s : steps) near += std::abs(s - period) <= 0.15 * period;
  return Cadence{Cadence::Source::kSteps, period, double(near) / steps.size()};
}

}  // namespace

absl::StatusOr<Cadence> FindCadence(const Motion& clip, const HumanoidRoles& roles) {
  return FindCadence(GlobalPositionsYUp(clip, roles.up_axis), clip.frame_time, roles);
}

absl::StatusOr<Cadence> FindCadence(const std::vector<std::vector<Vec3>>& positions,
                                    double frame_time, const HumanoidRoles& roles) {
  const int frames = static_cast<int>(positions.size());
  const double dt = frame_time;
  if (std::optional<Cadence> steps = StepCadence(positions, roles, dt)) return *steps;
  const int min_lag = std::max(2, static_cast<int>(std::lround(kMinPeriodS / dt)));
  const int max_lag = std::min(static_cast<int>(std::lround(kMaxPeriodS / dt)), (frames - 1) / 2);
  if (max_lag <= min_lag + 1) {
    return absl::NotFoundError(absl::StrFormat(
        "%d frames (%.2f s) are too short to show a repeating motion twice", frames, frames * dt));
  }
  // Summed speed of the joints relative to the pelvis's floor point.
  std::vector<double> speed(frames - 1, 0);
  for (int f = 0; f + 1 < frames; ++f) {
    const Vec3 a{positions[f][roles.pelvis].x, 0, positions[f][roles.pelvis].z};
    const Vec3 b{positions[f + 1][roles.pelvis].x, 0, positions[f + 1][roles.pelvis].z};
    for (size_t j = 0; j < positions[f].size(); ++j) {
      speed[f] += Norm((positions[f + 1][j] - b) - (positions[f][j] - a));
    }
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
  std::vector<double> r(max_lag + 2, 0);
  for (int lag = 0; lag <= max_lag + 1 && lag < n; ++lag) {
    double sum = 0;
    for (int t = 0; t + lag < n; ++t) sum += speed[t] * speed[t + lag];
    r[lag] = sum / energy;
  }
  int lag = -1;
  for (int k = min_lag; k <= max_lag; ++k) {
    if (r[k] >= r[k - 1] && r[k] > r[k + 1] && (lag < 0 || r[k] > r[lag])) lag = k;
  }
  if (lag < 0 || r[lag] < kMinCadenceStrength) {
    return absl::NotFoundError(
        absl::StrFormat("it neither steps nor repeats (autocorrelation %.2f at best, %.2f needed)",
                        lag < 0 ? 0.0 : r[lag], kMinCadenceStrength));
  }
  // A parabola through the peak and its neighbours.
  const double a = r[lag - 1], b = r[lag], c = r[lag + 1];
  const double denom = a - 2 * b + c;
  const double shift = std::abs(denom) > 1e-12 ? std::clamp(0.5 * (a - c) / denom, -0.5, 0.5) : 0;
  return Cadence{Cadence::Source::kMotion, (lag + shift) * dt, std::min(1.0, b)};
}

absl::StatusOr<double> TempoRatio(const Cadence& from, const Cadence& to) {
  if (from.source != to.source) {
    return absl::InvalidArgumentError(
        from.source == Cadence::Source::kSteps
            ? "the content steps and the style clip does not: their cadences do not compare"
            : "the style clip steps and the content does not: their cadences do not compare");
  }
  return to.period_s / from.period_s;
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
