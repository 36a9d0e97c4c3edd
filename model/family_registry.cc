#include "model/family_registry.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "model/config_text.h"
#include "model/contrastive/contrastive_model.h"
#include "model/cyclic/cyclic_model.h"

namespace stylus::model {

const std::vector<ModelFamily>& ModelFamilies() {
  static const std::vector<ModelFamily>* families =
      new std::vector<ModelFamily>{ContrastiveFamily(), CyclicFamily()};
  return *families;
}

absl::StatusOr<const ModelFamily*> FindFamily(const std::string& name) {
  std::vector<std::string> known;
  for (const ModelFamily& f : ModelFamilies()) {
    if (f.name == name) return &f;
    known.push_back(f.name);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown family '", name, "' (known: ", absl::StrJoin(known, ", "), ")"));
}

bool IsServedFamily(const std::string& name) { return FindFamily(name).ok(); }

namespace {

absl::StatusOr<const ModelFamily*> FamilyOf(const std::string& dir) {
  absl::StatusOr<std::string> name = ReadConfigFamily(dir);
  if (!name.ok()) return name.status();
  absl::StatusOr<const ModelFamily*> family = FindFamily(*name);
  if (!family.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/config.txt: ", family.status().message()));
  }
  return family;
}

}  // namespace

absl::StatusOr<ModelSummary> ReadPackageHeader(const std::string& dir) {
  absl::StatusOr<const ModelFamily*> family = FamilyOf(dir);
  if (!family.ok()) return family.status();
  return (*family)->read_header(dir);
}

absl::StatusOr<std::unique_ptr<StyleModel>> LoadStyleModel(const std::string& dir,
                                                           const ConfigOverrides& overrides) {
  absl::StatusOr<const ModelFamily*> family = FamilyOf(dir);
  if (!family.ok()) return family.status();
  const std::vector<std::string>& keys = (*family)->inference_keys;
  std::string text;
  for (const auto& [key, value] : overrides) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat(dir, ": '", key, "' is not an inference key of the ", (*family)->name,
                       " family (inference keys: ", absl::StrJoin(keys, ", "), ")"));
    }
    AppendConfigLine(&text, key, value);
  }
  return (*family)->load(dir, text);
}

}  // namespace stylus::model
