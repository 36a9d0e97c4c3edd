#include "server/style_bank.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace stylus::server {

absl::Status StyleBank::Save(const std::string& model_id, const std::string& name,
                             model::StyleCode code) {
  if (name.empty() || name.size() > 200) {
    return absl::InvalidArgumentError("a style name must have 1 to 200 characters");
  }
  // A saved style keeps its code and cadence, not its clip: the bank's
  // memory stays a few values per name whatever clips clients send. Its
  // movement comes from the server's style library (a saved style named as
  // one of the library's styles uses that style's takes; docs/movement.md).
  code.example = nullptr;
  absl::MutexLock lock(&mu_);
  auto it = codes_.find({model_id, name});
  if (it != codes_.end()) {
    it->second = std::move(code);
    return absl::OkStatus();
  }
  // Keys sort by model first: the model's names are one run from here.
  int count = 0;
  for (auto m = codes_.lower_bound({model_id, ""}); m != codes_.end() && m->first.first == model_id;
       ++m) {
    ++count;
  }
  if (max_per_model_ > 0 && count >= max_per_model_) {
    return absl::ResourceExhaustedError(
        absl::StrCat("model ", model_id, " already has its most saved styles (", max_per_model_,
                     ", --max-saved-styles); save over a name already there"));
  }
  codes_.emplace(std::make_pair(model_id, name), std::move(code));
  return absl::OkStatus();
}

std::vector<std::string> StyleBank::Names(const std::string& model_id) const {
  absl::MutexLock lock(&mu_);
  std::vector<std::string> names;
  for (auto m = codes_.lower_bound({model_id, ""}); m != codes_.end() && m->first.first == model_id;
       ++m) {
    names.push_back(m->first.second);
  }
  return names;
}

absl::StatusOr<model::StyleCode> StyleBank::Get(const std::string& model_id,
                                                const std::string& name) const {
  absl::MutexLock lock(&mu_);
  auto it = codes_.find({model_id, name});
  if (it == codes_.end()) {
    // Saved names belong to one model: say where this one is saved, if
    // anywhere (codes live in each model's own space).
    std::vector<std::string> elsewhere;
    for (const auto& [key, code] : codes_) {
      if (key.second == name) elsewhere.push_back(key.first);
    }
    return absl::NotFoundError(absl::StrCat(
        "no style named '", name, "' saved for model ", model_id,
        elsewhere.empty()
            ? " (save one with EncodeStyle save_as)"
            : absl::StrCat(" (saved names belong to one model; '", name, "' is saved for ",
                           absl::StrJoin(elsewhere, ", "), ": save it again on ", model_id,
                           " with EncodeStyle save_as and model ", model_id, ")")));
  }
  return it->second;
}

}  // namespace stylus::server
