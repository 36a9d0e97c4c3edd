// Style schedules from a text file, for `stylus interpolate --schedule`:
// keyframes "FRAME W1 W2 ..." (one weight per style; spaces, tabs or commas
// between them; '#' starts a comment), frames in increasing order. The
// weights are held before the first keyframe and after the last, and run
// linearly between keyframes.
#ifndef STYLUS_CLIENT_SCHEDULE_FILE_H_
#define STYLUS_CLIENT_SCHEDULE_FILE_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace stylus {

// One row of `num_styles` weights per frame of a `num_frames`-frame content.
// INVALID_ARGUMENT "<source>:<line>: ..." for a malformed line, a frame out
// of order, the wrong number of weights or a weight that is not finite;
// "<source>: no keyframes" for a file without one.
absl::StatusOr<std::vector<std::vector<double>>> ParseSchedule(absl::string_view text,
                                                               absl::string_view source,
                                                               int num_styles, int num_frames);

}  // namespace stylus

#endif  // STYLUS_CLIENT_SCHEDULE_FILE_H_
