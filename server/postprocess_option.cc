#include "server/postprocess_option.h"

#include "absl/strings/str_cat.h"

namespace stylus::server {

absl::StatusOr<motion::PostProcessMode> ToPostProcessMode(v1::PostProcess mode) {
  switch (mode) {
    case v1::POSTPROCESS_DEFAULT:
    case v1::POSTPROCESS_FULL:
      return motion::PostProcessMode::kFull;
    case v1::POSTPROCESS_NONE:
      return motion::PostProcessMode::kNone;
    case v1::POSTPROCESS_FEET:
      return motion::PostProcessMode::kFeet;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("unknown postprocess value ", static_cast<int>(mode)));
  }
}

}  // namespace stylus::server
