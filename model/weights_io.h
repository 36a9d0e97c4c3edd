// Loading a network's weights from a package (internal to model/: LibTorch).
#ifndef STYLUS_MODEL_WEIGHTS_IO_H_
#define STYLUS_MODEL_WEIGHTS_IO_H_

#include <torch/torch.h>

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace stylus::model {

// Loads `path` into `net` and checks every parameter kept the shape the
// configuration gave it (torch::load adopts whatever the archive holds).
// INVALID_ARGUMENT naming the file for a corrupt archive or a mismatch.
template <typename Holder>
absl::Status LoadWeights(Holder& net, const std::string& path) {
  try {
    std::vector<std::vector<int64_t>> expected;
    for (const auto& p : net->named_parameters()) expected.push_back(p.value().sizes().vec());
    torch::load(net, path);
    size_t i = 0;
    for (const auto& p : net->named_parameters()) {
      if (i >= expected.size() || p.value().sizes().vec() != expected[i]) {
        return absl::InvalidArgumentError(absl::StrCat(
            path, ": parameter '", p.key(), "' does not have the shape config.txt implies"));
      }
      ++i;
    }
  } catch (const std::exception& e) {
    std::string what = e.what();
    what = what.substr(0, what.find('\n'));
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": cannot load weights (corrupt, or made for another configuration): ", what));
  }
  return absl::OkStatus();
}

}  // namespace stylus::model

#endif  // STYLUS_MODEL_WEIGHTS_IO_H_
