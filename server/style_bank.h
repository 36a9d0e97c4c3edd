// Named style codes saved by EncodeStyle, per model (a code only means
// something to the model that made it). Kept in memory for the server's
// lifetime.
//
// Thread-safety: all methods may be called concurrently.
#ifndef STYLUS_SERVER_STYLE_BANK_H_
#define STYLUS_SERVER_STYLE_BANK_H_

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "model/style_model.h"

namespace stylus::server {

class StyleBank {
 public:
  // At most `max_per_model` names per model (0: no cap).
  explicit StyleBank(int max_per_model = 0) : max_per_model_(max_per_model) {}

  // INVALID_ARGUMENT for an empty name or one longer than 200 characters;
  // RESOURCE_EXHAUSTED for a new name when the model has its most (saving
  // over a name already there is always allowed).
  absl::Status Save(const std::string& model_id, const std::string& name, model::StyleCode code);
  // NOT_FOUND names the model and the style, and the models the name is
  // saved for instead, if any.
  absl::StatusOr<model::StyleCode> Get(const std::string& model_id, const std::string& name) const;
  // The names saved for `model_id`, sorted.
  std::vector<std::string> Names(const std::string& model_id) const;

 private:
  const int max_per_model_;
  mutable absl::Mutex mu_;
  std::map<std::pair<std::string, std::string>, model::StyleCode> codes_ ABSL_GUARDED_BY(mu_);
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_STYLE_BANK_H_
