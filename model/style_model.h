// What every model family serves: encode a style, transfer it onto a content
// clip of any length, interpolate between styles. The server, the offline
// tool and the evaluation drive models through this interface only;
// LoadStyleModel picks the family from the package's config.txt.
//
// Thread-safety: after loading, all const methods may be called concurrently.
#ifndef STYLUS_MODEL_STYLE_MODEL_H_
#define STYLUS_MODEL_STYLE_MODEL_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "model/package.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::model {

// A style vector from EncodeStyle; style codes of one model can be blended
// linearly.
struct StyleCode {
  std::vector<float> values;
};

// How styles mix over a clip: `fixed` (one weight per style) for the whole clip,
// or `per_frame` (one row of weights per content frame) when not empty.
struct StyleWeights {
  std::vector<double> fixed;
  std::vector<std::vector<double>> per_frame;
};

// How a model's content guard treated one whole-clip transfer
// (ContrastiveConfig::content_guard; docs/contrastive.md, session 14).
struct TransferNote {
  bool guarded = false;    // The model has a content guard.
  bool backed_off = false;  // It read another action in the configured transfer...
  double residual_strength = 1;  // ...and returned the residual form at this strength,
  bool last_form = false;        // the last one it tries (returned even if it fails too).

  // The note of a guarded transfer that returned form `step` (0: the
  // configured one, k: strengths[k - 1]).
  static TransferNote Guarded(size_t step, const std::vector<double>& strengths) {
    return {true, step > 0, step > 0 ? strengths[step - 1] : 1, step == strengths.size()};
  }
};

// What a client may want to know about a loaded model.
struct ModelSummary {
  std::string family;
  int window = 0, hop = 0;  // Training windows (frames).
  int trained_iterations = 0;
};

class StyleModel {
 public:
  virtual ~StyleModel() = default;

  virtual const std::string& dir() const = 0;
  // The skeleton, frame rate and feature statistics input clips must match.
  virtual const DataFiles& data() const = 0;
  virtual ModelSummary summary() const = 0;

  // INVALID_ARGUMENT for a clip the model cannot take (another skeleton or
  // frame rate, non-finite values, no frames); INTERNAL when LibTorch fails.
  virtual absl::StatusOr<StyleCode> EncodeStyle(const motion::Motion& clip) const = 0;

  // The content clip re-generated with `style`: same skeleton, channel layout,
  // frame count and frame rate, the root starting where the content's does.
  // `post` cleans the result (motion/postprocess.h).
  absl::StatusOr<motion::Motion> Transfer(
      const motion::Motion& content, const StyleCode& style,
      motion::PostProcessMode post = motion::PostProcessMode::kFull) const {
    return Interpolate(content, {style}, StyleWeights{{1.0}, {}}, post);
  }

  // Transfer with a blend sum_k w_k s_k of `styles`, fixed or per frame.
  virtual absl::StatusOr<motion::Motion> Interpolate(
      const motion::Motion& content, const std::vector<StyleCode>& styles,
      const StyleWeights& weights,
      motion::PostProcessMode post = motion::PostProcessMode::kFull) const = 0;

  // Interpolate that also fills `note` (when not null); a model without a
  // content guard leaves it at its defaults.
  virtual absl::StatusOr<motion::Motion> InterpolateNoted(const motion::Motion& content,
                                                          const std::vector<StyleCode>& styles,
                                                          const StyleWeights& weights,
                                                          motion::PostProcessMode post,
                                                          TransferNote* note) const {
    (void)note;
    return Interpolate(content, styles, weights, post);
  }
  absl::StatusOr<motion::Motion> TransferNoted(const motion::Motion& content,
                                               const StyleCode& style,
                                               motion::PostProcessMode post,
                                               TransferNote* note) const {
    return InterpolateNoted(content, {style}, StyleWeights{{1.0}, {}}, post, note);
  }
};

// INVALID_ARGUMENT unless every code has `code_size` values and `weights`
// fits `styles` (one weight per style, finite; per_frame: one row per frame).
absl::Status CheckStyleMix(const std::vector<StyleCode>& styles, const StyleWeights& weights,
                           int frames, int code_size);
// The weighted sum of `styles` with `mix`.
StyleCode MixStyles(const std::vector<StyleCode>& styles, const std::vector<double>& mix);

// Whether LoadStyleModel can load packages of `family`.
bool IsServedFamily(const std::string& family);

// Loads the package in `dir` with the family its config.txt names.
// INVALID_ARGUMENT for an unknown family; otherwise the family's own errors.
absl::StatusOr<std::unique_ptr<StyleModel>> LoadStyleModel(const std::string& dir);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_STYLE_MODEL_H_
