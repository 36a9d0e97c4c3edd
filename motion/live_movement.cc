#include "motion/live_movement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/resample.h"

namespace stylus::motion {
namespace {

// The positions at the front of a shape (MovementClip::shape): hands,
// elbows and ankles; their velocities follow.
constexpr int kShapePositions = 18;

// A gesture take plays at most this many of its frames per content frame
// (catching up on the content in a rush reads as a wave).
constexpr double kMaxGestureRate = 2;

// Stepping: how often another take may take over (seconds), and by how much
// nearer it must be than the one playing.
constexpr double kRecheckS = 0.5;
constexpr double kKeepMargin = 0.15;

// Gestures: what the content's hands did is read over this long, and a take
// whose arms do another thing counts its cost this many times.
constexpr double kArmWindowS = 3;
constexpr double kOtherArmsFactor = 2;
constexpr double kHeldS = 1;  // A hand up this long without a swing: no wave.

int Frames(double seconds, double fps) {
  return std::max(1, static_cast<int>(std::lround(seconds * fps)));
}

// The straight line through (i, y_i) for i in [a, b], at `at`; its slope
// (per frame) in `slope_out` when given.
template <typename Get>
double LineAt(int64_t a, int64_t b, int64_t at, Get y, double* slope_out = nullptr) {
  const int n = static_cast<int>(b - a + 1);
  if (slope_out != nullptr) *slope_out = 0;
  if (n < 2) return y(b);
  double si = 0, sy = 0, sii = 0, siy = 0;
  for (int64_t i = a; i <= b; ++i) {
    const double x = static_cast<double>(i - a), v = y(i);
    si += x;
    sy += v;
    sii += x * x;
    siy += x * v;
  }
  const double den = n * sii - si * si;
  const double slope = den > 0 ? (n * siy - si * sy) / den : 0;
  if (slope_out != nullptr) *slope_out = slope;
  return (sy - slope * si) / n + slope * static_cast<double>(at - a);
}

}  // namespace

ContentTrack::ContentTrack(const Skeleton& skeleton, const HumanoidRoles& roles, double frame_time,
                           int lookahead)
    : skeleton_(skeleton),
      roles_(roles),
      fps_(1 / frame_time),
      leg_(std::max(roles.leg_length, 1e-9)),
      lookahead_(std::max(0, lookahead)),
      path_window_(Frames(0.8, fps_)),
      heading_window_(Frames(0.4, fps_)),
      speed_window_(Frames(1.0, fps_)),
      lag_(Frames(0.2, fps_)) {
  for (int side = 0; side < 2; ++side) {
    const int upper = side == 0 ? roles.left_shoulder : roles.right_shoulder;
    const int fore = upper < 0 ? -1 : MainChild(skeleton, upper);
    const int hand = fore < 0 ? -1 : MainChild(skeleton, fore);
    arms_[side] = {upper, fore < 0 ? upper : fore, hand < 0 ? upper : hand};
  }
}

void ContentTrack::Add(const LocalPose& pose) {
  Frame fr;
  fr.positions = ForwardKinematics(skeleton_, pose).positions;
  const std::vector<Vec3>& p = fr.positions;
  const Vec3 across = (p[roles_.left_hip] - p[roles_.right_hip]) +
                      (p[roles_.left_shoulder] - p[roles_.right_shoulder]);
  const Vec3 ahead = Cross(across, Vec3{0, 1, 0});
  fr.yaw = std::atan2(ahead.x, ahead.z);
  if (!frames_.empty()) {
    const double prev = frames_.back().yaw;
    while (fr.yaw - prev > M_PI) fr.yaw -= 2 * M_PI;
    while (fr.yaw - prev < -M_PI) fr.yaw += 2 * M_PI;
  }
  frames_.push_back(std::move(fr));
}

void ContentTrack::Forget(int64_t first) {
  const int64_t keep = first - std::max({path_window_, heading_window_, speed_window_}) - 1;
  while (base_ < keep && frames_.size() > 1) {
    frames_.pop_front();
    ++base_;
  }
}

ContentTrack::Reading ContentTrack::Read(int64_t f) {
  Reading reading;
  Estimate& e = reading.at;
  const int64_t last = std::min(f + lookahead_, received() - 1);
  auto frame = [&](int64_t i) -> const Frame& { return frames_[static_cast<size_t>(i - base_)]; };
  const int pelvis = roles_.pelvis;
  const int64_t a = std::max(base_, f - path_window_);
  e.floor_point = {LineAt(a, last, f, [&](int64_t i) { return frame(i).positions[pelvis].x; }), 0,
                   LineAt(a, last, f, [&](int64_t i) { return frame(i).positions[pelvis].z; })};
  e.heading = LineAt(std::max(base_, f - heading_window_), last, f,
                     [&](int64_t i) { return frame(i).yaw; });
  const int64_t since = std::max(base_, last - speed_window_);
  if (last > since) {
    const Vec3 moved = OnFloor(frame(last).positions[pelvis] - frame(since).positions[pelvis]);
    e.speed = Norm(moved) * fps_ / static_cast<double>(last - since) / leg_;
    e.travel = Normalized(InFacing(moved, e.heading), Vec3{0, 0, 1});
    double slope = 0;
    LineAt(
        since, last, last, [&](int64_t i) { return frame(i).yaw; }, &slope);
    e.turn_rate = slope * fps_;
  }
  // The feet's floor: the lowest a foot joint went up to this frame (and
  // each foot joint's own lowest, for its contacts).
  const std::array<int, 4> feet = FootJoints(roles_);
  for (int64_t i = std::max(base_, floored_); i <= last; ++i) {
    for (int k = 0; k < 4; ++k) {
      const double y = frame(i).positions[feet[k]].y;
      floor_ = std::min(floor_, y);
      joint_floor_[k] = std::min(joint_floor_[k], y);
    }
  }
  floored_ = std::max(floored_, last + 1);
  e.floor = floor_;
  // The share of the last second's frames with no foot joint down (low and
  // still, as ContactParams reads them): about 0 for a walk, more for a run.
  if (last > since) {
    const ContactParams contact;
    int airborne = 0;
    for (int64_t i = since + 1; i <= last; ++i) {
      bool down = false;
      for (int k = 0; k < 4 && !down; ++k) {
        const Vec3& now = frame(i).positions[feet[k]];
        const double moved = Norm(OnFloor(now - frame(i - 1).positions[feet[k]])) * fps_;
        down = now.y - joint_floor_[k] < contact.height * leg_ && moved < contact.speed * leg_;
      }
      airborne += !down;
    }
    e.flight = static_cast<double>(airborne) / static_cast<double>(last - since);
  }
  const Estimate& at = e;
  const std::vector<Vec3>& p = frames_[static_cast<size_t>(f - base_)].positions;
  auto rel = [&](int j) { return InFacing(p[j] - at.floor_point, at.heading) * (1 / leg_); };
  std::vector<double> g, s;
  const int knees[2] = {skeleton_.joint(roles_.left_ankle).parent,
                        skeleton_.joint(roles_.right_ankle).parent};
  for (int j : {knees[0], knees[1], roles_.left_ankle, roles_.right_ankle, roles_.left_toe,
                roles_.right_toe}) {
    const Vec3 v = rel(j);
    g.insert(g.end(), {v.x, v.y, v.z});
  }
  g.push_back((p[roles_.pelvis].y - at.floor) / leg_);
  for (int side = 0; side < 2; ++side) {
    for (int j : {arms_[side][1], arms_[side][2]}) {
      const Vec3 v = rel(j);
      s.insert(s.end(), {v.x, v.y, v.z});
    }
  }
  for (int j : {roles_.left_ankle, roles_.right_ankle}) {
    const Vec3 v = rel(j);
    s.insert(s.end(), {v.x, v.y, v.z});
  }
  recent_.emplace_back(g, s);
  while (static_cast<int>(recent_.size()) > lag_ + 1) recent_.pop_front();
  const auto& [g0, s0] = recent_.front();
  const double scale = recent_.size() > 1 ? static_cast<double>(lag_) / (recent_.size() - 1) : 0;
  reading.gait = g;
  for (size_t c = 0; c < g.size(); ++c) reading.gait.push_back((g[c] - g0[c]) * scale);
  reading.shape = s;
  for (int c : {3, 4, 5, 9, 10, 11}) reading.shape.push_back((s[c] - s0[c]) * scale);
  return reading;
}

size_t ContentTrack::bytes() const {
  size_t n = 0;
  for (const Frame& f : frames_) n += f.positions.size() * sizeof(Vec3) + sizeof(Frame);
  for (const auto& [g, s] : recent_) n += (g.size() + s.size()) * sizeof(double);
  return n;
}

MovementFollower::MovementFollower(StreamExamples examples, const ContentTrack& track,
                                   FollowOptions options)
    : examples_(std::move(examples)), options_(std::move(options)) {
  MovementOptions parts = options_.parts;
  auto played = [](PartSource s) { return s == PartSource::kLayer ? PartSource::kExample : s; };
  parts.legs = played(parts.legs);
  parts.arms = played(parts.arms);
  parts.spine = played(parts.spine);
  source_ = PartSources(track.skeleton(), track.roles(), parts);
  warps_.resize(examples_.gestures.size());
}

void MovementFollower::ReadActions(const std::vector<double>& probabilities) {
  if (!probabilities.empty()) content_actions_ = probabilities;
}

bool MovementFollower::gated() const {
  if (options_.action_gate <= 0) return false;
  for (const auto* actions : {&examples_.step_actions, &examples_.gesture_actions}) {
    for (const std::vector<double>& a : *actions) {
      if (!a.empty()) return true;
    }
  }
  return false;
}

double ActionOverlap(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.empty() || a.size() != b.size()) return 1;
  double overlap = 0;
  for (size_t i = 0; i < a.size(); ++i) overlap += std::min(a[i], b[i]);
  return overlap;
}

