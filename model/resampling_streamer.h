// A stream at a capture rate other than the model's (24-240 Hz): input
// frames are resampled to the model's rate on the way in (rotations by
// slerp) and the model's output back to the input's rate on the way out, so
// output frames match input frames one to one.
//
// An output frame leaves as soon as the model's output frame at or before
// its instant is final: between that frame and the one before it the pose
// is extrapolated (slerp past its end) rather than waiting one more model
// frame to interpolate, so a live model's latency in time is the same at
// any input rate. Frames whose next model frame is already out (after
// Finish, or from a streamer that emits in chunks) are interpolated.
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_RESAMPLING_STREAMER_H_
#define STYLUS_MODEL_RESAMPLING_STREAMER_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "model/frame_streamer.h"
#include "motion/motion.h"

namespace stylus::model {

class ResamplingStreamer : public WrappingStreamer {
 public:
  // `inner` streams at `model_frame_time`; frames come in on `empty`'s
  // skeleton at its frame time.
  ResamplingStreamer(std::unique_ptr<FrameStreamer> inner, const motion::Motion& empty,
                     double model_frame_time);

  absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) override;
  absl::StatusOr<motion::Motion> Finish() override;
  int64_t received() const override { return received_; }
  int64_t emitted() const override { return emitted_; }
  absl::Status Feed(const motion::Motion& frames, bool end = false) override;
  absl::StatusOr<motion::Motion> Collect() override;
  // The change's frames converted to the model's rate.
  absl::Status ChangeStyle(const StyleChange& change) override;

 private:
  // Feeds the inner streamer every model frame the input received covers
  // (with `batched`, through its Feed: no network step runs).
  absl::Status FeedModel(bool finished, bool batched = false);
  // Appends the inner streamer's new output frames to the model output held.
  void TakeModel(const motion::Motion& frames);
  // The output frames ready (all of them once `finished`).
  motion::Motion EmitReady(bool finished);

  const double in_ft_, model_ft_;
  motion::Motion input_;  // The last input frames held (from in_base_).
  int64_t in_base_ = 0, received_ = 0;
  int64_t model_fed_ = 0;     // Model-rate frames given to the inner streamer.
  motion::Motion model_out_;  // The last model output frames held (from out_base_).
  int64_t out_base_ = 0, model_emitted_ = 0;
  int64_t emitted_ = 0;
  bool ending_ = false;  // Fed its end (batched use).
  std::vector<motion::Vec3> in_euler_, out_euler_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_RESAMPLING_STREAMER_H_
