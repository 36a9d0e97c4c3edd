#include "server/postprocess_option.h"

namespace stylus::server {

absl::Status ToPostProcessMode(v1::PostProcess mode) {
  switch (mode) {
    case v1::POSTPROCESS_DEFAULT:
    case v1::POSTPROCESS_NONE:
      return absl::OkStatus();
    default:
      return absl::UnimplementedError("post-processing 'feet' and 'full' are not available yet");
  }
}

}  // namespace stylus::server