bool MovementFollower::ActionAllowed(const std::vector<std::vector<double>>& actions,
                                     int take) const {
  if (options_.action_gate <= 0 || static_cast<size_t>(take) >= actions.size()) return true;
  return ActionOverlap(actions[take], content_actions_) >= options_.action_gate;
}

double MovementFollower::gesture_time() const {
  return gesture_ >= 0 ? warps_[gesture_].time : 0;
}

void MovementFollower::Register(const MovementClip& take, const std::vector<double>& shape,
                                Warp* warp) const {
  const int m = take.clip.num_frames;
  // The content skipping ahead of the take costs RegisterOptions'
  // hold_penalty; the take waiting for the content (a performer standing
  // before a gesture) costs a plain step.
  const float hold = 1.5f, wait = 1.0f;
  std::vector<float>& acc = warp->acc;
  std::vector<float>& len = warp->len;
  // Positions are compared from where each clip's gesture starts (the
  // content's at the pass's first frame, the take's at its first): two
  // performers' rest poses differ more than a raise's first tenth does.
  if (warp->frames == 0) warp->origin.assign(shape.begin(), shape.begin() + kShapePositions);
  std::vector<double> from_start = shape;
  for (int c = 0; c < kShapePositions; ++c) {
    from_start[c] += take.shape[0][c] - warp->origin[c];
  }
  auto cost = [&](int j) {
    return static_cast<float>(std::sqrt(SquaredDistance(from_start, take.shape[j])));
  };
  if (warp->frames == 0) {
    acc.assign(m, 0);
    len.assign(m, 0);
    for (int j = 0; j < m; ++j) {
      const float c = cost(j);
      acc[j] = j == 0 ? c : acc[j - 1] + hold * c;
      len[j] = static_cast<float>(j + 1);
    }
  } else {
    float diag_acc = 0, diag_len = 0;  // The row before's, at column j - 1.
    for (int j = 0; j < m; ++j) {
      const float c = cost(j);
      float best = acc[j] + wait * c, best_len = len[j] + 1;  // The take holds.
      if (j > 0) {
        if (diag_acc + c < best) best = diag_acc + c, best_len = diag_len + 1;  // Both move.
        if (acc[j - 1] + hold * c < best) {  // The content holds (acc[j - 1]: this row's).
          best = acc[j - 1] + hold * c;
          best_len = len[j - 1] + 1;
        }
      }
      diag_acc = acc[j];
      diag_len = len[j];
      acc[j] = best;
      len[j] = best_len;
    }
  }
  ++warp->frames;
  int at = 0;
  double score = std::numeric_limits<double>::infinity();
  for (int j = 0; j < m; ++j) {
    const double sc = acc[j] / len[j];
    if (sc < score) score = sc, at = j;
  }
  warp->cost = score;
  // Forward only, at most kMaxGestureRate take frames per content frame.
  warp->time = std::clamp(static_cast<double>(at), warp->time, warp->time + kMaxGestureRate);
}

