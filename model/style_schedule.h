// A stream's style over its frames, changed while it runs: from a frame the
// client names, the style code, the strength, or both move to new values,
// cross-faded linearly over a number of frames (no pop in the joints).
// Torch-free; used by the live streamer (model/contrastive/live_streamer.h).
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_STYLE_SCHEDULE_H_
#define STYLUS_MODEL_STYLE_SCHEDULE_H_

#include <cstdint>
#include <deque>
#include <optional>

#include "absl/status/status.h"
#include "model/style_model.h"
#include "motion/live_movement.h"

namespace stylus::model {

// One change: from `from_frame` on (a stream frame index), the style code
// and/or the strength become the given ones, reached after `fade_frames`
// frames (0 or 1: at once).
struct StyleChange {
  int64_t from_frame = 0;
  std::optional<StyleCode> code;
  std::optional<double> strength;
  int fade_frames = 0;
  // With a code, for packages whose movement comes from examples: where the
  // new style's takes come from (ChooseStreamExamples), and the takes the
  // streamer chose from it.
  MovementRequest movement = {};
  std::shared_ptr<const motion::StreamExamples> examples = nullptr;
};

class StyleSchedule {
 public:
  StyleSchedule(StyleCode code, double strength);

  // Queues `change`. A change naming a frame before `earliest` (one already
  // generated) takes effect from `earliest`. INVALID_ARGUMENT for a change
  // with neither a code nor a strength, a code of another size, a strength
  // outside [0, 1], a negative fade, or a frame before a change already
  // queued; RESOURCE_EXHAUSTED when kMaxQueuedChanges wait already.
  absl::Status Add(StyleChange change, int64_t earliest);
  static constexpr int kMaxQueuedChanges = 64;

  // The code and strength at frame `t` (t never decreasing from one call to
  // the next). `changed` is true when either differs from the previous
  // call's.
  // `fade`: how far the latest change's fade has come (1 when done);
  // `generation` counts the changes of code begun so far, and `examples` are
  // the latest's takes (null: the first style's, or none).
  struct At {
    const StyleCode& code;
    double strength;
    bool changed;
    double fade = 1;
    int generation = 0;
    const std::shared_ptr<const motion::StreamExamples>* examples = nullptr;
  };
  At Advance(int64_t t);

  // Bytes held (codes of the fade and the changes queued).
  size_t bytes() const;

 private:
  StyleCode now_code_, from_code_, to_code_;
  double now_strength_, from_strength_, to_strength_;
  int64_t fade_start_ = 0;
  int fade_len_ = 0;
  bool fading_ = false;
  double fade_ = 1;
  int generation_ = 0;
  std::shared_ptr<const motion::StreamExamples> examples_;
  std::deque<StyleChange> queued_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_STYLE_SCHEDULE_H_
