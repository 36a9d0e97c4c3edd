// The post-processing option of a request.
#ifndef STYLUS_SERVER_POSTPROCESS_OPTION_H_
#define STYLUS_SERVER_POSTPROCESS_OPTION_H_

#include "absl/status/status.h"
#include "stylus/v1/stylus.pb.h"

namespace stylus::server {

// OK for the modes this server applies; UNIMPLEMENTED names the others.
absl::Status ToPostProcessMode(v1::PostProcess mode);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_POSTPROCESS_OPTION_H_
