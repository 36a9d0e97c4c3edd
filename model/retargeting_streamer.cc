#include "model/retargeting_streamer.h"

#include <algorithm>
#include <utility>

namespace stylus::model {

RetargetingStreamer::RetargetingStreamer(std::unique_ptr<FrameStreamer> inner,
                                         std::shared_ptr<const motion::ModelRig> model,
                                         const motion::Skeleton& rig, double frame_time,
                                         motion::JointMap joint_map)
    : WrappingStreamer(std::move(inner)),
      model_(std::move(model)),
      rig_out_(motion::RestMotion(rig, 0, frame_time)),
      model_in_(motion::RestMotion(model_->skeleton, 0, frame_time)),
      joint_map_(std::move(joint_map)) {}

absl::StatusOr<const motion::Motion*> RetargetingStreamer::In(const motion::Motion& frames) {
  if (retargeter_ == nullptr && frames.num_frames > 0) {
    absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
        motion::Retargeter::Create(model_, frames.skeleton, frames.frame(0), joint_map_);
    if (!r.ok()) return r.status();
    retargeter_ = *std::move(r);
  }
  model_in_.num_frames = frames.num_frames;
  model_in_.values.resize(static_cast<size_t>(frames.num_frames) *
                          model_in_.skeleton.num_channels());
  const int channels = frames.skeleton.num_channels();
  for (int f = 0; f < frames.num_frames; ++f) {
    retargeter_->ToModel(frames.frame(f), model_in_.frame(f));
    pending_.emplace_back(frames.frame(f), frames.frame(f) + channels);
  }
  received_ += frames.num_frames;
  return &model_in_;
}

motion::Motion RetargetingStreamer::Out(const motion::Motion& model_frames) {
  rig_out_.num_frames = std::min<int>(model_frames.num_frames, pending_.size());
  rig_out_.values.resize(static_cast<size_t>(rig_out_.num_frames) *
                         rig_out_.skeleton.num_channels());
  for (int f = 0; f < rig_out_.num_frames; ++f) {
    retargeter_->FromModel(model_frames.frame(f), pending_.front().data(), rig_out_.frame(f));
    pending_.pop_front();
    ++emitted_;
  }
  return rig_out_;
}

absl::StatusOr<motion::Motion> RetargetingStreamer::Push(const motion::Motion& frames) {
  absl::StatusOr<const motion::Motion*> in = In(frames);
  if (!in.ok()) return in.status();
  absl::StatusOr<motion::Motion> out = inner_->Push(**in);
  if (!out.ok()) return out.status();
  return Out(*out);
}

absl::StatusOr<motion::Motion> RetargetingStreamer::Finish() {
  if (received_ == 0) return absl::FailedPreconditionError("the stream has no frames");
  absl::StatusOr<motion::Motion> out = inner_->Finish();
  if (!out.ok()) return out.status();
  return Out(*out);
}

absl::Status RetargetingStreamer::Feed(const motion::Motion& frames, bool end) {
  absl::StatusOr<const motion::Motion*> in = In(frames);
  if (!in.ok()) return in.status();
  return inner_->Feed(**in, end);
}

absl::StatusOr<motion::Motion> RetargetingStreamer::Collect() {
  absl::StatusOr<motion::Motion> out = inner_->Collect();
  if (!out.ok()) return out.status();
  return Out(*out);
}

}  // namespace stylus::model
