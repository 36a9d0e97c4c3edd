// What every model family serves: encode a style, transfer it onto a content
// clip of any length, interpolate between styles, stream. The server, the
// offline tool and the evaluation drive models through this interface only;
// model/family_registry.h loads a package with the family its config.txt
// names.
//
// A family implements EncodeStyle, PrepareTransfer (the transfer of one clip
// in the forms the content guard may choose from) and, when it streams in its
// own way, OpenStream. The content guard's loop and the post-processing are
// this class's, the same for every family.
//
// Thread-safety: after loading, all const methods may be called concurrently.
#ifndef STYLUS_MODEL_STYLE_MODEL_H_
#define STYLUS_MODEL_STYLE_MODEL_H_

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "model/config_text.h"
#include "model/frame_streamer.h"
#include "model/movement.h"
#include "model/package.h"
#include "motion/cadence.h"
#include "motion/motion.h"
#include "motion/postprocess.h"
#include "motion/retarget.h"

namespace stylus::model {

class ContentGuard;

// A style vector from EncodeStyle; style codes of one model can be blended
// linearly.
struct StyleCode {
  std::vector<float> values;
  // The style clip's cadence (motion/cadence.h); none when its motion does
  // not repeat (EncodeStyle fills it in).
  std::optional<motion::Cadence> cadence = std::nullopt;
  // The style clip on the model's skeleton and rate, read for movement from
  // examples (model/movement.h); EncodeStyle fills it in.
  std::shared_ptr<const motion::MovementClip> example = nullptr;
  // The example's action as the package's content guard reads it (a
  // probability per action), when its movement is gated by action
  // (MovementKeys::movement_action_gate); empty otherwise.
  std::vector<double> example_actions = {};
};

// How styles mix over a clip: `fixed` (one weight per style) for the whole clip,
// or `per_frame` (one row of weights per content frame) when not empty.
struct StyleWeights {
  std::vector<double> fixed;
  std::vector<std::vector<double>> per_frame;
};

// How a model's content guard (GuardKeys, model/config_text.h) treated one
// whole-clip transfer.
struct TransferNote {
  bool guarded = false;          // The transfer went through a content guard.
  bool backed_off = false;       // It read another action in the configured transfer...
  double residual_strength = 1;  // ...and returned the weaker form at this strength,
  bool last_form = false;        // the last one it tries (returned even if it fails too).

