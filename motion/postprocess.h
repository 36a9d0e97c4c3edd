// Post-processing of generated motion, what animators check first: planted
// feet (contact spans of the content clip, foot locking with two-bone leg IK),
// bone lengths equal to the skeleton's offsets, and continuous Euler angles.
// docs/postprocess.md explains the choices.
#ifndef STYLUS_MOTION_POSTPROCESS_H_
#define STYLUS_MOTION_POSTPROCESS_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/motion.h"

namespace stylus::motion {

// none: the network's output as is; feet: foot locking; full: feet, bone
// lengths and Euler continuity.
enum class PostProcessMode { kNone, kFeet, kFull };
// "none", "feet", "full"; INVALID_ARGUMENT otherwise.
absl::StatusOr<PostProcessMode> ParsePostProcessMode(absl::string_view name);
const char* PostProcessModeName(PostProcessMode mode);

// Contact thresholds, in leg lengths (so they hold at any scale) and seconds
// (so they hold at any frame rate). A foot joint enters contact when it is
// within `height_on` of its floor and slower than `speed_on` (horizontal),
// and leaves it only when above `height_off` or faster than `speed_off`
// (hysteresis); spans shorter than `min_span_s` are dropped.
struct ContactSpanParams {
  double height_on = 0.05, height_off = 0.07;
  double speed_on = 0.5, speed_off = 0.7;
  double min_span_s = 0.1;
};

struct ContactSpan {
  int begin = 0, end = 0;  // Frames [begin, end).
};

// Spans per foot joint, in FootJoints order (left ankle, left toe, right
// ankle, right toe). `positions`: frames x joints world positions, Y up. A
// joint's floor is its lowest height in `positions`.
std::array<std::vector<ContactSpan>, 4> DetectContactSpans(
    absl::Span<const std::vector<Vec3>> positions, const HumanoidRoles& roles, double fps,
    const ContactSpanParams& params = {});

struct PostProcessParams {
  ContactSpanParams contacts;
  // `full` first smooths every joint's local rotation over +-this many frames
  // (triangle weights): generated rotations carry frame-to-frame noise.
  int smooth_radius = 2;
  double blend_s = 0.1;  // Locks blend in and out over this long (smoothstep).
  // The leg solve's soft reach, in leg lengths (motion/ik.h): a stance leg
  // near full stretch eases towards its pin instead of snapping straight.
  double soft_reach = 0.02;
  // Where a locked foot is pinned: the mean of its span (offline), or, for
  // streaming, where it is at the span's first frame (known without waiting
  // for the span's end).
  bool pin_at_span_start = false;
  // The contacts to plant, when the caller knows them (a transfer whose
  // steps are its own, motion/example_motion.h); else they are detected on
  // the content clip.
  const std::array<std::vector<ContactSpan>, 4>* contact_spans = nullptr;
};

// The two-bone solve for one leg with toes following is applied to every frame
// where a foot of `output` is locked, and no foot is left below the content's
// floor (KeepFeetAboveFloor). `content` decides the contacts (it may
// have more frames than `output`, e.g. look-ahead in a stream; frame i of
// both is the same instant). The root and everything above the hips keep
// their values; frame count and channel layout are unchanged. INVALID_ARGUMENT
// when the clips' skeletons differ in topology, or the legs are not
// hip -> knee -> ankle -> toe chains.
absl::StatusOr<Motion> PostProcess(const Motion& output, const Motion& content,
                                   const HumanoidRoles& roles, PostProcessMode mode,
                                   const PostProcessParams& params = {});

// A foot's contact as a stream's cleaner carries it from call to call: a
// frame of the contact (an index into the call's frames, negative before
// them) and where the foot is pinned.
struct ContactPin {
  int frame = 0;
  Vec3 pin;
};
using ContactPins = std::array<std::optional<ContactPin>, 4>;  // FootJoints order.

// PostProcess on poses, for callers that keep poses from call to call (a
// stream's cleaner converts each frame from and to Euler angles once, not
// once per call). `output`: the output's local poses; `content_positions`:
// the content's world positions (frames x joints, at least as many frames);
// both at `fps`. Returns the cleaned poses of frames [first_kept, n): the
// frames before it are read (smoothing, pins, the knees' hinges) but not
// returned. The skeleton checks of PostProcess are the caller's.
// `pins`, when given: on the way in, contacts seen by the previous call (a
// contact span holding its frame keeps that pin, however far back the span
// began); on the way out, each foot's last contact span in these frames
// (none: nullopt). Without it a span that began before the first frame is
// pinned where it is at the first frame, which drifts as a stream's history
// window slides along a long contact.
// `posed`, when given (a stream's history): on the way in, the world poses of
// frames [0, first_kept) as this function posed them when they were new
// (smoothed, before the feet were locked); those frames are final, so they are
// read (as the new frames' smoothing neighbours, for pins and hinges) but
// neither smoothed nor posed again. On the way out (modes other than none),
// the same for every frame. INVALID_ARGUMENT when its size is not first_kept.
absl::StatusOr<std::vector<LocalPose>> PostProcessPoses(
    const Skeleton& skeleton, const HumanoidRoles& roles, std::vector<LocalPose> output,
    absl::Span<const std::vector<Vec3>> content_positions, double fps, PostProcessMode mode,
    const PostProcessParams& params = {}, int first_kept = 0, ContactPins* pins = nullptr,
    std::vector<GlobalPose>* posed = nullptr);

// The leg above `ankle` turned so the ankle reaches `target` (two-bone IK
// from the hip; `posed` is `pose` posed), the foot's world orientation kept.
void PlaceAnkle(const Skeleton& skeleton, const GlobalPose& posed, int ankle, const Vec3& target,
                LocalPose* pose);

// Each leg whose ankle or toe is below `floor` (a height, Y up) in `pose`
// is bent up by the depth (two-bone IK at the ankle, the foot's world
// orientation kept): no foot under the floor. PostProcess applies it to
// every frame with the content's floor (the lowest its foot joints go).
void KeepFeetAboveFloor(const Skeleton& skeleton, const HumanoidRoles& roles, double floor,
                        LocalPose* pose);

// Position channels of every joint below the pelvis set to its offset (its
// bone length and direction at rest).
void RestoreBoneLengths(Motion* motion, const HumanoidRoles& roles);

// Replaces each non-root joint's local rotation by the triangle-weighted mean
// of its rotations over [f - radius, f + radius] (quaternions aligned to one
// hemisphere, renormalized). Translations are kept.
void SmoothRotations(Motion* motion, int radius);
// The same on poses; frames before `first` keep their rotations (they are
// still read as their neighbours').
void SmoothPoses(const Skeleton& skeleton, std::vector<LocalPose>* poses, int radius,
                 int first = 0);

// Rewrites every rotation as the Euler angles, in the joint's own order,
// nearest to the previous frame's: the same rotations without 360-degree (or
// gimbal-flip) jumps.
void MakeEulerContinuous(Motion* motion);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_POSTPROCESS_H_
