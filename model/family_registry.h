// The model families this build serves, by name: how to load a package of
// each and read its header without its weights. Adding a family is a folder
// under model/ and one line in family_registry.cc.
#ifndef STYLUS_MODEL_FAMILY_REGISTRY_H_
#define STYLUS_MODEL_FAMILY_REGISTRY_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "model/style_model.h"

namespace stylus::model {

// Inference keys set on top of a package's config.txt when loading it, in
// order ("kc_iters", "0"). Only a family's inference keys may be set.
using ConfigOverrides = std::vector<std::pair<std::string, std::string>>;

struct ModelFamily {
  std::string name;
  // The package in `dir` with `overrides` (config.txt lines) applied.
  absl::StatusOr<std::unique_ptr<StyleModel>> (*load)(const std::string& dir,
                                                      const std::string& overrides);
  absl::StatusOr<ModelSummary> (*read_header)(const std::string& dir);
  // The config keys that change inference only (docs/config.md).
  std::vector<std::string> inference_keys;
};

// The entry of a family whose model class `Model` has
// `static StatusOr<unique_ptr<Model>> Load(dir, overrides)` and whose config
// `Config` has `Read(dir)`, the header fields and `InferenceKeys()`.
template <typename Model, typename Config>
ModelFamily MakeFamily(std::string name) {
  ModelFamily f;
  f.name = std::move(name);
  f.load = [](const std::string& dir,
              const std::string& overrides) -> absl::StatusOr<std::unique_ptr<StyleModel>> {
    absl::StatusOr<std::unique_ptr<Model>> m = Model::Load(dir, overrides);
    if (!m.ok()) return m.status();
    return std::unique_ptr<StyleModel>(*std::move(m));
  };
  f.read_header = [](const std::string& dir) -> absl::StatusOr<ModelSummary> {
    absl::StatusOr<Config> c = Config::Read(dir);
    if (!c.ok()) return c.status();
    return ModelSummary{c->family, c->window, c->hop, c->dim, c->trained_iterations};
  };
  f.inference_keys = Config::InferenceKeys();
  return f;
}

// Every family of this build.
const std::vector<ModelFamily>& ModelFamilies();
// The family named `name`; INVALID_ARGUMENT listing the known ones otherwise.
absl::StatusOr<const ModelFamily*> FindFamily(const std::string& name);
bool IsServedFamily(const std::string& name);

// The header of the package in `dir` (its config.txt only): NOT_FOUND when
// missing, INVALID_ARGUMENT for an unknown family or a malformed config.
absl::StatusOr<ModelSummary> ReadPackageHeader(const std::string& dir);

// Loads the package in `dir` with the family its config.txt names.
// INVALID_ARGUMENT for an unknown family or an override of a key that is not
// one of that family's inference keys; otherwise the family's own errors.
absl::StatusOr<std::unique_ptr<StyleModel>> LoadStyleModel(const std::string& dir,
                                                           const ConfigOverrides& overrides = {});

}  // namespace stylus::model

#endif  // STYLUS_MODEL_FAMILY_REGISTRY_H_
