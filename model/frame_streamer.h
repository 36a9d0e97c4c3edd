// What a stream session drives, whichever family serves it: frames go in as
// they arrive and stylized frames come out, in order, once final.
#ifndef STYLUS_MODEL_FRAME_STREAMER_H_
#define STYLUS_MODEL_FRAME_STREAMER_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::model {

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
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_FRAME_STREAMER_H_
