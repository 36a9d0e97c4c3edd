// The motion-only style judge: a style classifier that sees how the body
// moves and not how it poses. Its input is, per frame, the velocity of every
// joint relative to the character root in the root's facing frame, and the
// root's own planar velocity, yaw rate and vertical velocity: no positions,
// no rotations, no foot contacts. A clip held still on any one of its frames
// is all zeros to it, so it can read style only from gait, rhythm and
// amplitude. It sits beside the pose-reading judges (eval/judges.h) in the
// same directory: motion_style.pt, motion_norm.txt and motion.txt.
#ifndef STYLUS_EVAL_MOTION_JUDGE_H_
#define STYLUS_EVAL_MOTION_JUDGE_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "eval/judges.h"
#include "motion/features.h"
#include "motion/motion.h"

namespace stylus::model {

// The judge's channels from a clip's features (motion/features.h, not
// normalized): per second, each joint's change of position relative to the
// root, in its facing frame, from frame t to t + 1 (the last frame repeats
// the one before; 0 for joints above the pelvis, which the trajectory
// covers), then the root trajectory's four velocities. frames x (3J + 4).
motion::FeatureClip MotionChannels(const motion::FeatureClip& features,
                                   const motion::Skeleton& skeleton,
                                   const motion::HumanoidRoles& roles, double frame_time);

// `clip` held still: every frame is its middle frame.
motion::Motion Frozen(const motion::Motion& clip);

struct MotionJudgeAccuracy {
  double held_out = 0;  // Clip-level style accuracy on real held-out clips.
  double frozen = 0;    // The same on those clips frozen (Frozen): about chance.
  // What a judge that reads nothing scores at best: the share of the
  // commonest style among the held-out clips.
  double chance = 0;
  int clips = 0;
};

// Trains the motion-only style judge on the labelled training split of
// `options.data` (options.iterations, batch, lr, seed, random_starts) and
// writes it into `options.out` (with the data files when the directory has
// none yet).
absl::StatusOr<MotionJudgeAccuracy> TrainMotionJudge(const JudgeTrainOptions& options);

class MotionJudge {
 public:
  // NOT_FOUND when `dir` has no motion judge; INVALID_ARGUMENT for malformed
  // files.
  static absl::StatusOr<std::unique_ptr<MotionJudge>> Load(const std::string& dir);
  ~MotionJudge();

  const std::vector<std::string>& styles() const;
  // Held-out and frozen-clip accuracy recorded when it was trained.
  const MotionJudgeAccuracy& trained_accuracy() const;
  // Index into styles() of the clip's most likely style. INVALID_ARGUMENT
  // for a clip on another skeleton or frame rate. Thread-safe.
  absl::StatusOr<int> ClassifyStyle(const motion::Motion& clip) const;
  absl::StatusOr<std::vector<double>> StyleProbabilities(const motion::Motion& clip) const;

 private:
  struct Impl;
  explicit MotionJudge(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_EVAL_MOTION_JUDGE_H_
