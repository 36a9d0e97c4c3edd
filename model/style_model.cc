#include "model/style_model.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "model/chunked_streamer.h"
#include "model/content_guard.h"
#include "motion/features.h"

namespace stylus::model {

absl::Status CheckStyleMix(const std::vector<StyleCode>& styles, const StyleWeights& weights,
                           int frames, int code_size) {
  if (styles.empty()) return absl::InvalidArgumentError("no style given");
  for (const StyleCode& s : styles) {
    if (static_cast<int>(s.values.size()) != code_size) {
      return absl::InvalidArgumentError(absl::StrCat("style code has ", s.values.size(),
                                                     " values; this model's have ", code_size));
    }
  }
  const bool per_frame = !weights.per_frame.empty();
  if (per_frame && static_cast<int>(weights.per_frame.size()) != frames) {
    return absl::InvalidArgumentError(absl::StrCat("weight schedule has ", weights.per_frame.size(),
                                                   " rows; the content clip has ", frames,
                                                   " frames"));
  }
  for (const auto& row :
       per_frame ? weights.per_frame : std::vector<std::vector<double>>{weights.fixed}) {
    if (row.size() != styles.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("got ", row.size(), " weights for ", styles.size(), " styles"));
    }
    for (double w : row) {
      if (!std::isfinite(w)) return absl::InvalidArgumentError("style weights must be finite");
    }
  }
  return absl::OkStatus();
}

StyleCode MixStyles(const std::vector<StyleCode>& styles, const std::vector<double>& mix) {
  StyleCode out;
  out.values.assign(styles[0].values.size(), 0.f);
  for (size_t c = 0; c < out.values.size(); ++c) {
    double v = 0;
    for (size_t k = 0; k < styles.size(); ++k) v += mix[k] * styles[k].values[c];
    out.values[c] = static_cast<float>(v);
  }
  return out;
}

StyleModel::~StyleModel() = default;

absl::StatusOr<TransferResult> StyleModel::Transfer(const motion::Motion& content,
                                                    const StyleCode& style,
                                                    const TransferOptions& options) const {
  return Interpolate(content, {style}, StyleWeights{{1.0}, {}}, options);
}

absl::StatusOr<TransferResult> StyleModel::Interpolate(const motion::Motion& content,
                                                       const std::vector<StyleCode>& styles,
                                                       const StyleWeights& weights,
                                                       const TransferOptions& options) const {
  if (absl::Status s = CheckStyleMix(styles, weights, content.num_frames, code_size()); !s.ok()) {
    return s;
  }
  absl::StatusOr<std::unique_ptr<Forms>> forms = PrepareTransfer(content, styles, weights);
  if (!forms.ok()) return forms.status();
  TransferResult result;
  const ContentGuard* guard = options.content_guard ? content_guard() : nullptr;
  absl::StatusOr<motion::Motion> out;
  if (guard == nullptr) {
    out = (*forms)->Final(0, nullptr);
  } else {
    // The first form whose action reads as the content's, judged before
    // refinement and post-processing (as `eval` judges raw transfers), so
    // only the chosen form is refined and post-processed.
    auto normalized = [this](const motion::Motion& clip) -> absl::StatusOr<motion::FeatureClip> {
      absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, data().roles);
      if (f.ok()) data().norm.Normalize(&*f);
      return f;
    };
    absl::StatusOr<motion::FeatureClip> read = normalized(content);
    if (!read.ok()) return read.status();
    const int action = guard->Classify(*read);
    const GuardKeys& keys = guard_keys();
    const std::vector<double>& strengths = keys.guard_strengths;
    for (size_t step = 0; step <= strengths.size(); ++step) {
      absl::StatusOr<motion::Motion> draft = (*forms)->Draft(step);
      if (!draft.ok()) return draft.status();
      read = normalized(*draft);
      if (!read.ok()) return read.status();
      if (guard->Keeps(*read, action, keys.guard_min_probability) || step == strengths.size()) {
        result.note = TransferNote::Guarded(step, strengths);
        out = (*forms)->Final(step, &*draft);
        break;
      }
    }
  }
  if (!out.ok()) return out.status();
  if (options.post == motion::PostProcessMode::kNone) {
    result.motion = *std::move(out);
  } else {
    absl::StatusOr<motion::Motion> clean =
        motion::PostProcess(*out, content, data().roles, options.post);
    if (!clean.ok()) return clean.status();
    result.motion = *std::move(clean);
  }
  return result;
}

absl::StatusOr<std::unique_ptr<FrameStreamer>> StyleModel::OpenStream(
    const StreamSpec& spec) const {
  std::shared_ptr<const StyleModel> self = weak_from_this().lock();
  if (self == nullptr) {
    return absl::FailedPreconditionError(
        absl::StrCat("model ", dir(), ": streams need a model owned by a std::shared_ptr"));
  }
  absl::StatusOr<std::unique_ptr<ChunkedStreamer>> s =
      ChunkedStreamer::Create(std::move(self), spec);
  if (!s.ok()) return s.status();
  return std::unique_ptr<FrameStreamer>(*std::move(s));
}

}  // namespace stylus::model