LocalPose MovementFollower::Gesture(const ContentTrack& track, const ContentTrack::Estimate& est,
                                    int take, double time, const LocalPose& network) const {
  FramePlacement at;
  at.time = time;
  at.heading = est.heading;
  at.floor_point = est.floor_point;
  at.floor = est.floor;
  return MoveFrame(track.skeleton(), track.roles(), *examples_.gestures[take], source_,
                   options_.parts.pelvis, network, at);
}

LocalPose MovementFollower::Apply(const ContentTrack& track, const ContentTrack::Reading& now,
                                  const LocalPose& network, double strength,
                                  std::optional<std::array<bool, 4>>* contacts) {
  contacts->reset();
  const ContentTrack::Estimate& est = now.at;
  const std::vector<double>& gait = now.gait;
  const std::vector<double>& shape = now.shape;
  const int fade = Frames(options_.fade_s, track.fps());
  const double dw = 1.0 / fade;

  // Stepping: the content steps from step_speed on, until below
  // stop_speed (with takes to play or not: a gesture take never plays on a
  // content that travels). While it steps, every half second or so: the
  // stepping take nearest the content's speed, turning and direction of
  // travel, if one is near enough (max_mismatch); a new one enters at the
  // instant whose legs (and their contacts) are most as the content's and
  // fades in; none near enough, the network's legs fade back.
  if (!stepping_ && est.speed >= options_.step_speed) {
    stepping_ = true;
    next_check_ = 0;
  } else if (stepping_ && est.speed < options_.stop_speed) {
    stepping_ = false;
  }
  bool steps_on = false;
  if (stepping_ && !examples_.steps.empty()) {
    if (--next_check_ <= 0) {
      next_check_ = Frames(kRecheckS, track.fps());
      const int nearest = NearestSteps(est, w_steps_ > 0 ? step_take_ : -1);
      steps_fit_ = nearest >= 0;
      if (nearest >= 0 && w_steps_ <= 0) {
        step_take_ = nearest;
        t_steps_ = Entry(*examples_.steps[step_take_], gait);
      } else if (nearest >= 0 && nearest != step_take_) {  // Another takes over, faded in.
        step_from_ = step_take_;
        step_from_time_ = t_steps_;
        step_switch_left_ = fade;
        step_take_ = nearest;
        t_steps_ = Entry(*examples_.steps[step_take_], gait);
      }
    }
    steps_on = steps_fit_;
  }
  w_steps_ = std::clamp(w_steps_ + (steps_on ? dw : -dw), 0.0, 1.0);
  // Gestures: every take registered while the content stands; the best
  // plays (a switch fades from the last one).
  if (!warps_.empty()) {
    // What the content's hands did over the last seconds: which travel and
    // whether they swing (SameArmAction's reading, causally). A take whose
    // arms do another thing is chosen only when no other fits (refusing it
    // outright, as a transfer does, loses more style than content on the
    // validation pairs: docs/notes/movement.md).
    hands_.push_back({shape[3], shape[4], shape[9], shape[10]});
    while (static_cast<int>(hands_.size()) > Frames(kArmWindowS, track.fps())) hands_.pop_front();
    const ArmReading arms = ReadArms();
    int best = -1;
    std::vector<double> score(warps_.size(), std::numeric_limits<double>::infinity());
    for (size_t k = 0; k < warps_.size(); ++k) {
      Warp& w = warps_[k];
      if (stepping_) {
        w = Warp{};
        continue;
      }
      Register(*examples_.gestures[k], shape, &w);
      if (!ActionAllowed(examples_.gesture_actions, static_cast<int>(k))) continue;
      const bool differ = ArmsDiffer(arms, *examples_.gestures[k], Frames(kHeldS, track.fps()));
      score[k] = w.cost * (differ ? kOtherArmsFactor : 1);
      if (best < 0 || score[k] < score[best]) best = static_cast<int>(k);
    }
    if (best >= 0 && best != gesture_ && (gesture_ < 0 || score[best] < 0.8 * score[gesture_])) {
      if (gesture_ >= 0 && w_gesture_ > 0) {
        switch_from_ = gesture_;
        switch_time_ = warps_[gesture_].time;
        switch_left_ = fade;
      }
      gesture_ = best;
    }
    const bool follows = !stepping_ && gesture_ >= 0 &&
                         warps_[gesture_].cost <= options_.max_cost &&
                         ActionAllowed(examples_.gesture_actions, gesture_);
    w_gesture_ = std::clamp(w_gesture_ + (follows ? dw : -dw), 0.0, 1.0);
  }

  LocalPose out = network;
  if (gesture_ >= 0 && w_gesture_ > 0) {
    Warp& w = warps_[gesture_];
    LocalPose moved = Gesture(track, est, gesture_, w.time, network);
    if (switch_left_ > 0) {
      const LocalPose was = Gesture(track, est, switch_from_, switch_time_, network);
      moved = BlendPoses(was, moved, 1 - static_cast<double>(switch_left_) / fade);
      --switch_left_;
    }
    if (strength > 0) out = BlendPoses(out, moved, w_gesture_ * strength);
    const MovementClip& take = *examples_.gestures[gesture_];
    const int m = take.clip.num_frames;
    if (w_gesture_ >= 0.5 && strength >= 0.5 && options_.parts.legs != PartSource::kNetwork) {
      const int e = std::clamp(static_cast<int>(std::lround(w.time)), 0, m - 1);
      std::array<bool, 4> on;
      for (int k = 0; k < 4; ++k) on[k] = take.contact[k][e];
      *contacts = on;
    }
    if (w.time >= m - 1.5) {  // Played out: a new pass, faded from its end.
      switch_from_ = gesture_;
      switch_time_ = m - 1;
      switch_left_ = fade;
      w = Warp{};
    }
  }
  if (step_take_ >= 0 && w_steps_ > 0) {
    const MovementClip& steps = *examples_.steps[step_take_];
    double rate = 1;
    LocalPose moved = Steps(track, est, step_take_, t_steps_, network, &rate);
    if (step_switch_left_ > 0) {  // Another take took over: faded in.
      double was_rate = 1;
      const LocalPose was = Steps(track, est, step_from_, step_from_time_, network, &was_rate);
      moved = BlendPoses(was, moved, 1 - static_cast<double>(step_switch_left_) / fade);
      --step_switch_left_;
      step_from_time_ = Advance(*examples_.steps[step_from_], step_from_time_, was_rate);
    }
    if (strength > 0) out = BlendPoses(out, moved, w_steps_ * strength);
    if (w_steps_ >= 0.5 && strength >= 0.5 && options_.parts.legs != PartSource::kNetwork) {
      const int e =
          std::clamp(static_cast<int>(std::lround(t_steps_)), 0, steps.clip.num_frames - 1);
      std::array<bool, 4> on;
      for (int k = 0; k < 4; ++k) on[k] = steps.contact[k][e];
      *contacts = on;
    }
    t_steps_ = Advance(steps, t_steps_, rate);
  }
  return out;
}

