#include "server/style_bank.h"

#include "absl/strings/str_cat.h"

namespace stylus::server {

absl::Status StyleBank::Save(const std::string& model_id, const std::string& name,
                             model::StyleCode code) {
  if (name.empty() || name.size() > 200) {
    return absl::InvalidArgumentError("a style name must have 1 to 200 characters");
  }
  absl::MutexLock lock(&mu_);
  codes_[{model_id, name}] = std::move(code);
  return absl::OkStatus();
}

absl::StatusOr<model::StyleCode> StyleBank::Get(const std::string& model_id,
                                                const std::string& name) const {
  absl::MutexLock lock(&mu_);
  auto it = codes_.find({model_id, name});
  if (it == codes_.end()) {
    return absl::NotFoundError(absl::StrCat("no style named '", name, "' saved for model ",
                                            model_id, " (save one with EncodeStyle save_as)"));
  }
  return it->second;
}

}  // namespace stylus::server
