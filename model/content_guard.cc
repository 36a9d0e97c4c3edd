#include "model/content_guard.h"

#include <torch/torch.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "model/config_text.h"
#include "model/guard_net.h"
#include "model/weights_io.h"

namespace stylus::model {

std::string ContentGuardInfoPath(const std::string& dir) { return dir + "/guard.txt"; }
std::string ContentGuardWeightsPath(const std::string& dir, int k) {
  return absl::StrCat(dir, "/guard_", k, ".pt");
}

struct ContentGuard::Impl {
  std::vector<std::string> styles, contents;
  int guards = 1;
  int window = 0, hop = 0;
  std::vector<GuardNet> nets;
};

ContentGuard::ContentGuard(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ContentGuard::~ContentGuard() = default;
const std::vector<std::string>& ContentGuard::contents() const { return impl_->contents; }

absl::StatusOr<std::unique_ptr<ContentGuard>> ContentGuard::Load(const std::string& dir, int dim,
                                                                 int window, int hop) {
  const std::string info_path = ContentGuardInfoPath(dir);
  std::ifstream file(info_path);
  if (!file) {
    return absl::NotFoundError(info_path + ": missing (train it with stylus-tool train-guard)");
  }
  std::stringstream text;
  text << file.rdbuf();
  auto impl = std::make_unique<Impl>();
  impl->window = window;
  impl->hop = hop;
  absl::Status parsed =
      ParseConfigText(text.str(), info_path, [&impl](const ConfigEntry& e) -> absl::Status {
        if (e.key == "styles" || e.key == "contents") {
          std::vector<std::string> labels = absl::StrSplit(e.value, ',', absl::SkipEmpty());
          if (labels.size() < 2) return e.Error("needs at least two labels");
          (e.key == "styles" ? impl->styles : impl->contents) = std::move(labels);
        }
        if (e.key == "guards") return e.Int(&impl->guards, 1, 16);
        return absl::OkStatus();  // Provenance and accuracy: informational.
      });
  if (!parsed.ok()) return parsed;
  if (impl->styles.empty() || impl->contents.empty()) {
    return absl::InvalidArgumentError(info_path + ": missing 'styles' or 'contents'");
  }
  for (int k = 1; k <= impl->guards; ++k) {
    const std::string path = ContentGuardWeightsPath(dir, k);
    if (!std::filesystem::exists(path)) {
      return absl::NotFoundError(path + ": missing (train it with stylus-tool train-guard)");
    }
    GuardNet net(dim, static_cast<int>(impl->styles.size()),
                 static_cast<int>(impl->contents.size()));
    if (absl::Status s = LoadWeights(net, path); !s.ok()) return s;
    net->eval();
    impl->nets.push_back(net);
  }
  return std::unique_ptr<ContentGuard>(new ContentGuard(std::move(impl)));
}

std::vector<double> ContentGuard::Probabilities(const motion::FeatureClip& normalized) const {
  c10::InferenceMode guard;
  torch::Tensor sum;
  for (GuardNet& net : impl_->nets) {
    const torch::Tensor p = ClipContentProbabilities(net, normalized, impl_->window, impl_->hop);
    sum = sum.defined() ? sum + p : p;
  }
  const torch::Tensor mean = (sum / static_cast<double>(impl_->nets.size())).contiguous();
  return std::vector<double>(mean.data_ptr<double>(), mean.data_ptr<double>() + mean.numel());
}

bool ContentGuard::Keeps(const motion::FeatureClip& normalized, int action,
                         double min_probability) const {
  const std::vector<double> p = Probabilities(normalized);
  return std::max_element(p.begin(), p.end()) - p.begin() == action && p[action] >= min_probability;
}

int ContentGuard::Classify(const motion::FeatureClip& normalized) const {
  const std::vector<double> p = Probabilities(normalized);
  return static_cast<int>(std::max_element(p.begin(), p.end()) - p.begin());
}

}  // namespace stylus::model
