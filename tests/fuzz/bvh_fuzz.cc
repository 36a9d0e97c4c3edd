// libFuzzer target: the BVH reader on arbitrary bytes. What parses must
// format and parse back to the same shape (scripts/fuzz bvh SECONDS).
#include <cstdint>
#include <cstdlib>

#include "motion/bvh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using stylus::motion::Motion;
  // Limits small enough that a header cannot ask for gigabytes.
  stylus::motion::BvhLimits limits;
  limits.max_joints = 512;
  limits.max_frames = 100000;
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<Motion> motion = stylus::motion::ParseBvh(text, "fuzz", limits);
  if (!motion.ok()) return 0;
  absl::StatusOr<Motion> again =
      stylus::motion::ParseBvh(stylus::motion::FormatBvh(*motion), "formatted", limits);
  if (!again.ok() || again->num_frames != motion->num_frames ||
      again->skeleton.num_joints() != motion->skeleton.num_joints() ||
      again->values.size() != motion->values.size()) {
    std::abort();  // A clip the writer cannot round-trip.
  }
  return 0;
}
