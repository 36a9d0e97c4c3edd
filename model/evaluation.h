// Evaluation of a style-transfer model on held-out Bandai pairs against two
// baselines: identity (output = content clip) and copy-style (output = style
// clip). Torch-free: it drives the model and the judges through their APIs.
#ifndef STYLUS_MODEL_EVALUATION_H_
#define STYLUS_MODEL_EVALUATION_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/contrastive_model.h"
#include "model/judges.h"

namespace stylus::model {

struct EvalPair {
  std::string content_path, style_path;
};

// Deterministic pairs from the held-out split of `dirs`: for every held-out
// clip as content, up to `per_content` held-out style clips of another content
// and another style, chosen by a stable hash of both names.
absl::StatusOr<std::vector<EvalPair>> MakeEvalPairs(const std::vector<std::string>& dirs,
                                                    int per_content);

// Kinematic metrics (motion/metrics.h) are measured against the clip whose
// feet should be planted: the content clip, or for copy-style the style clip.
struct EvalRow {
  std::string name;
  double style_accuracy = 0;    // Judged style == the style clip's style.
  double content_accuracy = 0;  // Judged content == the content clip's content.
  double foot_skating = 0;      // Mean horizontal foot speed in contact (units/s).
  double foot_height_error = 0;  // Mean height of contact feet above their floor (units).
  double bone_length_error = 0;  // Mean relative bone length error.
  double jitter = 0;             // Mean jerk (units/s^3).
  int euler_discontinuities = 0;  // Summed over all pairs.
  int pairs = 0;
};

struct EvalReport {
  // Model without post-processing, model with `full` post-processing,
  // identity (the content clips: real data), copy-style (the style clips).
  std::vector<EvalRow> rows;
  std::string Markdown() const;
};

// Runs the model over every pair; `progress(done, total)` may be empty.
absl::StatusOr<EvalReport> Evaluate(const ContrastiveModel& model, const Judges& judges,
                                    const std::vector<EvalPair>& pairs,
                                    const std::function<void(int, int)>& progress = {});

}  // namespace stylus::model

#endif  // STYLUS_MODEL_EVALUATION_H_
