// A stream through a live `contrastive` package (docs/service.md "Live
// streams"): each input frame costs one step of the causal networks, with
// their state carried (model/contrastive/live_carry.h), and output frame t
// is final, post-processed and returned once input frame t + lookahead has
// arrived. Raw output (before post-processing) equals the package's
// whole-clip Transfer of the same frames.
//
// The steps can run one stream at a time (Push) or gathered from many
// streams into one batch by a caller (Feed, NextStep, StepDone, Collect:
// the server's batcher).
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_CONTRASTIVE_LIVE_STREAMER_H_
#define STYLUS_MODEL_CONTRASTIVE_LIVE_STREAMER_H_

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "model/contrastive/contrastive_model.h"
#include "model/contrastive/live_carry.h"
#include "model/frame_streamer.h"
#include "model/stream_cleaner.h"
#include "model/style_schedule.h"
#include "motion/features.h"
#include "motion/live_movement.h"
#include "motion/motion.h"

namespace stylus::model {

class LiveStreamer : public FrameStreamer {
 public:
  // INVALID_ARGUMENT when frames on `spec.skeleton` at `spec.frame_time`
  // cannot feed the model or `spec.style` does not fit it;
  // FAILED_PRECONDITION when the package is not live.
  static absl::StatusOr<std::unique_ptr<LiveStreamer>> Create(
      std::shared_ptr<const ContrastiveModel> model, const StreamSpec& spec);

  // FrameStreamer: runs the steps itself, one at a time.
  absl::StatusOr<motion::Motion> Push(const motion::Motion& frames) override;
  absl::StatusOr<motion::Motion> Finish() override;
  int64_t received() const override { return received_; }
  int64_t emitted() const override { return emitted_; }

  // Batched use. Feed takes frames (INVALID_ARGUMENT for non-finite
  // values) and queues their steps; with `end`, the stream's end too (the
  // steps that flush its last frames; FAILED_PRECONDITION when no frame
  // was ever fed).
  bool batchable() const override { return true; }
  absl::Status Feed(const motion::Motion& frames, bool end = false) override;
  bool has_steps() const override { return !queue_.empty(); }
  // The next queued step, to run with ContrastiveModel::StepLive; false
  // when none is queued. Steps of one stream run one at a time, in order:
  // call StepDone after each before asking for the next.
  bool NextStep(LiveStep* step);
  void StepDone();
  // The output frames that became final since the last call.
  absl::StatusOr<motion::Motion> Collect() override;
  // Live control: the style code and strength change from a frame on,
  // cross-faded; a change naming a frame already generated applies from the
  // next one.
  absl::Status ChangeStyle(const StyleChange& change) override;
  std::vector<std::optional<std::array<bool, 4>>> TakeContacts() override;
  int pending_steps() const { return static_cast<int>(queue_.size()); }

  // Bytes this stream holds, all of it bounded: the networks' carried state
  // plus the frames held for features, decoding and post-processing.
  size_t state_bytes() const;
  // The networks' carried state alone.
  size_t carry_bytes() const { return carry_.bytes(); }

 private:
  LiveStreamer(std::shared_ptr<const ContrastiveModel> model, const motion::Motion& empty,
               StyleCode style, std::vector<float> params, motion::PostProcessMode post,
               std::shared_ptr<const motion::StreamExamples> examples);
  // The output frame `emitted_` moved as the takes say (movement from
  // examples), and its own contacts noted for the cleaner.
  void Move(motion::Motion* one);
  absl::Status RunSteps();  // Every queued step, one at a time.
  void Trim();              // Drops the input frames no longer needed.
  // The action gate: the content's action read from the rows frame
  // emitted_ may read, handed to the followers.
  void ReadActions();

  std::shared_ptr<const ContrastiveModel> model_;
  const int dim_, shift_, lookahead_;
  StyleSchedule schedule_;     // The style over the frames.
  std::vector<float> params_;  // The generator's parameters for the current code.
  double strength_;            // The strength of the step running.
  motion::FeatureStream features_;
  LiveCarry carry_;
  std::deque<std::vector<float>> queue_;   // Normalized feature frames to step.
  std::deque<std::vector<float>> recent_;  // The last shift + 1 stepped (keep_path).
  std::vector<float> out_;                 // The running step's output.
  int64_t stepped_ = 0;                    // Feature frames stepped.
  motion::FeatureClip generated_;          // Denormalized, waiting to be decoded.
  motion::Motion input_;                   // Held input frames from base_ on.
  const motion::Motion empty_;             // No frames: what an empty result copies.
  int64_t base_ = 0, received_ = 0, emitted_ = 0;
  bool ended_ = false;
  motion::DecodeState decode_;
  StreamCleaner cleaner_;
  // Movement from examples (model/movement.h, motion/live_movement.h): the
  // content as it arrives, the takes playing and, during a change of style's
  // fade, the last style's; per generated frame not yet moved, its style.
  struct FrameStyle {
    double strength, fade;
    int generation;
    std::shared_ptr<const motion::StreamExamples> examples;
  };
  motion::FollowOptions follow_;
  std::optional<motion::ContentTrack> track_;
  std::unique_ptr<motion::MovementFollower> follower_, fading_;
  int generation_ = 0;
  FrameStyle step_style_ = {1, 1, 0, nullptr};  // The running step's.
  std::deque<FrameStyle> frame_styles_;
  std::vector<motion::Vec3> moved_euler_;
  // The action gate (MovementKeys::movement_action_gate): the content's
  // last normalized feature rows (row i is frame i's), read by the
  // package's content guard every few frames; its last reading.
  std::deque<std::vector<float>> action_rows_;
  int64_t action_rows_end_ = 0;  // Rows pushed so far.
  std::vector<double> actions_;
  std::vector<std::optional<std::array<bool, 4>>> contacts_;  // Since TakeContacts.
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_LIVE_STREAMER_H_
