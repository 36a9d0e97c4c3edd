// Movement from examples in a stream (docs/movement.md "Streams"): the
// same parts as a transfer's (motion/example_motion.h), decided frame by
// frame from the content frames received so far and a look-ahead of a few.
//
//  - ContentTrack reads the content as it arrives: its path and facing
//    (linear fits over the last ~0.8 s and the look-ahead, so neither lags
//    a steady walk), its speed over the last second, and the shapes a
//    transfer registers on (legs, hands, elbows, and their velocities).
//  - MovementFollower plays takes of the style on it, the body's parts as
//    a transfer's (legs, pelvis, arms, spine). Stepping (the content
//    travels): of the stepping takes, the one nearest the content's speed
//    and turning if one is near enough (else the network's legs), its loop
//    at its cadence scaled by its walk ratio to the content's speed, entered
//    at the instant whose legs are most as the content's (the phase of its
//    contacts), the stride fitted to the path.
//    Gestures (the content stands): every standing take registered to the
//    content by open-end dynamic time warping, one row per frame, compared
//    from where each gesture starts; the best one plays, waiting for the
//    content and never rushing (a pass starts again once played out). The
//    output's contacts are the playing take's. Each fades in and out over a
//    quarter second; the strength blends the result with the network's.
//
// Everything kept is bounded by the examples' lengths and ~1.2 s of
// content, whatever the stream's length.
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MOTION_LIVE_MOVEMENT_H_
#define STYLUS_MOTION_LIVE_MOVEMENT_H_

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "motion/example_motion.h"
#include "motion/humanoid.h"
#include "motion/motion.h"

namespace stylus::motion {

class ContentTrack {
 public:
  // `skeleton`: the stream's frames' (Y up); `lookahead`: content frames
  // after an output frame that may be read when it is made.
  ContentTrack(const Skeleton& skeleton, const HumanoidRoles& roles, double frame_time,
               int lookahead);

  // The stream's next content frame.
  void Add(const LocalPose& pose);
  int64_t received() const { return base_ + static_cast<int64_t>(frames_.size()); }
  // Drops what no frame from `first` on reads.
  void Forget(int64_t first);

  // At content frame `f` (received, looking at most `lookahead` ahead):
  struct Estimate {
    Vec3 floor_point;  // The pelvis's floor point, without sway.
    double heading = 0;
    double speed = 0;  // Leg lengths per second.
    double floor = 0;  // The feet's floor so far.
    // Over the last second: the turning (rad/s, + left) and the direction
    // of travel in the facing frame (x left, z ahead).
    double turn_rate = 0;
    Vec3 travel = {0, 0, 1};
    double flight = 0;  // The share of frames with no foot down (MovementClip::flight).
  };
  // With the registration features at `f` (as MovementClip's, velocities
  // taken backwards over 0.2 s).
  struct Reading {
    Estimate at;
    std::vector<double> gait, shape;
  };
  // Frame `f`: each frame once, in order.
  Reading Read(int64_t f);

  const Skeleton& skeleton() const { return skeleton_; }
  const HumanoidRoles& roles() const { return roles_; }
  double fps() const { return fps_; }
  size_t bytes() const;

 private:
  struct Frame {
    std::vector<Vec3> positions;
    double yaw = 0;  // Unwrapped.
  };
  Skeleton skeleton_;
  HumanoidRoles roles_;
  double fps_, leg_;
  int lookahead_, path_window_, heading_window_, speed_window_, lag_;
  std::array<std::array<int, 3>, 2> arms_ = {};
  std::deque<Frame> frames_;
  int64_t base_ = 0;
  // The lowest the foot joints went in frames [0, floored_): all of them,
  // and each (FootJoints order).
  double floor_ = 1e300;
  std::array<double, 4> joint_floor_ = {1e300, 1e300, 1e300, 1e300};
  int64_t floored_ = 0;
  // The last lag + 1 frames' position features (for velocities).
  std::deque<std::pair<std::vector<double>, std::vector<double>>> recent_;
};

// The examples a stream plays: takes of its style.
struct StreamExamples {
  // Takes that step; while the content steps, the one whose speed, turning
  // and direction of travel are nearest the content's plays.
  std::vector<std::shared_ptr<const MovementClip>> steps;
  // Takes that do not step; each is registered to the content all along,
  // and the one that registers best plays.
  std::vector<std::shared_ptr<const MovementClip>> gestures;
  std::vector<std::string> step_names, gesture_names;  // For notes and logs.
  // Each take's action, when the takes are gated by action
  // (MovementFollower::ReadActions): a probability per action of the
  // package's content guard (a labelled take's is its label's alone);
  // empty: not known (the take is not gated).
  std::vector<std::vector<double>> step_actions, gesture_actions;
  static constexpr int kMaxTakes = 64;  // Of each kind.
};

// How far two readings of an action (a probability per action, as a
// content guard gives them) agree: the sum over actions of the smaller
// probability (1 the same reading, 0 nothing in common); 1 when either is
// empty or they differ in length (nothing known to disagree on).
double ActionOverlap(const std::vector<double>& a, const std::vector<double>& b);

struct FollowOptions {
  MovementOptions parts;  // kLayer is played as kExample (a posture needs the future).
  double fade_s = 0.25;
  // The content steps from this speed on, and stops below `stop_speed`
  // (leg lengths per second).
  double step_speed = 0.3, stop_speed = 0.15;
  // A gesture's registration is used while its mean cost stays below this
  // (MovementKeys::movement_max_cost).
  double max_cost = 1;
  // A stepping take plays while its turning, travel and flight stay this
  // near the content's (MovementKeys::movement_max_mismatch).
  double max_mismatch = 1;
  // Takes are gated by action (MovementKeys::movement_action_gate): a take
  // whose action is known plays only while the content's action as last
  // read (ReadActions) overlaps its own by at least this much (the sum over
  // actions of the smaller of the two probabilities: 1 the same reading, 0
  // nothing in common). Until the first reading every take may play.
  // 0: no gate.
  double action_gate = 0;
};

class MovementFollower {
 public:
  MovementFollower(StreamExamples examples, const ContentTrack& track, FollowOptions options);