  // The note of a guarded transfer that returned form `step` (0: the
  // configured one, k: strengths[k - 1]).
  static TransferNote Guarded(size_t step, const std::vector<double>& strengths) {
    return {true, step > 0, step > 0 ? strengths[step - 1] : 1, step == strengths.size()};
  }
};

// A transfer's motion and what the content guard did to it.
// Whose timing a transfer keeps: the content's (frame for frame), or the
// style clip's cadence, by a uniform time warp of the output.
enum class Timing { kContent, kStyle };

// What Timing::kStyle did.
struct TimeWarpNote {
  bool applied = false;
  double ratio = 1;  // Output duration / content duration.
  // The content's period (its strongest), and the style's at the same
  // harmonic (content_period_s x ratio).
  double content_period_s = 0, style_period_s = 0;
  std::string reason;  // Why no warp was applied (when not applied).
  // Per output frame, the content instant (seconds) it plays (when applied).
  std::vector<double> content_time_s;
};

struct TransferResult {
  motion::Motion motion;
  TransferNote note;
  TimeWarpNote warp;
  MovementNote movement;
  // With movement from examples: the output's own foot contacts, the ones
  // post-processing planted (FootJoints order, the output's frames).
  using Contacts = std::array<std::vector<motion::ContactSpan>, 4>;
  std::optional<Contacts> contacts;
};

class PassBatcher;

struct TransferOptions {
  // Implicit, so that a post-processing mode alone is a set of options.
  TransferOptions(motion::PostProcessMode post = motion::PostProcessMode::kFull)  // NOLINT
      : post(post) {}
  motion::PostProcessMode post;
  // With a guarded package: false returns the configured form without
  // asking the guard (as streams do; docs/service.md).
  bool content_guard = true;
  // When set, the transfer's network passes may run in one forward with
  // those of concurrent transfers (model/pass_batcher.h); families whose
  // passes cannot batch run alone.
  PassBatcher* batcher = nullptr;
  // Roles of the content clip's joints the role finder should not guess,
  // for a clip on another rig than the model's (motion/rig_roles.h).
  motion::JointMap joint_map = {};
  // Timing::kStyle: the output, post-processed, is played slower or faster
  // by the ratio of the style's cadence to the content's (within
  // [kMinTimeWarp, kMaxTimeWarp]), so it has another length. When either has
  // no cadence the output keeps the content's timing and the note says why.
  Timing timing = Timing::kContent;
  // An exact output length (frames at the content's rate; 0: none): the
  // content is played at the pace that fills it, within [kMinTimeWarp,
  // kMaxTimeWarp] of its own length (INVALID_ARGUMENT outside).
  int fit_frames = 0;
  // With a package whose movement comes from examples (MovementKeys): false
  // keeps the network's; `movement.library` adds a style library's takes to
  // the style clip as examples.
  bool movement_from_examples = true;
  MovementRequest movement = {};
};

inline constexpr double kMinTimeWarp = 0.5, kMaxTimeWarp = 2.0;

// What every package says of itself, whatever its family (config.txt).
struct ModelSummary {
  std::string family;
  int window = 0, hop = 0;  // Training windows (frames).
  int dim = 0;              // Feature channels (motion/features.h).
  int trained_iterations = 0;
  // Live packages stream frame by frame, each output frame final once
  // `lookahead` more input frames have arrived (0 for offline packages).
  bool live = false;
  int lookahead = 0;
  // Multiply-adds of the networks per live step (one frame); 0 for
  // packages that do not stream frame by frame.
  int64_t step_macs = 0;
};

// A stream's fixed settings: the style, the skeleton and frame rate of the
// frames that will arrive, and their post-processing.
struct StreamSpec {
  StyleCode style;
  motion::Skeleton skeleton;
  double frame_time = 1.0 / 30;
  motion::PostProcessMode post = motion::PostProcessMode::kFull;
  // For frames on another rig than the model's (motion/rig_roles.h).
  motion::JointMap joint_map = {};
  // Live packages whose movement comes from examples: where the stream's
  // takes come from besides `style.example` (ChooseStreamExamples).
  MovementRequest movement = {};
};

// `content` (on any rig, at any served rate) played through a stream of
// `model` one frame per push, as a stage sends it, with `code`'s style;
// the frames returned, in order. `contacts`, when given, gets the output's
// own foot contacts when its steps are its own (movement from examples; the
// content's where its feet follow the content's), else nullopt. `model`
// must be owned by a std::shared_ptr.
absl::StatusOr<motion::Motion> StreamClip(
    const StyleModel& model, const motion::Motion& content, const StyleCode& code,
    motion::PostProcessMode post, const MovementRequest& movement = {},
    std::optional<std::array<std::vector<motion::ContactSpan>, 4>>* contacts = nullptr);

class StyleModel : public std::enable_shared_from_this<StyleModel> {
 public:
  virtual ~StyleModel();

  virtual const std::string& dir() const = 0;
  // The skeleton, frame rate and feature statistics input clips must match.
  virtual const DataFiles& data() const = 0;
  virtual ModelSummary summary() const = 0;
  // Values in each of this model's style codes.
  virtual int code_size() const = 0;

  // A clip at another frame rate than the model's (24-240 Hz) is resampled
  // to it first (motion/resample.h). INVALID_ARGUMENT for a clip the model
  // cannot take (another skeleton, a rate outside 24-240 Hz, non-finite
  // values, no frames); INTERNAL when LibTorch fails.
  // A clip on another humanoid rig than the model's is retargeted onto the
  // model's skeleton first (motion/retarget.h; `joint_map` fixes roles).
  absl::StatusOr<StyleCode> EncodeStyle(const motion::Motion& clip,
                                        const motion::JointMap& joint_map = {}) const;

