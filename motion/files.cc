#include "motion/files.h"

#include <cstdio>
#include <fstream>

#include "absl/strings/str_cat.h"

namespace stylus::motion {

absl::Status WriteFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return absl::PermissionDeniedError(absl::StrCat(path, ": cannot open for writing"));
    f.write(text.data(), static_cast<std::streamsize>(text.size()));
    f.close();
    if (!f) {
      std::remove(tmp.c_str());
      return absl::InternalError(absl::StrCat(path, ": write failed (disk full?)"));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return absl::InternalError(absl::StrCat(path, ": cannot move the written file into place"));
  }
  return absl::OkStatus();
}

}  // namespace stylus::motion
