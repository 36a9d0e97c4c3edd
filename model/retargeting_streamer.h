// A stream on another humanoid rig than the model's (motion/retarget.h):
// each frame is retargeted onto the model's skeleton on the way in, and
// each output frame back onto the rig on the way out, starting from the
// input frame it was made from; frames match one to one, so the latency
// is the wrapped streamer's. The rig's roles are found on its first frame.
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_RETARGETING_STREAMER_H_
#define STYLUS_MODEL_RETARGETING_STREAMER_H_

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "model/frame_streamer.h"
#include "motion/retarget.h"

namespace stylus::model {

class RetargetingStreamer : public WrappingStreamer {
 public:
  // `inner` streams on `model`'s skeleton at the rig's frame time; frames
  // come in on `rig`.
  RetargetingStreamer(std::unique_ptr<FrameStreamer> inner,
                      std::shared_ptr<const motion::ModelRig> model, const motion::Skeleton& rig,
                      double frame_time, motion::JointMap joint_map);

  absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) override;
  absl::StatusOr<motion::Motion> Finish() override;
  int64_t received() const override { return received_; }
  int64_t emitted() const override { return emitted_; }
  absl::Status Feed(const motion::Motion& frames, bool end = false) override;
  absl::StatusOr<motion::Motion> Collect() override;

 private:
  // The frames on the model's skeleton (finding the rig's roles first).
  absl::StatusOr<const motion::Motion*> In(const motion::Motion& frames);
  // The model's output frames back on the rig.
  motion::Motion Out(const motion::Motion& model_frames);

  std::shared_ptr<const motion::ModelRig> model_;
  motion::Motion rig_out_, model_in_;  // Scratch, reused from call to call.
  motion::JointMap joint_map_;
  std::unique_ptr<motion::Retargeter> retargeter_;
  std::deque<std::vector<double>> pending_;  // Input frames whose output has not left.
  int64_t received_ = 0, emitted_ = 0;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_RETARGETING_STREAMER_H_
