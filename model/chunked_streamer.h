// Streaming for any model family through its whole-clip transfer: every
// `chunk` frames, the newest chunk is transferred together with up to
// `context` frames of input history before it, and the chunk's output frames
// are emitted. The root continues from the last emitted frame with the
// window's own motion, so the path has no jumps; poses may differ slightly at
// chunk seams, since each window sees a different stretch of input. Used for
// the `cyclic` family (the contrastive family has its own windowed streaming,
// model/contrastive/window_streamer.h).
//
// Latency: a frame comes out when its chunk is complete (at most `chunk`
// frames after it went in) plus one transfer of context + chunk frames.
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_CHUNKED_STREAMER_H_
#define STYLUS_MODEL_CHUNKED_STREAMER_H_

#include <memory>

#include "model/frame_streamer.h"
#include "model/style_model.h"
#include "motion/postprocess.h"

namespace stylus::model {

class ChunkedStreamer : public FrameStreamer {
 public:
  // INVALID_ARGUMENT when frames on `spec.skeleton` at `spec.frame_time`
  // cannot feed the model or `spec.style` does not fit it (checked with a
  // transfer of two rest frames), or chunk/context are not positive.
  static absl::StatusOr<std::unique_ptr<ChunkedStreamer>> Create(
      std::shared_ptr<const StyleModel> model, const StreamSpec& spec, int chunk = 30,
      int context = 60);

  absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) override;
  absl::StatusOr<motion::Motion> Finish() override;
  int64_t received() const override { return received_; }
  int64_t emitted() const override { return emitted_; }

 private:
  ChunkedStreamer(std::shared_ptr<const StyleModel> model, StyleCode style,
                  const motion::Motion& empty, motion::PostProcessMode post, int chunk,
                  int context);
  // Transfers the next `n` frames (with their context) and returns them.
  absl::StatusOr<motion::Motion> Emit(int n);

  std::shared_ptr<const StyleModel> model_;
  StyleCode style_;
  motion::PostProcessMode post_;
  int chunk_, context_;
  motion::Motion input_;  // Held input; frame 0 is stream frame base_.
  int64_t base_ = 0, received_ = 0, emitted_ = 0;
  bool has_last_ = false;
  double last_root_[3] = {0, 0, 0};  // Root position channels of the last emitted frame.
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CHUNKED_STREAMER_H_
