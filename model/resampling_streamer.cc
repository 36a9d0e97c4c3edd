#include "model/resampling_streamer.h"

#include <algorithm>
#include <cmath>

#include "model/style_schedule.h"
#include "motion/resample.h"

namespace stylus::model {
namespace {

motion::Motion Empty(const motion::Motion& like, double frame_time) {
  motion::Motion m = like;
  m.num_frames = 0;
  m.values.clear();
  m.frame_time = frame_time;
  return m;
}

// Drops the frames of `m` (whose first is stream frame *base) before `keep`.
void DropBefore(int64_t keep, motion::Motion* m, int64_t* base) {
  if (keep <= *base) return;
  const int channels = m->skeleton.num_channels();
  const int64_t n = std::min<int64_t>(keep - *base, m->num_frames);
  m->values.erase(m->values.begin(), m->values.begin() + n * channels);
  m->num_frames -= static_cast<int>(n);
  *base += n;
}

void AppendPose(motion::Motion* m, const motion::LocalPose& pose,
                std::vector<motion::Vec3>* euler) {
  m->values.resize(m->values.size() + m->skeleton.num_channels());
  ++m->num_frames;
  motion::SetPose(m, m->num_frames - 1, pose, euler);
}

}  // namespace

ResamplingStreamer::ResamplingStreamer(std::unique_ptr<FrameStreamer> inner,
                                       const motion::Motion& empty, double model_frame_time)
    : WrappingStreamer(std::move(inner)),
      in_ft_(empty.frame_time),
      model_ft_(model_frame_time),
      input_(Empty(empty, empty.frame_time)),
      model_out_(Empty(empty, model_frame_time)),
      in_euler_(empty.skeleton.num_joints()),
      out_euler_(empty.skeleton.num_joints()) {}

absl::StatusOr<motion::Motion> ResamplingStreamer::Push(const motion::Motion& frames) {
  input_.values.insert(input_.values.end(), frames.values.begin(), frames.values.end());
  input_.num_frames += frames.num_frames;
  received_ += frames.num_frames;
  if (absl::Status s = FeedModel(false); !s.ok()) return s;
  return EmitReady(false);
}

absl::StatusOr<motion::Motion> ResamplingStreamer::Finish() {
  if (received_ == 0) return absl::FailedPreconditionError("the stream has no frames");
  if (absl::Status s = FeedModel(true); !s.ok()) return s;
  absl::StatusOr<motion::Motion> rest = inner_->Finish();
  if (!rest.ok()) return rest.status();
  TakeModel(*rest);
  return EmitReady(true);
}

absl::Status ResamplingStreamer::ChangeStyle(const StyleChange& change) {
  StyleChange at_model = change;
  const double ratio = in_ft_ / model_ft_;  // Model frames per input frame.
  at_model.from_frame = static_cast<int64_t>(std::ceil(change.from_frame * ratio - 1e-6));
  at_model.fade_frames = static_cast<int>(std::lround(change.fade_frames * ratio));
  return inner_->ChangeStyle(at_model);
}

absl::Status ResamplingStreamer::Feed(const motion::Motion& frames, bool end) {
  input_.values.insert(input_.values.end(), frames.values.begin(), frames.values.end());
  input_.num_frames += frames.num_frames;
  received_ += frames.num_frames;
  if (end && received_ == 0) return absl::FailedPreconditionError("the stream has no frames");
  if (absl::Status s = FeedModel(end, /*batched=*/true); !s.ok()) return s;
  if (end) {
    motion::Motion none = Empty(input_, model_ft_);
    if (absl::Status s = inner_->Feed(none, /*end=*/true); !s.ok()) return s;
    ending_ = true;
  }
  return absl::OkStatus();
}

absl::StatusOr<motion::Motion> ResamplingStreamer::Collect() {
  absl::StatusOr<motion::Motion> out = inner_->Collect();
  if (!out.ok()) return out.status();
  TakeModel(*out);
  return EmitReady(ending_ && !inner_->has_steps());
}

absl::Status ResamplingStreamer::FeedModel(bool finished, bool batched) {
  const double ratio = model_ft_ / in_ft_;  // Input frames per model frame.
  motion::Motion chunk = Empty(input_, model_ft_);
  motion::Motion held = input_;
  for (;; ++model_fed_) {
    const double t = model_fed_ * ratio;  // In input frames.
    if (t > received_ - 1 + 1e-6) break;  // Not covered yet.
    // Needs the input frames either side of t (the one at t when exact).
    if (!finished && std::ceil(t - 1e-6) > received_ - 1) break;
    AppendPose(&chunk, motion::PoseAtTime(held, t - in_base_), &in_euler_);
  }
  // Keep the input frame before the next model frame's instant.
  DropBefore(static_cast<int64_t>(std::floor(model_fed_ * ratio + 1e-6)) - 1, &input_, &in_base_);
  if (chunk.num_frames == 0) return absl::OkStatus();
  if (batched) return inner_->Feed(chunk);
  absl::StatusOr<motion::Motion> out = inner_->Push(chunk);
  if (!out.ok()) return out.status();
  TakeModel(*out);
  return absl::OkStatus();
}

void ResamplingStreamer::TakeModel(const motion::Motion& frames) {
  model_out_.values.insert(model_out_.values.end(), frames.values.begin(), frames.values.end());
  model_out_.num_frames += frames.num_frames;
  model_emitted_ += frames.num_frames;
}

motion::Motion ResamplingStreamer::EmitReady(bool finished) {
  motion::Motion out = Empty(input_, in_ft_);
  const double ratio = in_ft_ / model_ft_;  // Model frames per input frame.
  while (emitted_ < received_ && model_emitted_ > 0) {
    const double t = emitted_ * ratio;  // In model frames.
    const int64_t m0 = static_cast<int64_t>(std::floor(t + 1e-6));
    const double u = std::max(0.0, t - m0);
    motion::LocalPose pose;
    if (m0 + 1 < model_emitted_ || (finished && m0 + 1 >= model_emitted_)) {
      // Interpolated (held at the end).
      pose = motion::PoseAtTime(model_out_, t - out_base_);
    } else if (m0 < model_emitted_) {
      if (u < 1e-6 || m0 == 0) {
        pose = motion::PoseAt(model_out_, static_cast<int>(m0 - out_base_));
      } else {  // Past the newest final model frame: extrapolated from the one before.
        pose =
            motion::BlendPoses(motion::PoseAt(model_out_, static_cast<int>(m0 - 1 - out_base_)),
                               motion::PoseAt(model_out_, static_cast<int>(m0 - out_base_)), 1 + u);
      }
    } else {
      break;
    }
    AppendPose(&out, pose, &out_euler_);
    ++emitted_;
  }
  // Keep the model frame before the next output frame's instant.
  DropBefore(
      std::min(static_cast<int64_t>(std::floor(emitted_ * ratio + 1e-6)) - 1, model_emitted_ - 2),
      &model_out_, &out_base_);
  return out;
}

}  // namespace stylus::model
