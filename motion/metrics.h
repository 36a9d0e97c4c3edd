// Kinematic quality metrics of a clip, none of which needs a model or a
// dataset: what an animator checks first (feet, bones, smoothness, path).
// Lengths are in the clip's units (Bandai: centimetres), times in seconds.
#ifndef STYLUS_MOTION_METRICS_H_
#define STYLUS_MOTION_METRICS_H_

#include <array>
#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/humanoid.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::motion {

// Mean horizontal speed (units/s) of the foot joints while in contact, with
// contacts (motion/postprocess.h DetectContactSpans) detected on `reference` (the clip whose feet should be planted:
// for a transfer, its content clip). Both on the same skeleton topology; only
// the frames both have are used. 0 when no foot is in contact.
double FootSkating(const Motion& clip, const Motion& reference, const HumanoidRoles& roles);

// The same with the contacts given: spans per foot joint (FootJoints order),
// e.g. the ones a transfer planted its feet on.
double FootSkatingOnSpans(const Motion& clip, const std::array<std::vector<ContactSpan>, 4>& spans,
                          const HumanoidRoles& roles);

// Mean height (units) of contact feet above the floor of `reference` (the
// lowest height each foot joint reaches in it), contacts from `reference`.
double FootHeightError(const Motion& clip, const Motion& reference, const HumanoidRoles& roles);

// Mean relative difference between each bone's length in the posed clip and
// its length in the skeleton's offsets (0.001 = 0.1%), over frames and the
// bones below the pelvis (the pelvis's own translation is motion, not a bone)
// of non-zero length.
double BoneLengthError(const Motion& clip, const HumanoidRoles& roles);

// Mean magnitude of the third time derivative of joint world positions
// (units/s^3) over joints and frames: high-frequency shake.
double Jitter(const Motion& clip);

// Mean horizontal distance (units) between the pelvis paths of two clips over
// the frames both have.
double TrajectoryError(const Motion& clip, const Motion& reference, const HumanoidRoles& roles);

// The largest change of any Euler channel between consecutive frames, in
// degrees (a jump > 90 means a discontinuity).
double MaxEulerStep(const Motion& clip);

// Joint-frames where an Euler channel steps by more than 90 degrees while the
// joint's rotation itself turns by less than 45 degrees: jumps of the
// representation (wrapping, flipped branches), not of the motion.
int EulerDiscontinuities(const Motion& clip);

// Every metric above that the given clips allow, by name: "foot_skating",
// "foot_height_error", "trajectory_error" need `reference` (may be null: then
// they are measured against `clip` itself where that makes sense);
// "bone_length_error", "jitter", "max_euler_step_deg", "euler_discontinuities"
// need only `clip`.
// INVALID_ARGUMENT when the clip has no frames, is not a humanoid, or the
// reference has another topology.
absl::StatusOr<std::map<std::string, double>> ComputeMetrics(const Motion& clip,
                                                             const Motion* reference);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_METRICS_H_
