#include "motion/example_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "motion/cadence.h"
#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/splice.h"

namespace stylus::motion {
namespace {

// Gaussian smoothing over time. Past the clip's ends the signal is
// continued by point reflection about its end values (x[-k] = 2 x[0] - x[k]),
// so a path keeps its trend to the last frame instead of stopping short;
// with `trend` false the window is cut there instead (weights renormalized).
template <typename T>
std::vector<T> Smooth(const std::vector<T>& x, double sigma_frames, T zero, bool trend = true) {
  const int n = static_cast<int>(x.size());
  if (sigma_frames <= 0 || n < 2) return x;
  const int r = std::max(1, static_cast<int>(std::ceil(3 * sigma_frames)));
  std::vector<double> w(r + 1);
  for (int k = 0; k <= r; ++k) w[k] = std::exp(-0.5 * k * k / (sigma_frames * sigma_frames));
  auto at = [&](int g) -> T {
    if (g < 0) return x[0] * 2.0 - x[std::min(n - 1, -g)];
    if (g >= n) return x[n - 1] * 2.0 - x[std::max(0, 2 * (n - 1) - g)];
    return x[g];
  };
  std::vector<T> out(n, zero);
  for (int f = 0; f < n; ++f) {
    T sum = zero;
    double total = 0;
    for (int k = -r; k <= r; ++k) {
      const int g = f + k;
      if (!trend && (g < 0 || g >= n)) continue;
      sum = sum + at(g) * w[std::abs(k)];
      total += w[std::abs(k)];
    }
    out[f] = sum * (1.0 / total);
  }
  return out;
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// The example sampled at a fractional frame.
struct Sample {
  int i0, i1;
  double a;
};
Sample At(double t, int m) {
  t = std::clamp(t, 0.0, static_cast<double>(m - 1));
  const int i0 = std::min(m - 1, static_cast<int>(std::floor(t)));
  return {i0, std::min(m - 1, i0 + 1), t - i0};
}
Vec3 Lerp(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }
Quat SlerpShort(const Quat& a, const Quat& b, double t) {
  return Slerp(a, SameHemisphere(b, a), t);
}

// Each joint's local rotation smoothed over time (quaternions kept on one
// hemisphere, renormalized): a clip's posture without its movement.
std::vector<std::vector<Quat>> Posture(const std::vector<LocalPose>& poses, double sigma_frames) {
  const int n = static_cast<int>(poses.size());
  if (n == 0) return {};
  const int joints = static_cast<int>(poses[0].rotations.size());
  std::vector<std::vector<Quat>> out(n, std::vector<Quat>(joints));
  for (int j = 0; j < joints; ++j) {
    std::vector<Vec3> xyz(n);
    std::vector<double> w(n);
    Quat prev = poses[0].rotations[j];
    for (int f = 0; f < n; ++f) {
      const Quat q = SameHemisphere(poses[f].rotations[j], prev);
      prev = q;
      xyz[f] = {q.x, q.y, q.z};
      w[f] = q.w;
    }
    const std::vector<Vec3> sx = Smooth(xyz, sigma_frames, Vec3{}, false);
    const std::vector<double> sw = Smooth(w, sigma_frames, 0.0, false);
    for (int f = 0; f < n; ++f) out[f][j] = Normalized(Quat{sw[f], sx[f].x, sx[f].y, sx[f].z});
  }
  return out;
}

}  // namespace

absl::StatusOr<PartSource> ParsePartSource(absl::string_view name) {
  if (name == "network") return PartSource::kNetwork;
  if (name == "example") return PartSource::kExample;
  if (name == "layer") return PartSource::kLayer;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown part source '", name, "': use network, example or layer"));
}

const char* PartSourceName(PartSource source) {
  switch (source) {
    case PartSource::kNetwork:
      return "network";
    case PartSource::kExample:
      return "example";
    case PartSource::kLayer:
      return "layer";
  }
  return "network";
}

std::array<std::vector<ContactSpan>, 4> SpansFromFlags(
    const std::array<std::vector<bool>, 4>& flags, int min_frames) {
  std::array<std::vector<ContactSpan>, 4> spans;
  for (int k = 0; k < 4; ++k) {
    const int n = static_cast<int>(flags[k].size());
    int begin = -1;
    for (int f = 0; f <= n; ++f) {
      const bool on = f < n && flags[k][f];
      if (on && begin < 0) begin = f;
      if (!on && begin >= 0) {
        if (f - begin >= min_frames) spans[k].push_back({begin, f});
        begin = -1;
      }
    }
  }
  return spans;
}

size_t MovementClipBytes(const MovementClip& m) {
  size_t n = sizeof(MovementClip) + m.clip.values.size() * sizeof(double);
  for (const LocalPose& p : m.poses)
    n += p.rotations.size() * sizeof(Quat) + p.translations.size() * sizeof(Vec3);
  for (const auto& p : m.positions) n += p.size() * sizeof(Vec3);
  for (const auto& v : m.shape) n += v.size() * sizeof(double);
  for (const auto& v : m.gait) n += v.size() * sizeof(double);
  n += m.heading.size() * (2 * sizeof(double) + sizeof(Vec3) + sizeof(Quat));
  for (const auto& c : m.contact) n += c.size() / 8;
  return n;
}

absl::StatusOr<MovementClip> AnalyzeMovement(const Motion& clip, const HumanoidRoles& roles) {
  const int n = clip.num_frames;
  if (n < 2) return absl::InvalidArgumentError("movement: the clip has fewer than 2 frames");
  if (roles.up_axis != 1) {
    return absl::InvalidArgumentError("movement: the clip's rig is not Y up");
  }
  const Skeleton& sk = clip.skeleton;
  MovementClip m;
  m.clip = clip;
  m.roles = roles;
  const double fps = clip.fps(), leg = std::max(roles.leg_length, 1e-9);
  for (int side = 0; side < 2; ++side) {
    const int upper = side == 0 ? roles.left_shoulder : roles.right_shoulder;
    const int fore = MainChild(sk, upper);
    const int hand = fore < 0 ? -1 : MainChild(sk, fore);
    if (hand < 0) {
      return absl::InvalidArgumentError(absl::StrCat("movement: the arm at '", sk.joint(upper).name,
                                                     "' has no forearm and hand below it"));
    }
    m.arms[side] = {upper, fore, hand};
  }
  m.poses.resize(n);
  m.positions.resize(n);
  m.pelvis_rotation.resize(n);
  for (int f = 0; f < n; ++f) {
    m.poses[f] = PoseAt(clip, f);
    GlobalPose g = ForwardKinematics(sk, m.poses[f]);
    m.positions[f] = std::move(g.positions);
    m.pelvis_rotation[f] = g.rotations[roles.pelvis];
  }
  // Facing: the hip and shoulder lines turned a quarter about the vertical.
  std::vector<double> yaw(n);
  for (int f = 0; f < n; ++f) {
    const std::vector<Vec3>& p = m.positions[f];
    const Vec3 across = (p[roles.left_hip] - p[roles.right_hip]) +
                        (p[roles.left_shoulder] - p[roles.right_shoulder]);
    const Vec3 ahead = Cross(across, Vec3{0, 1, 0});
    yaw[f] = std::atan2(ahead.x, ahead.z);
    if (f > 0) {  // Unwrapped.
      while (yaw[f] - yaw[f - 1] > M_PI) yaw[f] -= 2 * M_PI;
      while (yaw[f] - yaw[f - 1] < -M_PI) yaw[f] += 2 * M_PI;
    }
  }
  m.heading = Smooth(yaw, 0.25 * fps, 0.0);
  std::vector<Vec3> floor(n);
  for (int f = 0; f < n; ++f) floor[f] = OnFloor(m.positions[f][roles.pelvis]);
  m.floor_path = Smooth(floor, 0.5 * fps, Vec3{});
  m.speed.resize(n);
  for (int f = 0; f < n; ++f) {
    const int a = std::max(0, f - 1), b = std::min(n - 1, f + 1);
    m.speed[f] = Norm(m.floor_path[b] - m.floor_path[a]) * fps / (b - a) / leg;
  }
  const std::array<std::vector<ContactSpan>, 4> spans = DetectContactSpans(m.positions, roles, fps);
  for (int k = 0; k < 4; ++k) {
    m.contact[k].assign(n, false);
    for (const ContactSpan& s : spans[k]) {
      for (int f = s.begin; f < s.end; ++f) m.contact[k][f] = true;
    }
  }
  const std::array<int, 4> feet = FootJoints(roles);
  std::vector<double> lowest(n);
  for (int f = 0; f < n; ++f) {
    lowest[f] = 1e300;
    for (int j : feet) lowest[f] = std::min(lowest[f], m.positions[f][j].y);
  }
  m.floor_height = *std::min_element(lowest.begin(), lowest.end());

  const int knees[2] = {sk.joint(roles.left_ankle).parent, sk.joint(roles.right_ankle).parent};
  const int gait_joints[6] = {knees[0],          knees[1],       roles.left_ankle,
                              roles.right_ankle, roles.left_toe, roles.right_toe};
  std::vector<std::vector<double>> gait_pos(n);
  m.shape.resize(n);
  for (int f = 0; f < n; ++f) {
    const std::vector<Vec3>& p = m.positions[f];
    auto rel = [&](int j) { return InFacing(p[j] - m.floor_path[f], m.heading[f]) * (1 / leg); };
    for (int j : gait_joints) {
      const Vec3 v = rel(j);
      gait_pos[f].insert(gait_pos[f].end(), {v.x, v.y, v.z});
    }
    gait_pos[f].push_back((p[roles.pelvis].y - m.floor_height) / leg);
    for (int side = 0; side < 2; ++side) {
      for (int j : {m.arms[side][1], m.arms[side][2]}) {
        const Vec3 v = rel(j);
        m.shape[f].insert(m.shape[f].end(), {v.x, v.y, v.z});
      }
    }
    for (int j : {roles.left_ankle, roles.right_ankle}) {
      const Vec3 v = rel(j);
      m.shape[f].insert(m.shape[f].end(), {v.x, v.y, v.z});
    }
  }
  // What the arms do: each hand's reach (vertical travel over the pelvis)
  // and its swings (turns of its sideways or vertical path by kSwing or more).
  for (int side = 0; side < 2; ++side) {
    std::vector<double> height(n), across(n);
    for (int f = 0; f < n; ++f) {
      across[f] = m.shape[f][side * 6 + 3];
      height[f] = m.shape[f][side * 6 + 4];
    }
    m.hand_reach[side] = Percentile(height, 0.95) - Percentile(height, 0.05);
    int swings = 0;
    for (const std::vector<double>* path : {&across, &height})
      swings = std::max(swings, CountSwings(Smooth(*path, 0.05 * fps, 0.0)));
    m.hand_swings[side] = swings;
  }
  {
    std::vector<double> fastest(n, 0);
    for (int f = 0; f + 1 < n; ++f) {
      for (int side = 0; side < 2; ++side) {
        double d2 = 0;
        for (int c = 3; c < 6; ++c) {
          const double d = m.shape[f + 1][side * 6 + c] - m.shape[f][side * 6 + c];
          d2 += d * d;
        }
        fastest[f] = std::max(fastest[f], std::sqrt(d2) * fps);
      }
    }
    m.hand_speed = Percentile(fastest, 0.95);
  }
  const int lag = std::max(1, static_cast<int>(std::lround(0.2 * fps)));
  // The hands' velocities: the first 6 values of a frame's shape.
  std::vector<std::vector<double>> hands(n);
  for (int f = 0; f < n; ++f)
    hands[f] = {m.shape[f][3], m.shape[f][4],  m.shape[f][5],
                m.shape[f][9], m.shape[f][10], m.shape[f][11]};
  for (int f = 0; f < n; ++f) {
    const int a = std::max(0, f - lag / 2), b = std::min(n - 1, a + lag);
    for (size_t c = 0; c < 6; ++c) {
      m.shape[f].push_back(b > a ? (hands[b][c] - hands[a][c]) * lag / (b - a) : 0.0);
    }
  }
  m.gait.resize(n);
  for (int f = 0; f < n; ++f) {
    const int a = std::max(0, f - lag / 2), b = std::min(n - 1, a + lag);
    m.gait[f] = gait_pos[f];
    for (size_t c = 0; c < gait_pos[f].size(); ++c) {
      m.gait[f].push_back(b > a ? (gait_pos[b][c] - gait_pos[a][c]) * lag / (b - a) : 0.0);
    }
  }

  // Stepping: the clip steps, and its stepping part is where it travels at
  // half its brisk speed or more.
  absl::StatusOr<Cadence> cadence = FindCadence(m.positions, clip.frame_time, roles);
  const double brisk = Percentile(m.speed, 0.9);
  int s0 = n, s1 = 0;
  for (int f = 0; f < n; ++f) {
    if (m.speed[f] >= 0.5 * brisk) s0 = std::min(s0, f), s1 = std::max(s1, f + 1);
  }
  m.steps =
      cadence.ok() && cadence->source == Cadence::Source::kSteps && brisk > 0.15 && s1 - s0 >= 2;
  m.loop_begin = 0;
  m.loop_end = n - 1;
  if (!m.steps) return m;
  m.step_period_s = cadence->period_s;
  std::vector<double> part(m.speed.begin() + s0, m.speed.begin() + s1);
  m.step_speed = Percentile(part, 0.5);
  double turn = 0;
  Vec3 travel;
  for (int f = s0 + 1; f < s1; ++f) {
    turn += (m.heading[f] - m.heading[f - 1]) * fps;
    travel = travel + InFacing(m.floor_path[f] - m.floor_path[f - 1], m.heading[f]);
  }
  m.turn_rate = turn / std::max(1, s1 - s0 - 1);
  int airborne = 0;
  for (int f = s0; f < s1; ++f) {
    bool down = false;
    for (int k = 0; k < 4; ++k) down = down || m.contact[k][f];
    airborne += !down;
  }
  m.flight = static_cast<double>(airborne) / (s1 - s0);
  m.travel = Normalized(Vec3{travel.x, 0, travel.z}, {0, 0, 1});
  // The loop: two frames of the stepping part at least a stride (two steps,
  // less a fifth) and at most kMaxLoopS apart that look and move most alike;
  // of the near-best pairs, the farthest apart (more of the take is played).
  // Two passes over the pairs, none stored: time grows with the clip's
  // length times the longest loop, memory not at all.
  const int period = std::max(2, static_cast<int>(std::lround(m.step_period_s * fps)));
  const int min_len = std::max(2, static_cast<int>(std::lround(1.6 * period)));
  const int max_len = std::max(min_len, static_cast<int>(std::lround(kMaxLoopS * fps)));
  m.loop_begin = s0;
  m.loop_end = s1 - 1;
  if (s1 - 1 - s0 < min_len) return m;
  double best = std::numeric_limits<double>::infinity();
  for (int a = s0; a < s1; ++a) {
    for (int b = a + min_len; b < std::min(s1, a + max_len + 1); ++b) {
      best = std::min(best, SquaredDistance(m.gait[a], m.gait[b]));
    }
  }
  int longest = -1;
  for (int a = s0; a < s1; ++a) {
    for (int b = a + min_len; b < std::min(s1, a + max_len + 1); ++b) {
      if (b - a > longest && SquaredDistance(m.gait[a], m.gait[b]) <= 1.25 * best + 1e-9) {
        longest = b - a;
        m.loop_begin = a;
        m.loop_end = b;
      }
    }
  }
  return m;
}

bool HandTravels(const std::array<double, 2>& reach, int side) {
  return reach[side] >= kActiveReach ||
         (reach[side] >= kActiveReach / 3 && reach[side] >= 0.5 * reach[1 - side]);
}

int CountSwings(const std::vector<double>& path) {
  // A turn counts once the path has come back kSwing from its extreme.
  if (path.empty()) return 0;
  double hi = path[0], lo = path[0];
  int dir = 0, turns = 0;
  for (double v : path) {
    hi = std::max(hi, v);
    lo = std::min(lo, v);
    if (dir >= 0 && v < hi - kSwing) {
      turns += dir > 0;
      dir = -1;
      lo = v;
    } else if (dir <= 0 && v > lo + kSwing) {
      turns += dir < 0;
      dir = 1;
      hi = v;
    }
  }
  return turns;
}

bool SameArmAction(const MovementClip& a, const MovementClip& b, std::string* why) {
  auto active = [](const MovementClip& c, int side) { return HandTravels(c.hand_reach, side); };
  static const char* kSide[2] = {"left", "right"};
  for (int side = 0; side < 2; ++side) {
    if (active(a, side) != active(b, side)) {
      if (why)
        *why = absl::StrCat("the ", kSide[side], " hand travels in one clip and not the other");
      return false;
    }
    if (active(a, side) &&
        (a.hand_swings[side] >= kSwinging) != (b.hand_swings[side] >= kSwinging)) {
      if (why)
        *why = absl::StrCat("the ", kSide[side], " hand swings back and forth in one clip only");
      return false;
    }
  }
  return true;
}

absl::StatusOr<Registration> RegisterMovement(const MovementClip& content,
                                              const MovementClip& example,
                                              const RegisterOptions& options) {
  const int n = content.clip.num_frames, m = example.clip.num_frames;
  if (content.steps != example.steps) {
    return absl::FailedPreconditionError(absl::StrCat(
        "movement: the ", content.steps ? "content" : "example", " clip steps and the ",
        content.steps ? "example" : "content", " clip does not"));
  }
  Registration reg;
  reg.time.resize(n);
  if (content.steps) {
    reg.kind = Registration::Kind::kSteps;
    const double ve = std::max(example.step_speed, 1e-3);
    // The first instant: where the example's legs are most as the content's.
    double best = std::numeric_limits<double>::infinity();
    double t = example.loop_begin;
    for (int a = example.loop_begin; a < example.loop_end; ++a) {
      const double d = SquaredDistance(content.gait[0], example.gait[a]);
      if (d < best) best = d, t = a;
    }
    const double loop = example.loop_end - example.loop_begin;
    double total = 0;
    reg.step_rate.resize(n);
    for (int f = 0; f < n; ++f) {
      reg.time[f] = t;
      const double rate = std::clamp(std::sqrt(std::max(content.speed[f], 1e-6) / ve),
                                     options.min_rate, options.max_rate);
      reg.step_rate[f] = rate;
      total += rate;
      t += rate;
      while (loop > 0 && t >= example.loop_end) t -= loop;
    }
    reg.rate = total / n;
    return reg;
  }
  reg.kind = Registration::Kind::kGesture;
  // Dynamic time warping on every k-th frame, k such that the table holds at
  // most ~1M cells (a long clip costs time, never unbounded memory).
  const int k =
      std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n) * m / 1.0e6))));
  const int cn = (n + k - 1) / k, cm = (m + k - 1) / k;
  std::vector<float> acc(static_cast<size_t>(cn) * cm);
  std::vector<uint8_t> from(static_cast<size_t>(cn) * cm);
  auto cell = [cm](int i, int j) { return static_cast<size_t>(i) * cm + j; };
  for (int i = 0; i < cn; ++i) {
    for (int j = 0; j < cm; ++j) {
      const double c = std::sqrt(SquaredDistance(content.shape[i * k], example.shape[j * k]));
      if (i == 0 && j == 0) {
        acc[cell(i, j)] = static_cast<float>(c);
        continue;
      }
      double best = std::numeric_limits<double>::infinity();
      uint8_t how = 0;
      if (i > 0 && j > 0 && acc[cell(i - 1, j - 1)] + c < best) {
        best = acc[cell(i - 1, j - 1)] + c;
        how = 0;
      }
      if (i > 0 && acc[cell(i - 1, j)] + options.hold_penalty * c < best) {
        best = acc[cell(i - 1, j)] + options.hold_penalty * c;
        how = 1;
      }
      if (j > 0 && acc[cell(i, j - 1)] + options.hold_penalty * c < best) {
        best = acc[cell(i, j - 1)] + options.hold_penalty * c;
        how = 2;
      }
      acc[cell(i, j)] = static_cast<float>(best);
      from[cell(i, j)] = how;
    }
  }
  std::vector<double> sum(cn, 0), count(cn, 0);
  int i = cn - 1, j = cm - 1, steps = 1;
  while (true) {
    sum[i] += j;
    count[i] += 1;
    if (i == 0 && j == 0) break;
    const uint8_t how = from[cell(i, j)];
    if (i == 0) {
      --j;
    } else if (j == 0) {
      --i;
    } else if (how == 0) {
      --i, --j;
    } else if (how == 1) {
      --i;
    } else {
      --j;
    }
    ++steps;
  }
  reg.cost = acc[cell(cn - 1, cm - 1)] / steps;
  std::vector<double> coarse(cn);
  for (int c = 0; c < cn; ++c) coarse[c] = k * sum[c] / count[c];
  for (int f = 0; f < n; ++f) {
    const double x = static_cast<double>(f) / k;
    const int c0 = std::min(cn - 1, static_cast<int>(x));
    const int c1 = std::min(cn - 1, c0 + 1);
    reg.time[f] = coarse[c0] + (coarse[c1] - coarse[c0]) * (x - c0);
  }
  reg.time = Smooth(reg.time, 1.5, 0.0);
  // Both clips' ends meet, as the warp's ends do.
  reg.time.front() = 0;
  reg.time.back() = m - 1;
  for (int f = 1; f < n; ++f) reg.time[f] = std::max(reg.time[f], reg.time[f - 1]);
  for (double& t : reg.time) t = std::clamp(t, 0.0, static_cast<double>(m - 1));
  reg.rate = n > 1 ? (reg.time[n - 1] - reg.time[0]) / (n - 1) : 1;
  return reg;
}

