// The post-processing option of a request.
#ifndef STYLUS_SERVER_POSTPROCESS_OPTION_H_
#define STYLUS_SERVER_POSTPROCESS_OPTION_H_

#include "absl/status/statusor.h"
#include "motion/postprocess.h"
#include "stylus/v1/stylus.pb.h"

namespace stylus::server {

// DEFAULT is `full`. INVALID_ARGUMENT for a value this server does not know.
absl::StatusOr<motion::PostProcessMode> ToPostProcessMode(v1::PostProcess mode);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_POSTPROCESS_OPTION_H_