MovementFollower::ArmReading MovementFollower::ReadArms() const {
  ArmReading r;
  for (int side = 0; side < 2; ++side) {
    double lo = 1e300, hi = -1e300;
    for (const auto& h : hands_)
      lo = std::min(lo, h[2 * side + 1]), hi = std::max(hi, h[2 * side + 1]);
    r.reach[side] = hands_.empty() ? 0 : hi - lo;
    for (const auto& h : hands_) r.held[side] += h[2 * side + 1] > lo + 0.5 * (hi - lo);
    // Turns of the hand's sideways or vertical path.
    std::vector<double> path(hands_.size());
    for (int axis = 0; axis < 2; ++axis) {
      for (size_t i = 0; i < hands_.size(); ++i) path[i] = hands_[i][2 * side + axis];
      r.swings[side] = std::max(r.swings[side], CountSwings(path));
    }
  }
  return r;
}

bool MovementFollower::ArmsDiffer(const ArmReading& content, const MovementClip& take,
                                  int held_frames) {
  const auto active = HandTravels;
  if (!active(content.reach, 0) && !active(content.reach, 1)) return false;  // Not yet moving.
  for (int side = 0; side < 2; ++side) {
    if (active(content.reach, side) != active(take.hand_reach, side)) return true;
    // A swinging content hand needs a swinging take; the other way round
    // the content may not have swung yet.
    if (content.swings[side] >= kSwinging && take.hand_swings[side] < kSwinging) return true;
    // A hand held up for a while without swinging is no wave.
    if (active(content.reach, side) && content.held[side] >= held_frames &&
        content.swings[side] < 2 && take.hand_swings[side] >= kSwinging) {
      return true;
    }
  }
  return false;
}

