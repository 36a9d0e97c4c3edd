// Judges: classifiers trained on real labelled clips, used by evaluation to
// tell whether a transfer carries the style clip's style and keeps the content
// clip's content (the field's recognition accuracies).
#ifndef STYLUS_EVAL_JUDGES_H_
#define STYLUS_EVAL_JUDGES_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::model {

struct JudgeTrainOptions {
  std::vector<std::string> data;  // Labelled dataset directories.
  std::string out;                // e.g. models/judges/v1
  int iterations = 3000;
  int batch = 32;
  double lr = 1e-3;
  uint64_t seed = 1;
  // With `random_starts`, each drawn window starts anywhere in its clip
  // instead of on the hop grid, so the judges also learn the clips' last
  // frames, which evaluation's end-aligned window shows them (a 78-frame
  // clip's grid windows stop at frame 56).
  bool random_starts = false;
  // With probability `swap_parts` a drawn window gets one body part (legs,
  // torso or an arm; motion/splice.h) from another drawn window with the
  // same label (the content judge: the same action; the style judge: the
  // same style). A content judge learns to read the action from whatever
  // the body does, not from one take's way of doing the rest: v1's verdicts
  // fall from 0.968 to 0.70-0.83 on real clips given one body part of the
  // same action in another style (`stylus-tool judge --swap-test`;
  // docs/notes/contrastive.md).
  double swap_parts = 0;
  std::function<void(const std::string&)> log;  // Default: stderr.
};

struct JudgeAccuracy {
  double style = 0, content = 0;  // Clip-level accuracy on the held-out split.
  int clips = 0;
};

// Trains the style and the content classifier on the training split, writes
// them to `out` and returns their held-out accuracy.
absl::StatusOr<JudgeAccuracy> TrainJudges(const JudgeTrainOptions& options);

class Judges {
 public:
  // NOT_FOUND / INVALID_ARGUMENT as for model packages.
  static absl::StatusOr<std::unique_ptr<Judges>> Load(const std::string& dir);
  ~Judges();

  const std::vector<std::string>& styles() const;
  const std::vector<std::string>& contents() const;
  // Index into styles() / contents() of the most likely label of a clip
  // (logits averaged over its windows). INVALID_ARGUMENT for a clip on another
  // skeleton or frame rate. Thread-safe.
  absl::StatusOr<int> ClassifyStyle(const motion::Motion& clip) const;
  absl::StatusOr<int> ClassifyContent(const motion::Motion& clip) const;
  // The softmax of the clip's mean logits, one probability per label of
  // styles() / contents(): how sure the judge is, and of what else.
  absl::StatusOr<std::vector<double>> StyleProbabilities(const motion::Motion& clip) const;
  absl::StatusOr<std::vector<double>> ContentProbabilities(const motion::Motion& clip) const;

 private:
  struct Impl;
  explicit Judges(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_EVAL_JUDGES_H_
