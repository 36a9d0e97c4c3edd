// Movement from examples: a real take's legs, pelvis and arms, registered to
// a content clip and played on the content's path. A network gives a
// transfer the style's pose; how the style moves (stride and cadence, foot
// lift, pelvis bob and sway, the arms' tempo and reach) comes from a take of
// the style, as an animator would layer a reference take under a shot
// (docs/movement.md).
//
// Three steps, all plain kinematics:
//  1. AnalyzeMovement: a clip's facing and smoothed floor path, its foot
//     contacts, whether it steps, its speed and step period, a seamless loop
//     of its stepping, and per-frame shape features for registration.
//  2. RegisterMovement: which instant of the example plays at each content
//     frame. Stepping (both clips step): the example's steps at its own
//     cadence scaled by its walk ratio to the content's speed (a slow style
//     walks at the content's speed with more, shorter steps), looped.
//     Gestures (neither steps): dynamic time warping of the hands', elbows'
//     and feet's paths, so the content's gesture still reaches where and
//     when it reached.
//  3. ApplyMovement: the network's output with the legs, the pelvis (its
//     rotation against the facing, its bob and sway) and, as asked, the
//     arms and spine of the example at those instants; the root's path and
//     facing stay the output's. The output's foot contacts are the example's
//     at those instants, for post-processing to plant the feet on.
//
// All clips are on one skeleton with Y up (the model's).
#ifndef STYLUS_MOTION_EXAMPLE_MOTION_H_
#define STYLUS_MOTION_EXAMPLE_MOTION_H_

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/humanoid.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::motion {

inline constexpr double kMaxLoopS = 20;

// A clip read for registration.
struct MovementClip {
  Motion clip;
  HumanoidRoles roles;
  std::vector<LocalPose> poses;
  std::vector<std::vector<Vec3>> positions;  // World, per frame and joint.
  std::vector<double> heading;               // Facing yaw (radians, unwrapped, smoothed).
  std::vector<Vec3> floor_path;              // The pelvis's floor point, smoothed (no sway).
  std::vector<double> speed;                 // Along floor_path, leg lengths per second.
  std::array<std::vector<bool>, 4> contact;  // Per FootJoints order, per frame.
  // Per frame: hands, elbows and ankles relative to the pelvis's floor point
  // in the facing frame, in leg lengths, and the hands' velocities over 0.2 s
  // (what registration compares: a wave's swings are not a raise's hold).
  std::vector<std::vector<double>> shape;
  // Per frame: knees, ankles and toes relative to the pelvis's floor point in
  // the facing frame, the pelvis's height, and their velocities over 0.2 s
  // (what a loop's seam and the first played instant are matched on).
  std::vector<std::vector<double>> gait;
  std::vector<Quat> pelvis_rotation;  // World rotation of the pelvis per frame.
  bool steps = false;                 // It steps (motion/cadence.h) and travels.
  double step_speed = 0;              // Median speed over its stepping part (leg lengths/s).
  double step_period_s = 0;           // Seconds per step.
  double turn_rate = 0;  // Mean heading change per second while stepping (rad/s, + left).
  // Which way it travels while stepping, in its facing frame (a unit vector
  // on the floor: x to its left, z ahead): a walk forward, back or sideways.
  Vec3 travel = {0, 0, 1};
  // The share of its stepping frames with neither foot on the floor: about
  // 0 for a walk, more for a run.
  double flight = 0;
  // A seamless loop of its stepping (at most kMaxLoopS long): frame
  // loop_end looks and moves like loop_begin, so playback wraps from
  // loop_end to loop_begin.
  int loop_begin = 0, loop_end = 0;
  double floor_height = 0;  // The feet's floor: the lowest any foot joint goes.
  // What its arms do, per side (left, right): how far the hand travels up
  // and down (95th minus 5th percentile of its height over the pelvis, leg
  // lengths), and how many times it swings back and forth (turns of its
  // sideways or vertical path by more than kSwing). A raise and a wave of
  // the same hand differ in the swings; a wave of the left hand and of both
  // in the reach.
  std::array<double, 2> hand_reach = {};
  std::array<int, 2> hand_swings = {};
  // How fast the hands travel: the 95th percentile over frames of the faster
  // hand's speed relative to the pelvis's floor point (leg lengths/s).
  double hand_speed = 0;
  // Side by side of the hand chains: [upper arm, forearm, hand] per side.
  std::array<std::array<int, 3>, 2> arms = {};
};

// The bytes a clip's reading holds (its frames, poses, positions and
// features).
size_t MovementClipBytes(const MovementClip& m);

// INVALID_ARGUMENT when the clip is empty, its rig's up axis is not Y, or an
// arm has no forearm and hand below its upper arm.
absl::StatusOr<MovementClip> AnalyzeMovement(const Motion& clip, const HumanoidRoles& roles);

// The least a hand's path turns back by to count as a swing (leg lengths).
inline constexpr double kSwing = 0.06;

// Whether two clips' arms do the same kind of thing: the same hands travel
// (a hand travels when it reaches kActiveReach or more, or at least half of
// the other hand's reach), and each such hand swings back and forth in both
// or in neither (kSwinging or more swings). The reason when not.
inline constexpr double kActiveReach = 0.15;
inline constexpr int kSwinging = 4;
bool SameArmAction(const MovementClip& a, const MovementClip& b, std::string* why = nullptr);

// The pieces of that reading, shared with the streams' follower: whether
// hand `side` travels, given both hands' reach; how many times a path turns
// back by kSwing or more (turning points with hysteresis).
bool HandTravels(const std::array<double, 2>& reach, int side);
int CountSwings(const std::vector<double>& path);

struct Registration {
  enum class Kind { kSteps, kGesture };
  Kind kind = Kind::kGesture;
  // Per content frame: the example's instant (a fractional frame) played there.
  std::vector<double> time;
  // Gesture: the mean distance (leg lengths) of the registered shapes.
  double cost = 0;
  double rate = 1;  // Mean example frames per content frame.
  // Steps: per content frame, the example frames played per content frame
  // (sqrt(content speed / example speed), within RegisterOptions' bounds).
  std::vector<double> step_rate;
};

struct RegisterOptions {
  // Stepping: the playback rate is sqrt(content speed / example speed)
  // (walk ratio kept), within these bounds.
  double min_rate = 0.5, max_rate = 2.0;
  // Gestures: the cost of a warp step that holds one clip while the other
  // moves, against a diagonal step (1: plain dynamic time warping).
  double hold_penalty = 1.5;
};

// FAILED_PRECONDITION, saying which, when one clip steps and the other does
// not (a walk's steps cannot register to a wave).
absl::StatusOr<Registration> RegisterMovement(const MovementClip& content,
                                              const MovementClip& example,
                                              const RegisterOptions& options = {});

// Where each part of the output's body comes from.
enum class PartSource {
  kNetwork,  // The network's output as it is.
  kExample,  // The example's local rotations.
  kLayer,    // The network's posture (its rotations smoothed over ~0.5 s) with
             // the example's movement about its own posture on top.
};
// "network", "example", "layer"; INVALID_ARGUMENT otherwise.
absl::StatusOr<PartSource> ParsePartSource(absl::string_view name);
const char* PartSourceName(PartSource source);

struct MovementOptions {
  PartSource legs = PartSource::kExample;   // Hips and everything below them.
  PartSource arms = PartSource::kLayer;     // Clavicles, arms, hands.
  PartSource spine = PartSource::kNetwork;  // Spine, chest, neck, head.
  bool pelvis = true;  // The pelvis's rotation against the facing, bob and sway.
  // Stepping: the ankles' reach ahead of and behind the pelvis scaled so a
  // stride covers the content's path at the played cadence (two-bone IK).
  bool fit_stride = true;
  double posture_s = 0.5;  // kLayer: the posture's smoothing (Gaussian sigma, s).
};

struct MovementResult {
  Motion motion;
  // The output's own foot contacts (FootJoints order): the example's at the
  // registered instants.
  std::array<std::vector<ContactSpan>, 4> contacts;
};

// `network`: the network's transfer of `content` (same skeleton and frame
// count). INVALID_ARGUMENT when the clips do not match.
absl::StatusOr<MovementResult> ApplyMovement(const Motion& network, const MovementClip& content,
                                             const MovementClip& example,
                                             const Registration& registration,
                                             const MovementOptions& options = {});

// Per joint, where ApplyMovement takes it from (the pelvis is handled apart).
std::vector<PartSource> PartSources(const Skeleton& skeleton, const HumanoidRoles& roles,
                                    const MovementOptions& options);

// Small geometry shared with the streams' follower: a point on the floor
// (Y up), a world offset in the frame facing `yaw` (x left, z ahead), the
// squared distance of two feature vectors of one length.
Vec3 OnFloor(const Vec3& p);
Vec3 InFacing(const Vec3& v, double yaw);
double SquaredDistance(const std::vector<double>& a, const std::vector<double>& b);

// Where one output frame plays the example (ApplyMovement per frame; the
// streams' MovementFollower, motion/live_movement.h).
struct FramePlacement {
  double time = 0;     // The example's instant (a fractional frame).
  double heading = 0;  // The output's facing (yaw, radians).
  Vec3 floor_point;    // The output's pelvis floor point, without sway.
  double floor = 0;    // The content's floor height.
  // Stepping: the ankles' reach ahead of and behind the pelvis scaled by
  // stride_scale (MovementOptions::fit_stride).
  bool fit_stride = false;
  double stride_scale = 1;
};
// kLayer: the network's posture at this frame and the example's per frame.
struct FrameLayer {
  const std::vector<Quat>* network = nullptr;
  const std::vector<std::vector<Quat>>* example = nullptr;
};
// `network` with the parts `source` names taken from `example` at
// `at.time`, the pelvis (when `pelvis`) turned and placed on the output's
// path, the stride fitted and no foot below the floor when the legs are the
// example's. kLayer without `layer` plays the example's rotations.
LocalPose MoveFrame(const Skeleton& skeleton, const HumanoidRoles& roles, const MovementClip& example,
                    const std::vector<PartSource>& source, bool pelvis, const LocalPose& network,
                    const FramePlacement& at, const FrameLayer* layer = nullptr);

// Frames [begin, end) per foot joint from per-frame contact flags; spans
// shorter than `min_frames` are dropped.
std::array<std::vector<ContactSpan>, 4> SpansFromFlags(
    const std::array<std::vector<bool>, 4>& flags, int min_frames);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_EXAMPLE_MOTION_H_
