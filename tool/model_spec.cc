#include "tool/model_spec.h"

#include <vector>

#include "absl/strings/str_split.h"
#include "model/family_registry.h"

namespace stylus::tool {

absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec) {
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  model::ConfigOverrides overrides;
  for (size_t i = 1; i < parts.size(); ++i) {
    const std::vector<std::string> kv = absl::StrSplit(parts[i], absl::MaxSplits('=', 1));
    if (kv.size() != 2 || kv[0].empty()) {
      return absl::InvalidArgumentError("'" + spec + "': ':" + parts[i] +
                                        "' is not KEY=VALUE (e.g. :kc_iters=0)");
    }
    overrides.emplace_back(kv[0] == "kc" ? "kc_iters" : kv[0], kv[1]);
  }
  return model::LoadStyleModel(parts[0], overrides);
}

}  // namespace stylus::tool
