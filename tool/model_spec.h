// Model directories as the offline commands take them.
#ifndef STYLUS_TOOL_MODEL_SPEC_H_
#define STYLUS_TOOL_MODEL_SPEC_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "model/style_model.h"

namespace stylus::tool {

// A model directory of any family, optionally followed by inference keys to
// set on top of its config.txt, each as ":KEY=VALUE" (docs/config.md);
// ":kc=N" is short for ":kc_iters=N". E.g. "models/cyclic/v2:kc_iters=100".
absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_MODEL_SPEC_H_
