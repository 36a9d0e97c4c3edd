// What a stream session drives, whichever family serves it: frames go in as
// they arrive and stylized frames come out, in order, once final.
#ifndef STYLUS_MODEL_FRAME_STREAMER_H_
#define STYLUS_MODEL_FRAME_STREAMER_H_

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::model {

struct StyleChange;  // model/style_schedule.h

class FrameStreamer {
 public:
  virtual ~FrameStreamer() = default;
  // Appends `frames` (on the stream's skeleton) and returns the output frames
  // that became final, continuing where the previous call's ended.
  virtual absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) = 0;
  // Returns every frame not yet returned. FAILED_PRECONDITION when no frame
  // was pushed.
  virtual absl::StatusOr<motion::Motion> Finish() = 0;
  virtual int64_t received() const = 0;
  virtual int64_t emitted() const = 0;

  // Batched stepping, for streams whose model runs one network step per
  // frame (live packages): the steps of many streams on one model can run
  // as one batch (StyleModel::StepStreams), one step of each stream per
  // batch. Feed queues frames (with `end`: the stream's end) without running
  // the network; batches then run while has_steps(); Collect returns the
  // frames that became final. Push and Finish do all of it alone. Streamers
  // that cannot batch say so with batchable() false (Feed and Collect are
  // then UNIMPLEMENTED).
  virtual bool batchable() const { return false; }
  virtual absl::Status Feed(const motion::Motion& /*frames*/, bool /*end*/ = false) {
    return absl::UnimplementedError("this stream runs its network in whole windows");
  }
  virtual bool has_steps() const { return false; }
  virtual absl::StatusOr<motion::Motion> Collect() {
    return absl::UnimplementedError("this stream runs its network in whole windows");
  }
  // Changes the style from `change.from_frame` (a stream frame index, from
  // 0) on, cross-faded (model/style_schedule.h). FAILED_PRECONDITION for a
  // streamer that keeps one style (offline packages); INVALID_ARGUMENT for a
  // change that does not fit.
  virtual absl::Status ChangeStyle(const StyleChange& /*change*/) {
    return absl::FailedPreconditionError(
        "this model's streams keep one style; style changes need a live model");
  }
  // The output's own foot contacts (FootJoints order, motion/contacts.h) of
  // the frames returned since the last call, one per frame in order, for a
  // stream whose steps are its own (movement from examples,
  // motion/live_movement.h); nullopt for a frame whose feet follow the
  // input's. Empty for streams that keep the network's movement.
  virtual std::vector<std::optional<std::array<bool, 4>>> TakeContacts() { return {}; }
  // The streamer whose steps StyleModel::StepStreams runs: this one, or the
  // one a wrapper (a resampler) feeds.
  virtual FrameStreamer* step_core() { return this; }
};

// A streamer that converts frames on their way to and from another one
// (resampling, retargeting): batched stepping and style changes go to the
// streamer it wraps.
class WrappingStreamer : public FrameStreamer {
 public:
  bool batchable() const override { return inner_->batchable(); }
  bool has_steps() const override { return inner_->has_steps(); }
  FrameStreamer* step_core() override { return inner_->step_core(); }
  // At the wrapped streamer's rate (a resampling wrapper's frames differ).
  std::vector<std::optional<std::array<bool, 4>>> TakeContacts() override {
    return inner_->TakeContacts();
  }
  absl::Status ChangeStyle(const StyleChange& change) override {
    return inner_->ChangeStyle(change);
  }

 protected:
  explicit WrappingStreamer(std::unique_ptr<FrameStreamer> inner) : inner_(std::move(inner)) {}
  std::unique_ptr<FrameStreamer> inner_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_FRAME_STREAMER_H_