std::vector<PartSource> PartSources(const Skeleton& sk, const HumanoidRoles& roles,
                                    const MovementOptions& options) {
  std::vector<PartSource> source(sk.num_joints(), PartSource::kNetwork);
  for (int j : BodyPartJoints(sk, roles, BodyPart::kLegs)) source[j] = options.legs;
  for (BodyPart arm : {BodyPart::kLeftArm, BodyPart::kRightArm}) {
    for (int j : BodyPartJoints(sk, roles, arm)) source[j] = options.arms;
  }
  for (int j : BodyPartJoints(sk, roles, BodyPart::kTorso)) source[j] = options.spine;
  return source;
}

LocalPose MoveFrame(const Skeleton& sk, const HumanoidRoles& roles, const MovementClip& example,
                    const std::vector<PartSource>& source, bool pelvis_from_example,
                    const LocalPose& network, const FramePlacement& at, const FrameLayer* layer) {
  const int m = example.clip.num_frames, joints = sk.num_joints();
  const Sample s = At(at.time, m);
  const int pelvis = roles.pelvis, pelvis_parent = sk.joint(pelvis).parent;
  LocalPose pose = network;
  for (int j = 0; j < joints; ++j) {
    if (j == pelvis || source[j] == PartSource::kNetwork) continue;
    const Quat e =
        SlerpShort(example.poses[s.i0].rotations[j], example.poses[s.i1].rotations[j], s.a);
    if (source[j] == PartSource::kLayer && layer != nullptr) {
      const Quat ep =
          SlerpShort((*layer->example)[s.i0][j], (*layer->example)[s.i1][j], s.a);
      pose.rotations[j] = Normalized((*layer->network)[j] * Conjugate(ep) * e);
    } else {
      pose.rotations[j] = e;
    }
  }
  if (pelvis_from_example) {
    const double he = example.heading[s.i0] + (example.heading[s.i1] - example.heading[s.i0]) * s.a;
    const Quat turn = YawRotation(at.heading - he);
    const Quat rot = SlerpShort(example.pelvis_rotation[s.i0], example.pelvis_rotation[s.i1], s.a);
    const Vec3 pos = Lerp(example.positions[s.i0][pelvis], example.positions[s.i1][pelvis], s.a);
    const Vec3 path = Lerp(example.floor_path[s.i0], example.floor_path[s.i1], s.a);
    // Sway about the example's path, turned to the output's facing; its
    // height over its own floor, on the content's floor.
    const Vec3 sway = Rotate(turn, OnFloor(pos - path));
    const Vec3 world{at.floor_point.x + sway.x, pos.y - example.floor_height + at.floor,
                     at.floor_point.z + sway.z};
    const Quat world_rot = Normalized(turn * rot);
    Quat parent_rot;
    Vec3 parent_pos;
    if (pelvis_parent >= 0) {
      const GlobalPose g = ForwardKinematics(sk, network);
      parent_rot = g.rotations[pelvis_parent];
      parent_pos = g.positions[pelvis_parent];
    }
    pose.rotations[pelvis] = Normalized(Conjugate(parent_rot) * world_rot);
    if (HasPositionChannel(sk.joint(pelvis))) {
      pose.translations[pelvis] = Rotate(Conjugate(parent_rot), world - parent_pos);
    }
  }
  const bool legs = source[roles.left_ankle] != PartSource::kNetwork;
  if (at.fit_stride && legs) {
    GlobalPose g = ForwardKinematics(sk, pose);
    const Vec3 centre = OnFloor(g.positions[pelvis]);
    for (int side = 0; side < 2; ++side) {
      const int ankle = side == 0 ? roles.left_ankle : roles.right_ankle;
      const Vec3 local = InFacing(g.positions[ankle] - centre, at.heading);
      const Vec3 want_local{local.x, local.y, local.z * at.stride_scale};
      PlaceAnkle(sk, g, ankle, centre + Rotate(YawRotation(at.heading), want_local), &pose);
    }
  }
  // No foot below the content's floor.
  if (legs) KeepFeetAboveFloor(sk, roles, at.floor, &pose);
  return pose;
}