  // The content clip re-generated with a blend sum_k w_k s_k of `styles`,
  // fixed or per frame: same skeleton, channel layout, frame count and frame
  // rate, the root starting where the content's does, cleaned by
  // `options.post` (motion/postprocess.h). With a content guard, the first of
  // the package's forms whose action reads as the content's (the note says
  // which). Content at another frame rate than the model's (24-240 Hz) is
  // resampled to it on the way in, and the output back to the content's
  // rate and frame count on the way out (before post-processing). Content
  // on another humanoid rig is retargeted onto the model's skeleton, and the
  // output (post-processed there) back onto the content's rig, frame for
  // frame (motion/retarget.h).
  // With options.timing kStyle, see TransferOptions::timing; with a package
  // whose movement comes from examples, kStyle is a pace: the content is
  // played at the example's pace first (its path at the example's speed, a
  // gesture in the example's time), so the steps are the example's own, and
  // the output's length changes (TimeWarpNote::content_time_s maps it).
  // INVALID_ARGUMENT for a clip, codes or weights the model cannot take;
  // INTERNAL when LibTorch fails.
  absl::StatusOr<TransferResult> Interpolate(const motion::Motion& content,
                                             const std::vector<StyleCode>& styles,
                                             const StyleWeights& weights,
                                             const TransferOptions& options = {}) const;
  // Interpolate with one style.
  absl::StatusOr<TransferResult> Transfer(const motion::Motion& content, const StyleCode& style,
                                          const TransferOptions& options = {}) const;

  // A streamer for frames on `spec.skeleton` at `spec.frame_time`
  // (model/frame_streamer.h); it shares ownership of the model. At another
  // rate than the model's (24-240 Hz), frames are resampled on the way in
  // and out (model/resampling_streamer.h); on another humanoid rig,
  // retargeted both ways (model/retargeting_streamer.h). Streams are never
  // guarded.
  // INVALID_ARGUMENT when such frames or the style cannot feed the model;
  // FAILED_PRECONDITION when the model is not owned by a std::shared_ptr.
  absl::StatusOr<std::unique_ptr<FrameStreamer>> OpenStream(const StreamSpec& spec) const;

  // Runs the next step of each of `cores` (FrameStreamer::step_core() of
  // batchable streams opened on this model, each with has_steps()) as one
  // batch. UNIMPLEMENTED for a model whose streams cannot batch.
  virtual absl::Status StepStreams(const std::vector<FrameStreamer*>& /*cores*/) const {
    return absl::UnimplementedError("this model's streams run whole windows");
  }

  // This model's side of retargeting: its skeleton, roles and the mean
  // pose of its training features. INVALID_ARGUMENT when its skeleton has
  // no humanoid roles.
  absl::StatusOr<std::shared_ptr<const motion::ModelRig>> model_rig() const;
  // A retargeter from `clip`'s rig onto this model's skeleton;
  // INVALID_ARGUMENT names `what` and the roles the rig lacks.
  absl::StatusOr<std::unique_ptr<motion::Retargeter>> RetargeterFor(
      const motion::Motion& clip, const motion::JointMap& joint_map, const std::string& what) const;
  // Whether this package takes a transfer's movement from examples
  // (MovementKeys; `movement = examples`).
  bool moves_from_examples() const { return movement_keys().movement_examples; }
  // The action the package's content guard reads in `clip` (on the model's
  // skeleton, at its rate): a probability per action; empty without a
  // guard or for a clip it cannot read.
  std::vector<double> ReadAction(const motion::Motion& clip) const;
  // The guard's probability of each action for `normalized` features (as
  // the package's statistics normalize them); empty without a guard.
  std::vector<double> ActionProbabilities(const motion::FeatureClip& normalized) const;
  // The action named `label` as a reading: 1 for it among the guard's
  // actions, 0 for the others; empty when the guard knows no such action
  // (or without a guard).
  std::vector<double> LabelledAction(const std::string& label) const;

