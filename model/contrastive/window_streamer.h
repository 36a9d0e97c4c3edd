// Style transfer of a live stream of frames: frames go in as they arrive, and
// stylized frames come out as soon as every window that covers them has been
// generated. The windows, their cross-fade and the reconstruction are those of
// a whole-clip ContrastiveModel transfer, so a stream yields the same
// frames as a whole-clip Transfer up to the differences documented in
// docs/service.md (features are computed causally, over a bounded history).
//
// Latency: a frame comes out once the window that starts after it has been
// generated, i.e. at most window + hop frames after it went in (56 frames for
// the default model); Finish() flushes the rest.
//
// Thread-safety: one WindowStreamer per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_CONTRASTIVE_WINDOW_STREAMER_H_
#define STYLUS_MODEL_CONTRASTIVE_WINDOW_STREAMER_H_

#include <cstdint>
#include <memory>

#include "absl/status/statusor.h"
#include "model/contrastive/contrastive_model.h"
#include "model/frame_streamer.h"
#include "model/stream_cleaner.h"
#include "model/window_blend.h"
#include "motion/features.h"
#include "motion/motion.h"

namespace stylus::model {

class WindowStreamer : public FrameStreamer {
 public:
  // INVALID_ARGUMENT when frames on `spec.skeleton` at `spec.frame_time`
  // cannot feed the model or `spec.style` does not fit it. Shares ownership
  // of `model`. ContrastiveModel::OpenStream makes one.
  // `spec.post` as in a transfer, decided causally: contacts from the input frames
  // held (the current window and the history before it), locked feet pinned
  // where they were at the start of their contact.
  static absl::StatusOr<std::unique_ptr<WindowStreamer>> Create(
      std::shared_ptr<const ContrastiveModel> model, const StreamSpec& spec);

  // Appends `frames` (a motion on the stream's skeleton; its values only are
  // read) and returns the output frames that became final, in order: they
  // continue where the previous call's ended (see emitted()). INVALID_ARGUMENT
  // for non-finite values.
  absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) override;
  // Generates the remaining windows and returns every frame not yet returned.
  // FAILED_PRECONDITION when no frame was pushed.
  absl::StatusOr<motion::Motion> Finish() override;

  int64_t received() const override { return received_; }
  int64_t emitted() const override { return blender_.taken(); }

 private:
  WindowStreamer(std::shared_ptr<const ContrastiveModel> model, StyleCode style,
                 const motion::Motion& empty, motion::PostProcessMode post);
  // Generates the window starting at `start` using input features computed
  // over the frames held; `end` is one past the last frame they may use.
  absl::Status Generate(int64_t start, int64_t end);
  absl::StatusOr<motion::Motion> Emit(int64_t end);
  void Trim();

  std::shared_ptr<const ContrastiveModel> model_;
  StyleCode style_;
  int window_, hop_;
  motion::Motion input_;  // Held input frames; frame 0 is stream frame base_.
  int64_t base_ = 0;
  int64_t received_ = 0;
  int64_t next_start_ = 0;       // Start of the next regular window.
  int64_t last_generated_ = -1;  // Start of the last window generated.
  WindowBlender blender_;
  motion::DecodeState decode_;
  // Feature quaternions of stream frame base_ - 1 (empty while base_ is 0),
  // so held frames get the signs the whole clip would give them.
  std::vector<motion::Quat> signs_;
  bool started_ = false;
  StreamCleaner cleaner_;  // Post-processing, with one window of history.
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_WINDOW_STREAMER_H_
