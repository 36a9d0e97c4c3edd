#include "model/contrastive/window_streamer.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "model/window_tensor.h"
#include "motion/windowing.h"

namespace stylus::model {
namespace {

// Frames of history before a window that its input features are computed
// over: enough for the contact detector's floor estimate and the quaternion
// hemisphere to settle as they do on the whole clip.
constexpr int kHistoryWindows = 2;

}  // namespace

absl::StatusOr<std::unique_ptr<WindowStreamer>> WindowStreamer::Create(
    std::shared_ptr<const ContrastiveModel> model, const StreamSpec& spec) {
  if (!model) return absl::InvalidArgumentError("no model");
  if (static_cast<int>(spec.style.values.size()) != model->code_size()) {
    return absl::InvalidArgumentError(absl::StrCat("style code has ", spec.style.values.size(),
                                                   " values; this model's have ",
                                                   model->code_size()));
  }
  motion::Motion probe = motion::RestMotion(spec.skeleton, 1, spec.frame_time);
  if (absl::Status s = CheckClipFitsModel(probe, model->data(), "stream"); !s.ok()) return s;
  probe.num_frames = 0;
  probe.values.clear();
  return std::unique_ptr<WindowStreamer>(
      new WindowStreamer(std::move(model), spec.style, probe, spec.post));
}

WindowStreamer::WindowStreamer(std::shared_ptr<const ContrastiveModel> model, StyleCode style,
                               const motion::Motion& empty, motion::PostProcessMode post)
    : model_(std::move(model)),
      style_(std::move(style)),
      window_(model_->config().window),
      hop_(model_->config().hop),
      input_(empty),
      blender_(window_, window_ - hop_, model_->data().norm.dim()),
      cleaner_(model_->data().roles, post, window_) {}

absl::StatusOr<motion::Motion> WindowStreamer::Push(const motion::Motion& frames) {
  const int channels = input_.skeleton.num_channels();
  for (size_t i = 0; i < frames.values.size(); ++i) {
    if (!std::isfinite(frames.values[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "frame ", received_ + static_cast<int64_t>(i / channels), " has a non-finite value"));
    }
  }
  if (!started_ && frames.num_frames > 0) {
    // The output starts where the content does, as in a whole-clip transfer.
    motion::Motion first = input_;
    first.num_frames = 1;
    first.values.assign(frames.values.begin(), frames.values.begin() + channels);
    decode_.root = motion::RootAt(first, model_->data().roles, 0);
    started_ = true;
  }
  input_.values.insert(input_.values.end(), frames.values.begin(), frames.values.end());
  input_.num_frames += frames.num_frames;
  received_ += frames.num_frames;
  int64_t emit_to = blender_.taken();
  // A window's last frame needs the frame after it for its velocities, as in
  // the whole clip (where only the clip's last frame looks backwards).
  while (next_start_ + window_ + 1 <= received_) {
    if (absl::Status s = Generate(next_start_, next_start_ + window_ + 1); !s.ok()) return s;
    // No later window (regular, or the tail window Finish may add) starts
    // before this one: the frames before it are final.
    emit_to = next_start_;
    next_start_ += hop_;
  }
  absl::StatusOr<motion::Motion> out = Emit(emit_to);
  Trim();
  return out;
}

absl::StatusOr<motion::Motion> WindowStreamer::Finish() {
  if (received_ == 0) return absl::FailedPreconditionError("the stream has no frames");
  const int n = static_cast<int>(received_);
  if (n < window_) {
    // Too short for one window: as Transfer does, pad by repeating the last
    // frame (all frames are still held: nothing was generated or trimmed).
    absl::StatusOr<motion::FeatureClip> f = model_->NormalizedFeatures(input_, "stream");
    if (!f.ok()) return f.status();
    PadToLength(&*f, window_);
    absl::StatusOr<std::vector<float>> y = model_->GenerateWindows(*f, {0}, {style_});
    if (!y.ok()) return y.status();
    blender_.Add(0, y->data());
  } else {
    absl::StatusOr<std::vector<int>> starts =
        motion::WindowStarts(n, {window_, hop_}, /*cover_tail=*/true);
    if (!starts.ok()) return starts.status();
    for (int start : *starts) {
      if (start <= last_generated_) continue;
      if (absl::Status s = Generate(start, n); !s.ok()) return s;
    }
  }
  next_start_ = received_;
  return Emit(received_);
}

absl::Status WindowStreamer::Generate(int64_t start, int64_t end) {
  const int channels = input_.skeleton.num_channels();
  const int64_t from = base_;
  motion::Motion context = input_;
  context.num_frames = static_cast<int>(end - from);
  context.values.assign(input_.values.begin() + (from - base_) * channels,
                        input_.values.begin() + (end - base_) * channels);
  absl::StatusOr<motion::FeatureClip> f =
      model_->NormalizedFeatures(context, "stream", signs_.empty() ? nullptr : &signs_);
  if (!f.ok()) return f.status();
  absl::StatusOr<std::vector<float>> y =
      model_->GenerateWindows(*f, {static_cast<int>(start - from)}, {style_});
  if (!y.ok()) return y.status();
  blender_.Add(start, y->data());
  last_generated_ = start;
  return absl::OkStatus();
}

absl::StatusOr<motion::Motion> WindowStreamer::Emit(int64_t end) {
  motion::FeatureClip out = blender_.Take(end);
  if (out.frames == 0) {
    motion::Motion empty = input_;
    empty.num_frames = 0;
    empty.values.clear();
    return empty;
  }
  model_->data().norm.Denormalize(&out);
  const int64_t first = blender_.taken() - out.frames;
  absl::StatusOr<motion::Motion> raw = motion::MotionFromFeatures(
      out, input_.skeleton, model_->data().roles, input_.frame_time, &decode_);
  if (!raw.ok()) return raw;
  return cleaner_.Clean(*std::move(raw), first, input_, base_);
}

void WindowStreamer::Trim() {
  const int64_t keep_from = std::max(base_, next_start_ - kHistoryWindows * window_);
  if (keep_from <= base_) return;
  const int channels = input_.skeleton.num_channels();
  // Carry the quaternion signs across the frames dropped.
  motion::Motion dropped = input_;
  dropped.num_frames = static_cast<int>(keep_from - base_);
  dropped.values.resize(static_cast<size_t>(dropped.num_frames) * channels);
  absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(
      dropped, model_->data().roles, {}, signs_.empty() ? nullptr : &signs_);
  if (f.ok()) signs_ = motion::FeatureRotations(*f, f->frames - 1);
  input_.values.erase(input_.values.begin(),
                      input_.values.begin() + (keep_from - base_) * channels);
  input_.num_frames -= static_cast<int>(keep_from - base_);
  base_ = keep_from;
}

}  // namespace stylus::model
