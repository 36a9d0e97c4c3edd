#include "tool/model_spec.h"

#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "model/cyclic_model.h"

namespace stylus::tool {

absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec) {
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  if (parts.size() == 1) return model::LoadStyleModel(spec);
  model::CyclicOptions options;
  for (size_t i = 1; i < parts.size(); ++i) {
    if (parts[i] == "adain") {
      options.adain = true;
    } else if (absl::StartsWith(parts[i], "kc=")) {
      if (!absl::SimpleAtoi(parts[i].substr(3), &options.kc_iters) || options.kc_iters < 0) {
        return absl::InvalidArgumentError("'" + spec + "': :kc= wants a whole number >= 0");
      }
    } else {
      return absl::InvalidArgumentError("'" + spec + "': unknown option ':" + parts[i] +
                                        "' (known: :kc=N, :adain)");
    }
  }
  auto m = model::CyclicModel::Load(parts[0], options);
  if (!m.ok()) return m.status();
  return std::unique_ptr<model::StyleModel>(*std::move(m));
}

}  // namespace stylus::tool
