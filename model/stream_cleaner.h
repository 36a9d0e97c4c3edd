// Causal post-processing of a stream's output (motion/postprocess.h): each
// batch of new output frames is cleaned together with the last frames already
// sent (their history) against the input frames held, which may run ahead of
// the output (a streamer's look-ahead). Contacts come from the input frames
// held; a locked foot is pinned where it was at the start of its contact;
// the new frames' Euler angles continue from the last frame sent. Used by
// the streamers of every family.
//
// The history's poses (local, and in the world as they were posed when new)
// and the input's world positions are kept between calls, so each frame is
// converted from Euler angles, smoothed, and posed once, and each input frame
// posed once (a live stream cleans one frame per call). The history is read
// as sent: its frames are final and are not smoothed again.
//
// Thread-safety: one per stream, used by one thread at a time.
#ifndef STYLUS_MODEL_STREAM_CLEANER_H_
#define STYLUS_MODEL_STREAM_CLEANER_H_

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::model {

class StreamCleaner {
 public:
  // `history`: output frames kept and read with each batch (as sent: they
  // are final and are not cleaned again).
  StreamCleaner(const motion::HumanoidRoles& roles, motion::PostProcessMode post, int history);

  // Cleans output frames [first, first + raw.num_frames) (stream indices,
  // following the frames cleaned before). `input` holds stream frames
  // [input_base, input_base + input.num_frames), at least from
  // first - history (or the stream's start) on; the frames from `input_end`
  // on (when >= 0) are not read.
  absl::StatusOr<motion::Motion> Clean(motion::Motion raw, int64_t first,
                                       const motion::Motion& input, int64_t input_base,
                                       int64_t input_end = -1);

  // The output's own foot contacts at stream frame `frame` (FootJoints
  // order; frames in order, each before it is cleaned), for a stream whose
  // steps are its own (motion/live_movement.h); nullopt: found on the input
  // as usual.
  void NoteContacts(int64_t frame, const std::optional<std::array<bool, 4>>& on);

  // The first stream frame Clean will read from `input` for output starting
  // at `first`.
  int64_t FirstInputNeeded(int64_t first) const;
  motion::PostProcessMode mode() const { return post_; }
  // Bytes of the frames it keeps between calls (the history's poses and
  // world poses, the input's world positions, the last Euler angles).
  size_t bytes() const;

 private:
  const motion::HumanoidRoles& roles_;
  motion::PostProcessMode post_;
  int history_;
  std::vector<motion::LocalPose> sent_;   // The last output frames sent (history).
  // Their world poses as post-processing posed them when they were new.
  std::vector<motion::GlobalPose> posed_;
  int64_t sent_base_ = 0;                 // Stream index of sent_'s first frame.
  std::vector<motion::Vec3> last_euler_;  // The last frame sent's Euler angles.
  // World positions of input frames [content_base_, content_base_ + size).
  std::vector<std::vector<motion::Vec3>> content_;
  int64_t content_base_ = 0;
  // Each foot's last contact: a stream frame of it and its pin.
  std::array<std::optional<std::pair<int64_t, motion::Vec3>>, 4> pins_;
  // Noted contacts of frames [own_base_, own_base_ + size).
  double floor_ = 1e300;  // The lowest the input's feet went so far.
  std::deque<std::optional<std::array<bool, 4>>> own_;
  int64_t own_base_ = 0;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_STREAM_CLEANER_H_
