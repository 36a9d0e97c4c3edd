#include "model/chunked_streamer.h"

#include <algorithm>
#include <cmath>

namespace stylus::model {
namespace {

// Frames [begin, end) of `m`.
motion::Motion Slice(const motion::Motion& m, int begin, int end) {
  motion::Motion out = m;
  const size_t c = m.skeleton.num_channels();
  out.num_frames = end - begin;
  out.values.assign(m.values.begin() + begin * c, m.values.begin() + end * c);
  return out;
}

// Indices of the root's X and Z position channels (-1 if it has none).
std::pair<int, int> RootFloorChannels(const motion::Skeleton& s) {
  int x = -1, z = -1;
  const motion::Joint& root = s.joint(0);
  for (size_t i = 0; i < root.channels.size(); ++i) {
    if (!motion::IsPosition(root.channels[i])) continue;
    const int axis = motion::ChannelAxis(root.channels[i]);
    if (axis == 0) x = s.channel_start(0) + static_cast<int>(i);
    if (axis == 2) z = s.channel_start(0) + static_cast<int>(i);
  }
  return {x, z};
}

}  // namespace

absl::StatusOr<std::unique_ptr<ChunkedStreamer>> ChunkedStreamer::Create(
    std::shared_ptr<const StyleModel> model, const StreamSpec& spec, int chunk, int context) {
  if (chunk <= 0 || context < 0) {
    return absl::InvalidArgumentError("chunk must be positive and context not negative");
  }
  const motion::Motion probe = motion::RestMotion(spec.skeleton, 2, spec.frame_time);
  TransferOptions raw(motion::PostProcessMode::kNone);
  raw.content_guard = false;
  raw.movement_from_examples = false;
  if (auto t = model->Transfer(probe, spec.style, raw); !t.ok()) return t.status();
  return std::unique_ptr<ChunkedStreamer>(new ChunkedStreamer(
      std::move(model), spec.style, motion::RestMotion(spec.skeleton, 0, spec.frame_time),
      spec.post, chunk, context));
}

ChunkedStreamer::ChunkedStreamer(std::shared_ptr<const StyleModel> model, StyleCode style,
                                 const motion::Motion& empty, motion::PostProcessMode post,
                                 int chunk, int context)
    : model_(std::move(model)),
      style_(std::move(style)),
      post_(post),
      chunk_(chunk),
      context_(context),
      input_(empty) {}

absl::StatusOr<motion::Motion> ChunkedStreamer::Push(const motion::Motion& frames) {
  for (float v : frames.values) {
    if (!std::isfinite(v)) return absl::InvalidArgumentError("stream frame: non-finite value");
  }
  input_.values.insert(input_.values.end(), frames.values.begin(), frames.values.end());
  input_.num_frames += frames.num_frames;
  received_ += frames.num_frames;
  motion::Motion out = Slice(input_, 0, 0);
  while (received_ - emitted_ >= chunk_) {
    absl::StatusOr<motion::Motion> part = Emit(chunk_);
    if (!part.ok()) return part.status();
    out.values.insert(out.values.end(), part->values.begin(), part->values.end());
    out.num_frames += part->num_frames;
  }
  return out;
}

absl::StatusOr<motion::Motion> ChunkedStreamer::Finish() {
  if (received_ == 0) return absl::FailedPreconditionError("no frame was streamed");
  if (received_ == emitted_) return Slice(input_, 0, 0);
  return Emit(static_cast<int>(received_ - emitted_));
}

absl::StatusOr<motion::Motion> ChunkedStreamer::Emit(int n) {
  const int64_t start = std::max(base_, emitted_ - context_);
  const motion::Motion window =
      Slice(input_, static_cast<int>(start - base_), static_cast<int>(emitted_ + n - base_));
  TransferOptions options(post_);
  options.content_guard = false;
  // Movement from examples registers whole clips; a stream's chunks keep
  // the network's movement (docs/movement.md "Streams").
  options.movement_from_examples = false;
  absl::StatusOr<TransferResult> transferred = model_->Transfer(window, style_, options);
  if (!transferred.ok()) return transferred.status();
  const motion::Motion* out = &transferred->motion;
  const int first = static_cast<int>(emitted_ - start);
  motion::Motion chunk = Slice(*out, first, first + n);
  // Continue the root from the last emitted frame with the window's own step.
  const auto [cx, cz] = RootFloorChannels(chunk.skeleton);
  const size_t c = chunk.skeleton.num_channels();
  for (int axis : {cx, cz}) {
    if (axis < 0) continue;
    const int slot = axis == cx ? 0 : 2;
    if (has_last_) {
      const double step =
          first > 0 ? out->values[first * c + axis] - out->values[(first - 1) * c + axis] : 0.0;
      const double shift = last_root_[slot] + step - chunk.values[axis];
      for (int f = 0; f < n; ++f) chunk.values[f * c + axis] += static_cast<float>(shift);
    }
    last_root_[slot] = chunk.values[(n - 1) * c + axis];
  }
  has_last_ = true;
  emitted_ += n;
  // Keep only the context the next window needs.
  const int64_t keep_from = std::max(base_, emitted_ - context_);
  if (keep_from > base_) {
    input_ = Slice(input_, static_cast<int>(keep_from - base_), input_.num_frames);
    base_ = keep_from;
  }
  return chunk;
}

}  // namespace stylus::model