  // Output frame `f` (each frame once, in order; `now`: the track's Read of
  // it, the track holding content up to f + its look-ahead): `network` moved as the examples say, blended by
  // `strength`. `contacts` gets the output's own foot contacts (FootJoints
  // order) while the legs are the example's, else nullopt.
  LocalPose Apply(const ContentTrack& track, const ContentTrack::Reading& now,
                  const LocalPose& network, double strength,
                  std::optional<std::array<bool, 4>>* contacts);

  // The content's action lately, one probability per action (the package's
  // content guard's reading of its last seconds). With an action gate, a
  // take whose action does not overlap it stops playing (fading out) and is
  // not chosen until the reading changes.
  void ReadActions(const std::vector<double>& probabilities);
  // Whether a reading can change what plays: an action gate, and a take
  // whose action is known.
  bool gated() const;

  // Reading, for notes and tests.
  double step_weight() const { return w_steps_; }
  double gesture_weight() const { return w_gesture_; }
  double step_time() const { return t_steps_; }
  double gesture_time() const;
  int step_take() const { return step_take_; }  // Index into examples().steps; -1: none yet.
  int gesture_take() const { return gesture_; }  // Index into examples().gestures; -1: none.
  double gesture_cost() const { return gesture_ >= 0 ? warps_[gesture_].cost : 0; }
  const StreamExamples& examples() const { return examples_; }
  size_t bytes() const;

 private:
  // A gesture take's registration: the warp's last row (cost and path
  // length per take frame), the content frames in this pass, the instant
  // played (forward only) and its mean cost there.
  struct Warp {
    std::vector<float> acc, len;
    std::vector<double> origin;  // The content's shape at the pass's start.
    int frames = 0;
    double time = 0, cost = 1e300;
  };
  void Register(const MovementClip& take, const std::vector<double>& shape, Warp* warp) const;
  LocalPose Gesture(const ContentTrack& track, const ContentTrack::Estimate& est, int take,
                    double time, const LocalPose& network) const;
  // Stepping: the take nearest the content's stepping (`current` favoured;
  // -1 when none is near enough); the instant of a take whose legs are most
  // as `gait`; an instant moved on by `rate` frames, looped; the network's
  // pose with a take's parts at an instant (and the rate it plays at).
  int NearestSteps(const ContentTrack::Estimate& est, int current) const;
  // Gestures: how far each of the content's hands travelled up and down
  // lately and how many times it swung (left, right); whether a take's arms
  // do another thing.
  struct ArmReading {
    std::array<double, 2> reach = {};
    std::array<int, 2> swings = {};
    std::array<int, 2> held = {};  // Frames in the upper half of its travel.
  };
  ArmReading ReadArms() const;
  static bool ArmsDiffer(const ArmReading& content, const MovementClip& take, int held_frames);
  double Entry(const MovementClip& take, const std::vector<double>& gait) const;
  // Whether take `take` (of `actions`' kind) may play (the action gate).
  bool ActionAllowed(const std::vector<std::vector<double>>& actions, int take) const;
  double Advance(const MovementClip& take, double t, double rate) const;
  LocalPose Steps(const ContentTrack& track, const ContentTrack::Estimate& est, int take,
                  double time, const LocalPose& network, double* rate) const;

  StreamExamples examples_;
  FollowOptions options_;
  std::vector<PartSource> source_;  // Per joint.
  bool stepping_ = false;
  double w_steps_ = 0, w_gesture_ = 0;
  int step_take_ = -1;
  double t_steps_ = 0;
  int next_check_ = 0;      // Frames until the stepping take is chosen again.
  bool steps_fit_ = false;  // A stepping take shows the content's stepping.
  // A stepping take that was taken over, faded out.
  int step_from_ = -1, step_switch_left_ = 0;
  double step_from_time_ = 0;
  std::vector<Warp> warps_;  // Per gesture take.
  // The content's hands lately: sideways and up per side (leg lengths).
  std::deque<std::array<double, 4>> hands_;
  int gesture_ = -1;         // The take playing.
  // A switch of take or a new pass fades from where the last one was.
  int switch_left_ = 0, switch_from_ = -1;
  double switch_time_ = 0;
  // The action gate: the content's action as last read; empty: not read
  // yet.
  std::vector<double> content_actions_;
};

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_LIVE_MOVEMENT_H_