absl::StatusOr<MovementResult> ApplyMovement(const Motion& network, const MovementClip& content,
                                             const MovementClip& example,
                                             const Registration& registration,
                                             const MovementOptions& options) {
  const int n = network.num_frames, m = example.clip.num_frames;
  const Skeleton& sk = network.skeleton;
  if (!sk.SameTopology(content.clip.skeleton) || !sk.SameTopology(example.clip.skeleton)) {
    return absl::InvalidArgumentError("movement: the clips are on different skeletons");
  }
  if (content.clip.num_frames != n || static_cast<int>(registration.time.size()) != n ||
      (registration.kind == Registration::Kind::kSteps &&
       static_cast<int>(registration.step_rate.size()) != n)) {
    return absl::InvalidArgumentError(
        absl::StrCat("movement: the network's output has ", n, " frames, the content ",
                     content.clip.num_frames, ", the registration ", registration.time.size()));
  }
  const HumanoidRoles& roles = content.roles;
  absl::StatusOr<MovementClip> out_read = AnalyzeMovement(network, roles);
  if (!out_read.ok()) return out_read.status();
  const MovementClip& net = *out_read;
  const double fps = network.fps();
  const std::vector<PartSource> source = PartSources(sk, roles, options);
  const bool layered = std::count(source.begin(), source.end(), PartSource::kLayer) > 0;
  std::vector<std::vector<Quat>> net_posture, example_posture;
  if (layered) {
    net_posture = Posture(net.poses, options.posture_s * fps);
    example_posture = Posture(example.poses, options.posture_s * fps);
  }
  const bool stepping = registration.kind == Registration::Kind::kSteps;
  const double ve = std::max(example.step_speed, 1e-3);

  MovementResult result;
  result.motion = network;
  std::array<std::vector<bool>, 4> flags;
  for (auto& f : flags) f.assign(n, false);
  std::vector<Vec3> prev_euler(sk.num_joints());
  for (int f = 0; f < n; ++f) {
    FramePlacement at;
    at.time = registration.time[f];
    at.heading = net.heading[f];
    at.floor_point = net.floor_path[f];
    at.floor = content.floor_height;
    // The example is played `step_rate` times as fast, so its stride must
    // cover vc / (rate ve) of what it did.
    at.fit_stride = stepping && options.fit_stride;
    if (at.fit_stride) {
      at.stride_scale = std::clamp(content.speed[f] / (registration.step_rate[f] * ve), 0.6, 1.6);
    }
    FrameLayer layer;
    if (layered) layer = {&net_posture[f], &example_posture};
    const LocalPose pose = MoveFrame(sk, roles, example, source, options.pelvis, net.poses[f], at,
                                     layered ? &layer : nullptr);
    if (options.legs != PartSource::kNetwork) {
      const int e = std::clamp(static_cast<int>(std::lround(at.time)), 0, m - 1);
      for (int k = 0; k < 4; ++k) flags[k][f] = example.contact[k][e];
    }
    SetPose(&result.motion, f, pose, &prev_euler);
  }
  if (options.legs != PartSource::kNetwork) {
    result.contacts = SpansFromFlags(flags, std::max(2, static_cast<int>(std::lround(0.1 * fps))));
  } else {
    result.contacts = DetectContactSpans(GlobalPositions(result.motion), roles, fps);
  }
  return result;
}

Vec3 OnFloor(const Vec3& p) { return {p.x, 0, p.z}; }

Vec3 InFacing(const Vec3& v, double yaw) { return Rotate(YawRotation(-yaw), v); }

double SquaredDistance(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]);
  return d;
}

}  // namespace stylus::motion
