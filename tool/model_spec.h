// Model directories and content/style pairs as the offline commands take them.
#ifndef STYLUS_TOOL_MODEL_SPEC_H_
#define STYLUS_TOOL_MODEL_SPEC_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "model/style_model.h"
#include "motion/motion.h"
#include "motion/postprocess.h"

namespace stylus::tool {

// A model directory of any family, optionally followed by inference keys to
// set on top of its config.txt, each as ":KEY=VALUE" (docs/config.md);
// ":kc=N" is short for ":kc_iters=N". E.g. "models/cyclic/v2:kc_iters=100".
absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec);

// The main model (labelled by its spec) and each comparison, given as
// LABEL=SPEC (a --compare value), in that order.
struct NamedModel {
  std::string label;
  std::unique_ptr<model::StyleModel> model;
};
absl::StatusOr<std::vector<NamedModel>> LoadModelAndComparisons(
    const std::string& spec, const std::vector<std::string>& compare);

// Each model's transfer of `content` in the style of `style`, in order.
absl::StatusOr<std::vector<motion::Motion>> TransferWithEach(const std::vector<NamedModel>& models,
                                                             const motion::Motion& content,
                                                             const motion::Motion& style,
                                                             motion::PostProcessMode post);

// A --pair value, CONTENT.bvh,STYLE.bvh: both clips, read, with their paths.
struct ClipPair {
  motion::Motion content, style;
  std::string content_path, style_path;
};
absl::StatusOr<ClipPair> ReadClipPair(const std::string& pair);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_MODEL_SPEC_H_
