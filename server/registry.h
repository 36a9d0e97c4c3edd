// The models a server hosts, keyed by id "<name>/<version>" (a directory
// models/<name>/<version>/ under the server's model root). Models are loaded
// at start-up or by LoadModel, never inside a transfer request (house rule 4).
//
// Thread-safety: all methods may be called concurrently. A model handed out
// stays valid for as long as the caller holds it, even if it is unloaded.
#ifndef STYLUS_SERVER_REGISTRY_H_
#define STYLUS_SERVER_REGISTRY_H_

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "model/style_model.h"

namespace stylus::server {

struct HostedModel {
  std::string id;  // "<name>/<version>"
  std::shared_ptr<const model::StyleModel> model;
};

class ModelRegistry {
 public:
  // Loads every servable package under `root` (directories
  // <root>/<name>/<version>/ whose config.txt names a served family; other
  // packages, such as the evaluation judges, are skipped). The default is
  // `default_id` when not empty, else the id the file <root>/DEFAULT names
  // (model::ReadDefaultPackage) when there is one, else the first id in
  // sorted order; a named default must be among the packages (NOT_FOUND
  // says which file or flag named it). NOT_FOUND when `root` does not exist;
  // the status of the first package that fails to load otherwise.
  static absl::StatusOr<std::unique_ptr<ModelRegistry>> Create(const std::string& root,
                                                               const std::string& default_id);

  // The model `id` names: "<name>/<version>", or "<name>" for its highest
  // version (versions "v<number>" by number, v10 after v2, and after other
  // names), or "" for the default. NOT_FOUND names what is available.
  absl::StatusOr<HostedModel> Get(const std::string& id) const;
  std::vector<HostedModel> List() const;
  std::string default_id() const;

  // Loads <root>/<id>/ (id "<name>/<version>"). ALREADY_EXISTS if loaded;
  // INVALID_ARGUMENT for an id that is not of that form; the package's own
  // error otherwise.
  absl::StatusOr<HostedModel> Load(const std::string& id);
  // NOT_FOUND if not loaded; FAILED_PRECONDITION for the default model,
  // which stays loaded for as long as the server runs (calls that name no
  // model use it).
  absl::Status Unload(const std::string& id);

 private:
  explicit ModelRegistry(std::string root) : root_(std::move(root)) {}

  const std::string root_;
  mutable absl::Mutex mu_;
  std::map<std::string, std::shared_ptr<const model::StyleModel>> models_ ABSL_GUARDED_BY(mu_);
  std::string default_id_ ABSL_GUARDED_BY(mu_);
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_REGISTRY_H_
