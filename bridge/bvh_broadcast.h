// BVH broadcast, the stream Axis Neuron and Axis Studio (Noitom) send of a
// performer's motion, and engines' Neuron plug-ins receive:
//
// - text (TCP): a frame is "<avatar index> <avatar name> <value> ... ||",
//   tokens separated by spaces, frames by "||" (and usually a line end).
// - binary (UDP): a frame is a 64-byte little-endian header, token 0xDDFF at
//   byte 0, the value count (uint16) at byte 6, "with displacement" at 8,
//   "with reference" at 9, the avatar index (uint32) at 10, its name (32
//   bytes, NUL padded) at 14, the frame index (uint32) at 46, token 0xEEFF at
//   62; then that many float32 values.
//
// The values are the BVH channels of the capture software's skeleton, in
// its file's order: with displacement every joint has six (position, then
// rotation), without it the root six and every other joint three. The
// skeleton itself is not sent: the stage exports it as a BVH file.
#ifndef STYLUS_BRIDGE_BVH_BROADCAST_H_
#define STYLUS_BRIDGE_BVH_BROADCAST_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/motion.h"

namespace stylus::bridge {

struct BroadcastFrame {
  int avatar_index = 0;
  std::string avatar_name;
  std::vector<double> values;
  int64_t frame_index = -1;  // Binary frames only.
};

// Splits a TCP text stream into frames. Bytes come in any pieces; a frame is
// taken when its "||" arrives. Bounded: text without a "||" within
// kMaxFrameBytes is dropped as malformed, so a peer cannot grow the buffer.
class BroadcastTextReader {
 public:
  static constexpr size_t kMaxFrameBytes = 256 * 1024;

  // Appends `bytes` and returns the frames they complete; frames that do not
  // parse (too few tokens, a value that is not a finite number) are counted
  // in malformed() and skipped.
  std::vector<BroadcastFrame> Feed(absl::string_view bytes);
  int64_t malformed() const { return malformed_; }

 private:
  std::string pending_;
  int64_t malformed_ = 0;
};

// One frame in the text form, "||" and a line end included.
std::string FormatBroadcastText(const BroadcastFrame& frame);

// The binary form: one datagram per frame. INVALID_ARGUMENT for a short or
// foreign datagram (it says which), or values that are not finite.
absl::StatusOr<BroadcastFrame> ParseBroadcastBinary(absl::string_view datagram);
std::string FormatBroadcastBinary(const BroadcastFrame& frame, bool with_displacement);

// A frame's values as a row of `skeleton` (the stage's BVH file). Values
// with displacement on a file without it keep the root's position and every
// joint's rotation. INVALID_ARGUMENT when the count fits neither form: the
// message says both counts and what to check.
absl::StatusOr<std::vector<double>> BroadcastRow(const motion::Skeleton& skeleton,
                                                 const std::vector<double>& values);

}  // namespace stylus::bridge

#endif  // STYLUS_BRIDGE_BVH_BROADCAST_H_
