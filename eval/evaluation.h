// Evaluation of a style-transfer model on held-out Bandai pairs against two
// baselines: identity (output = content clip) and copy-style (output = style
// clip). Torch-free: it drives the model and the judges through their APIs.
#ifndef STYLUS_EVAL_EVALUATION_H_
#define STYLUS_EVAL_EVALUATION_H_

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "eval/feature_judge.h"
#include "eval/judges.h"
#include "eval/motion_judge.h"
#include "model/style_model.h"

namespace stylus::model {

struct EvalPair {
  std::string content_path, style_path;
};

// Which pairs: the style clip doing another action than the content clip
// (cross-action), or the same action in another take (same-action).
enum class PairKind { kCrossAction, kSameAction };
// Which held-out content clips: all, or one of two halves by a stable hash
// of the file name: validation (settings are chosen on it) and test
// (figures are reported on it, never chosen on).
enum class EvalSplit { kAll, kValidation, kTest };
// "cross-action", "same-action"; "all", "validation", "test".
absl::StatusOr<PairKind> ParsePairKind(absl::string_view name);
absl::StatusOr<EvalSplit> ParseEvalSplit(absl::string_view name);
const char* PairKindName(PairKind kind);
const char* EvalSplitName(EvalSplit split);
// Whether a held-out content clip (by file name) is in `split`.
bool InEvalSplit(const std::string& path, EvalSplit split);

// Deterministic pairs from the held-out split of `dirs`: for every held-out
// clip as content (in `split`), up to `per_content` held-out style clips of
// another style and, by `kind`, another action (another label) or the same
// one (the same label in the same dataset), chosen by a stable hash of both
// names.
absl::StatusOr<std::vector<EvalPair>> MakeEvalPairs(const std::vector<std::string>& dirs,
                                                    int per_content,
                                                    PairKind kind = PairKind::kCrossAction,
                                                    EvalSplit split = EvalSplit::kAll);

// Kinematic metrics (motion/metrics.h) are measured against the clip whose
// feet should be planted: the content clip, or for copy-style the style clip.
struct EvalRow {
  std::string name;
  double style_accuracy = 0;      // Judged style == the style clip's style.
  double content_accuracy = 0;    // Judged content == the content clip's content.
  double foot_skating = 0;        // Mean horizontal foot speed in contact (units/s).
  double foot_height_error = 0;   // Mean height of contact feet above their floor (units).
  double bone_length_error = 0;   // Mean relative bone length error.
  double jitter = 0;              // Mean jerk (units/s^3).
  int euler_discontinuities = 0;  // Summed over all pairs.
  // Feature-judge metrics (when a feature judge is given): distribution
  // distances of the outputs to real clips, their diversity, and the mean
  // distances to the pair's content (features) and style (Gram matrices).
  double fmd = 0, kid = 0, kid_std = 0, diversity = 0;
  double content_distance = 0, style_distance = 0;
  // Paper 004's style similarity ratios (eq. 16-17), per pair then averaged:
  // with D_style and D_content the Gram (style) distances of the output to
  // the style clip and to the content clip, D_S = D_style / (D_style +
  // D_content) (low: the output's style is the style clip's) and D_C = 1 - D_S.
  double d_s = 0, d_c = 0;
  double trajectory_error = 0;  // Mean pelvis path distance to the content's (units).
  // With second judges: their accuracies, and the share of pairs whose
  // content both sets recognized (either set: the two accuracies minus it).
  double second_style_accuracy = 0, second_content_accuracy = 0, content_by_both = 0;
  // Style verdicts on what the content clip was: the pose judge's and the
  // motion-only judge's (eval/motion_judge.h) share of pairs judged as the
  // content clip's own style, and the motion judge's share judged as the
  // style clip's.
  double source_style = 0;
  double motion_style_accuracy = 0, motion_source_style = 0;
  double ContentByEither() const {
    return content_accuracy + second_content_accuracy - content_by_both;
  }
  int pairs = 0;
  // A model row of a model with a content guard (model/content_guard.h): how
  // many transfers it checked, and of those, how many it backed off to the
  // residual form at each strength (the full row post-processes these).
  int guarded = 0;
  std::map<double, int> backed_off_at = {};
  // A model row with style timing: the transfers time-warped to the style's
  // cadence, and their mean ratio (output duration / content duration).
  int time_warped = 0;
  double time_warp_ratio = 0;
  // Gait (motion/gait.h) over the pairs whose content and style clips both
  // step (walks, runs): for each figure (kGaitFigures), how far the output
  // moved from the content clip's value towards the style clip's, as the
  // median over pairs of (output - content) / (style - content), clamped to
  // [-1, 2] (0: the content's, 1: the style's), and over how many pairs:
  // those whose two clips differ by 10% or more in that figure.
  std::array<double, 5> gait_toward_style = {};
  std::array<int, 5> gait_pairs = {};
  // The same over the pairs whose clips both do not step (gestures), for
  // kGestureFigures: how fast the hands travel and how far they reach.
  std::array<double, 2> gesture_toward_style = {};
  std::array<int, 2> gesture_pairs = {};
  // A model row whose package takes movement from examples: the transfers
  // that got it, and of those, how many from a library take.
  int moved = 0, moved_from_library = 0;
  // Foot skating as above, measured on the contacts the output planted
  // where its steps are its own (movement from examples), else as above.
  double own_skating = 0;
  // The lowest any foot joint goes below the measured clip's floor, in leg
  // lengths (the deepest over the pairs; 0: never below).
  double below_floor = 0;
};

// The gait figures of EvalRow::gait_toward_style, in order.
inline constexpr const char* kGaitFigures[5] = {"step period", "stride", "foot lift",
                                                "arm swing", "bob"};

// The gesture figures of EvalRow::gesture_toward_style, in order
// (motion/example_motion.h MovementClip::hand_speed and hand_reach).
inline constexpr const char* kGestureFigures[2] = {"hand speed", "hand reach"};

// A model to evaluate; `postprocess` adds a second row with `full`
// post-processing. With `own_style`, each content clip is restyled with its
// own style code instead of the style clip's: what the model keeps of a clip
// it should give back unchanged (its ceiling on content accuracy). With
// `style_timing`, transfers take the style clip's cadence (Timing::kStyle;
// post-processing and the feet are measured against the content played at
// the same speed), and a further row is the content itself played at the
// style's cadence: what the time warp alone does.
struct EvalModel {
  std::string name;
  const StyleModel* model = nullptr;
  bool postprocess = false;
  bool own_style = false;
  bool style_timing = false;
  // Movement from examples: the library (may be null) and whether the
  // library's style is the style clip's label (else the nearest by code).
  const StyleLibrary* library = nullptr;
  bool label_from_name = true;
  // Transfers go through a stream, one frame per push as a stage sends them
  // (StyleModel::OpenStream), post-processed by the stream itself.
  bool stream = false;
};

// What the judges said about one output of one pair.
struct EvalVerdict {
  int pair = 0;                   // Index into the evaluated pairs.
  int row = 0;                    // Index into EvalReport::rows.
  std::string style, content;     // Judged labels.
  std::string motion_style = {};  // By the motion-only judge (when there is one).
  // Movement from examples: the example the movement came from ("style
  // clip" or a library take), or why there was none.
  std::string movement = {};
};

struct EvalReport {
  // Each model's rows (no post-processing; then `full` if asked), identity
  // (the content clips: real data), copy-style (the style clips).
  std::vector<EvalRow> rows;
  int identity_row = -1;
  double real_diversity = 0;  // Of the reference clips (with a feature judge).
  int reference_clips = 0;
  bool second_judges = false;                // The rows' second_* and content_by_* are set.
  bool motion_judge = false;                 // The rows' motion_* are set.
  MotionJudgeAccuracy motion_judge_trained;  // What the motion judge scored when trained.
  std::vector<EvalVerdict> verdicts;         // Every row's verdict on every pair (first judges).
  std::string Markdown() const;
  // One line per pair and row: content_bvh, style_bvh, output, wanted and
  // judged style and content (where a transfer goes wrong, and into what).
  std::string VerdictsCsv(const std::vector<EvalPair>& pairs) const;
  // Every row's style / content accuracy over the pairs whose content clip
  // comes from each dataset (the "dataset-N" of its name), then over the
  // pairs whose two clips come from one dataset and from two (Markdown).
  // Bandai's two datasets share few labels, so where a model loses content
  // depends on which (docs/notes/contrastive.md).
  std::string ByDatasetMarkdown(const std::vector<EvalPair>& pairs) const;
  // Every row's style accuracy per target style: the pose judge's, and the
  // motion-only judge's when there is one (Markdown).
  std::string ByStyleMarkdown(const std::vector<EvalPair>& pairs) const;
};

// Runs every model over every pair. With `features` (may be null), FMD and KID
// compare each row's outputs with `reference` (real clips, e.g. all of the
// dataset). `progress(done, total)` may be empty. With `second_judges`
// (may be null), every output is also judged by them: on transfers, judges
// trained alike disagree far more often than on real clips, so a verdict
// near their boundary is worth a second opinion (docs/notes/contrastive.md).
// With `motion_judge` (may be null), every output's style is also read by the
// motion-only judge.
absl::StatusOr<EvalReport> Evaluate(const std::vector<EvalModel>& models, const Judges& judges,
                                    const FeatureJudge* features,
                                    const std::vector<motion::Motion>& reference,
                                    const std::vector<EvalPair>& pairs,
                                    const std::function<void(int, int)>& progress = {},
                                    const Judges* second_judges = nullptr,
                                    const MotionJudge* motion_judge = nullptr);

}  // namespace stylus::model

#endif  // STYLUS_EVAL_EVALUATION_H_
