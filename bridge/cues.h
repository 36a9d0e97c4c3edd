// A cue file for stylus-bridge --cues: the show's style changes in time.
// One cue per line, "SECONDS style NAME-OR-CLIP" or "SECONDS strength K"
// (seconds from the bridge's start, increasing; '#' starts a comment).
#ifndef STYLUS_BRIDGE_CUES_H_
#define STYLUS_BRIDGE_CUES_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace stylus::bridge {

struct Cue {
  double seconds = 0;
  bool strength = false;  // Else a style.
  std::string style;
  double value = 1;
};

// INVALID_ARGUMENT "<source>:<line>: ..." for a malformed line, a time out
// of order or a strength outside [0, 1].
absl::StatusOr<std::vector<Cue>> ParseCues(absl::string_view text, absl::string_view source);

}  // namespace stylus::bridge

#endif  // STYLUS_BRIDGE_CUES_H_