int MovementFollower::NearestSteps(const ContentTrack::Estimate& est, int current) const {
  // Motion-matching features of stepping, as a transfer's (StepMismatch in
  // model/movement.cc): speed (a log ratio), turning (rad/s), the
  // direction of travel in the facing frame and the share of frames in
  // flight (a run is not a walk). A take that travels more than 45 degrees
  // off the content's way, or whose kind of stepping (all but the speed,
  // which the walk ratio absorbs, and which reads low while the content
  // sets off) is further than max_mismatch from it, does not show the
  // content's stepping.
  int best = -1;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < examples_.steps.size(); ++k) {
    if (!ActionAllowed(examples_.step_actions, static_cast<int>(k))) continue;
    const MovementClip& e = *examples_.steps[k];
    const double cosine = std::clamp(Dot(est.travel, e.travel), -1.0, 1.0);
    if (std::acos(cosine) > M_PI / 4) continue;
    // Its kind of stepping: turning, direction and flight.
    double kind = 2 * std::abs(est.turn_rate - e.turn_rate) + 2 * (1 - cosine) +
                  4 * std::abs(est.flight - e.flight);
    // The take playing keeps its place unless another is clearly nearer.
    if (static_cast<int>(k) == current) kind -= kKeepMargin;
    if (kind > options_.max_mismatch) continue;
    const double d =
        kind + std::abs(std::log(std::max(est.speed, 1e-3) / std::max(e.step_speed, 1e-3)));
    if (d < nearest) nearest = d, best = static_cast<int>(k);
  }
  return best;
}

