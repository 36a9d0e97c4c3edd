// Loading a network's weights from a package (internal to model/: LibTorch).
#ifndef STYLUS_MODEL_WEIGHTS_IO_H_
#define STYLUS_MODEL_WEIGHTS_IO_H_

#include <torch/torch.h>

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
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

// What CopyTensorsByName did: how many of `to`'s `total` tensors it set, and
// the names of `from`'s tensors that `to` has no place for.
struct TensorCopy {
  int copied = 0, total = 0;
  std::vector<std::string> unplaced;
};

// Fine-tuning from a package of another configuration: copies each tensor of
// `from` into the tensor of `to` of the same name; tensors only `to` has keep
// their values. INVALID_ARGUMENT naming `source` and the tensor when the two
// differ in shape.
template <typename From, typename To>
absl::StatusOr<TensorCopy> CopyTensorsByName(const From& from, To& to, const std::string& source) {
  torch::NoGradGuard no_grad;
  auto mine = to->named_parameters();
  TensorCopy copy;
  copy.total = static_cast<int>(mine.size());
  for (const auto& t : from->named_parameters()) {
    torch::Tensor* m = mine.find(t.key());
    if (m == nullptr) {
      copy.unplaced.push_back(t.key());
      continue;
    }
    if (m->sizes() != t.value().sizes()) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": its '", t.key(), "' has another shape than this network's"));
    }
    m->copy_(t.value());
    ++copy.copied;
  }
  return copy;
}

}  // namespace stylus::model

#endif  // STYLUS_MODEL_WEIGHTS_IO_H_
