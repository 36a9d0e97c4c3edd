// Small file helpers shared by every layer that writes results to disk.
#ifndef STYLUS_MOTION_FILES_H_
#define STYLUS_MOTION_FILES_H_

#include <string>

#include "absl/status/status.h"

namespace stylus::motion {

// Writes `text` to `path` through `path.tmp` renamed into place, so readers
// never see a half-written file. PERMISSION_DENIED when the file cannot be
// opened (the message names the path), INTERNAL when writing or renaming fails.
absl::Status WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_FILES_H_
