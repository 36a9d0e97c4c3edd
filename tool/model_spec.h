// Model directories as the offline commands take them.
#ifndef STYLUS_TOOL_MODEL_SPEC_H_
#define STYLUS_TOOL_MODEL_SPEC_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "model/style_model.h"

namespace stylus::tool {

// A model directory of any family, optionally followed by options for a
// cyclic model: ":kc=N", N inference-time kinematic optimization steps
// instead of the package's (":kc=0": none), and ":adain", the AdaIN probe of
// CyclicOptions. E.g. "models/cyclic/v1:kc=0:adain".
absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_MODEL_SPEC_H_
