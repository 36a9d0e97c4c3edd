// libFuzzer target: a package's normalization statistics file. What parses
// must serialize and parse back to the same width.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "motion/normalization.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using stylus::motion::NormStats;
  const std::string text(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<NormStats> stats = NormStats::Parse(text, "norm.txt");
  if (!stats.ok()) return 0;
  absl::StatusOr<NormStats> again = NormStats::Parse(stats->Serialize(), "serialized");
  if (!again.ok() || again->dim() != stats->dim()) std::abort();
  return 0;
}
