#include "tool/model_spec.h"

#include "absl/strings/numbers.h"
#include "model/cyclic_model.h"

namespace stylus::tool {

absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec) {
  const size_t colon = spec.rfind(":kc=");
  if (colon == std::string::npos) return model::LoadStyleModel(spec);
  model::CyclicOptions options;
  if (!absl::SimpleAtoi(spec.substr(colon + 4), &options.kc_iters) || options.kc_iters < 0) {
    return absl::InvalidArgumentError("'" + spec + "': :kc= wants a whole number >= 0");
  }
  auto m = model::CyclicModel::Load(spec.substr(0, colon), options);
  if (!m.ok()) return m.status();
  return std::unique_ptr<model::StyleModel>(*std::move(m));
}

}  // namespace stylus::tool