double MovementFollower::Entry(const MovementClip& take, const std::vector<double>& gait) const {
  double best = std::numeric_limits<double>::infinity(), t = take.loop_begin;
  for (int a = take.loop_begin; a < std::max(take.loop_begin + 1, take.loop_end); ++a) {
    const double d = SquaredDistance(gait, take.gait[a]);
    if (d < best) best = d, t = a;
  }
  return t;
}

double MovementFollower::Advance(const MovementClip& take, double t, double rate) const {
  const double loop = take.loop_end - take.loop_begin;
  t += rate;
  while (loop > 0 && t >= take.loop_end) t -= loop;
  return t;
}

LocalPose MovementFollower::Steps(const ContentTrack& track, const ContentTrack::Estimate& est,
                                  int take, double time, const LocalPose& network,
                                  double* rate) const {
  const MovementClip& steps = *examples_.steps[take];
  const double ve = std::max(steps.step_speed, 1e-3);
  const RegisterOptions bounds;
  *rate = std::clamp(std::sqrt(std::max(est.speed, 1e-6) / ve), bounds.min_rate, bounds.max_rate);
  FramePlacement at;
  at.time = time;
  at.heading = est.heading;
  at.floor_point = est.floor_point;
  at.floor = est.floor;
  at.fit_stride = options_.parts.fit_stride;
  at.stride_scale = std::clamp(est.speed / (*rate * ve), 0.6, 1.6);
  return MoveFrame(track.skeleton(), track.roles(), steps, source_, options_.parts.pelvis, network,
                   at);
}

size_t MovementFollower::bytes() const {
  size_t n = source_.size() * sizeof(PartSource);
  for (const Warp& w : warps_) n += (w.acc.capacity() + w.len.capacity()) * sizeof(float);
  return n;
}

}  // namespace stylus::motion
