// Causal post-processing of a stream's output (motion/postprocess.h): each
// batch of new output frames is cleaned together with the last frames already
// sent (their history) against the input frames held, which may run ahead of
// the output (a streamer's look-ahead). Contacts come from the input frames
// held; a locked foot is pinned where it was at the start of its contact;
// the new frames' Euler angles continue from the last frame sent. Used by
// the streamers of every family.
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_STREAM_CLEANER_H_
#define STYLUS_MODEL_STREAM_CLEANER_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "motion/humanoid.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::model {

class StreamCleaner {
 public:
  // `empty`: a motion of no frames on the stream's skeleton and frame time.
  // `history`: output frames kept and re-cleaned with each batch.
  StreamCleaner(const motion::Motion& empty, const motion::HumanoidRoles& roles,
                motion::PostProcessMode post, int history);

  // Cleans output frames [first, first + raw.num_frames) (stream indices,
  // following the frames cleaned before). `input` holds stream frames
  // [input_base, input_base + input.num_frames), at least from
  // first - history (or the stream's start) on; the frames from `input_end`
  // on (when >= 0) are not read.
  absl::StatusOr<motion::Motion> Clean(const motion::Motion& raw, int64_t first,
                                       const motion::Motion& input, int64_t input_base,
                                       int64_t input_end = -1);

  // The first stream frame Clean will read from `input` for output starting
  // at `first`.
  int64_t FirstInputNeeded(int64_t first) const;
  motion::PostProcessMode mode() const { return post_; }

 private:
  const motion::HumanoidRoles& roles_;
  motion::PostProcessMode post_;
  int history_;
  motion::Motion done_;    // The last output frames sent (history).
  int64_t done_base_ = 0;  // Stream index of done_'s first frame.
  // What each call hands to PostProcess, kept so that the skeleton is not
  // copied per call.
  motion::Motion output_, content_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_STREAM_CLEANER_H_
