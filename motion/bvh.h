// BVH (Biovision Hierarchy) reading and writing.
//
// The reader accepts any hierarchy with one ROOT, 0-6 channels per joint (3 or 6
// in practice), any Euler order per joint, tabs or spaces, LF, CRLF or CR line
// ends. Every malformed input is an INVALID_ARGUMENT status of the form
// "<source>:<line>: <what was expected>"; it never crashes, never recurses, and
// never sizes an allocation from an unchecked header count. Thread-safe.
#ifndef STYLUS_MOTION_BVH_H_
#define STYLUS_MOTION_BVH_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/motion.h"

namespace stylus::motion {

struct BvhLimits {
  int max_joints = 10000;
  int64_t max_frames = 10'000'000;
  int64_t max_file_bytes = int64_t{2} << 30;
};

// Parses BVH text; `source` names it in error messages (usually the path).
absl::StatusOr<Motion> ParseBvh(absl::string_view text, absl::string_view source,
                                const BvhLimits& limits = {});

// Reads and parses a file. NOT_FOUND when it cannot be opened.
absl::StatusOr<Motion> ReadBvhFile(const std::string& path, const BvhLimits& limits = {});

// BVH text for `motion`: the same hierarchy and channel layout, values in their
// shortest exact decimal form, so reading it back gives the same numbers.
std::string FormatBvh(const Motion& motion);

// Writes FormatBvh(motion) to `path` through a temporary file renamed into
// place, so a failed write never leaves a half-written file behind.
absl::Status WriteBvhFile(const Motion& motion, const std::string& path);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_BVH_H_