 protected:
  // Interpolate with the content's timing.
  absl::StatusOr<TransferResult> InterpolateInContentTime(const motion::Motion& content,
                                                          const std::vector<StyleCode>& styles,
                                                          const StyleWeights& weights,
                                                          const TransferOptions& options) const;
  // `clip` on the model's skeleton at its rate.
  absl::StatusOr<motion::Motion> OnModel(const motion::Motion& clip,
                                         const motion::JointMap& joint_map) const;
  // EncodeStyle without the cadence.
  absl::StatusOr<StyleCode> EncodeAnyRigStyle(const motion::Motion& clip,
                                              const motion::JointMap& joint_map) const;
  // Interpolate of `content` at the model's rate; `original` is the clip as
  // it came (the same object when no resampling was needed), whose rate and
  // frame count the output takes and whose contacts post-processing reads.
  absl::StatusOr<TransferResult> InterpolateAtModelRate(const motion::Motion& content,
                                                        const motion::Motion& original,
                                                        const std::vector<StyleCode>& styles,
                                                        const StyleWeights& weights,
                                                        const TransferOptions& options) const;
  // EncodeStyle of a clip at the model's own rate (the family checks it).
  virtual absl::StatusOr<StyleCode> EncodeModelRateStyle(const motion::Motion& clip) const = 0;
  // OpenStream with spec.frame_time the model's. The default streams in
  // chunks through whole-clip transfers (model/chunked_streamer.h); a
  // family may stream in its own way. The model is owned by a shared_ptr.
  virtual absl::StatusOr<std::unique_ptr<FrameStreamer>> OpenModelRateStream(
      const StreamSpec& spec) const;

  // One content clip's transfer, prepared once, rendered in the forms the
  // content guard chooses from: form 0 is the configured transfer, form k
  // the weaker one at guard_strengths[k - 1] (each family says what a
  // strength is). Used by one thread.
  class Forms {
   public:
    virtual ~Forms() = default;
    // Form `step` as the guard reads it, not post-processed.
    virtual absl::StatusOr<motion::Motion> Draft(size_t step) = 0;
    // Form `step` as returned, not post-processed; `draft` is Draft(step)
    // when the guard read it, else null. A family that refines the chosen
    // form only (an optimization) does it here.
    virtual absl::StatusOr<motion::Motion> Final(size_t step, const motion::Motion* draft) {
      if (draft != nullptr) return *draft;
      return Draft(step);
    }
  };
  // `styles` and `weights` are already checked against the clip and
  // code_size(); the clip is not.
  // `batcher`: TransferOptions::batcher (may be null).
  virtual absl::StatusOr<std::unique_ptr<Forms>> PrepareTransfer(
      const motion::Motion& content, const std::vector<StyleCode>& styles,
      const StyleWeights& weights, PassBatcher* batcher) const = 0;
  // The package's content guard and its keys (null when it has none).
  virtual const ContentGuard* content_guard() const { return nullptr; }
  virtual const GuardKeys& guard_keys() const = 0;
  virtual const MovementKeys& movement_keys() const = 0;

 private:
  mutable std::once_flag rig_once_;
  mutable absl::StatusOr<std::shared_ptr<const motion::ModelRig>> rig_;
};

// INVALID_ARGUMENT unless every code has `code_size` values and `weights`
// fits `styles` (one weight per style, finite; per_frame: one row per frame).
absl::Status CheckStyleMix(const std::vector<StyleCode>& styles, const StyleWeights& weights,
                           int frames, int code_size);
// The weighted sum of `styles` with `mix`.
StyleCode MixStyles(const std::vector<StyleCode>& styles, const std::vector<double>& mix);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_STYLE_MODEL_H_
