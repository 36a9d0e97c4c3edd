#include "model/content_guard.h"

#include <torch/torch.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "model/clip_classes.h"
#include "model/config_text.h"
#include "model/cyclic_config.h"
#include "model/label_critic_net.h"
#include "model/package.h"
#include "model/training_set.h"
#include "model/weights_io.h"
#include "model/window_tensor.h"
#include "motion/dataset.h"
#include "motion/files.h"
#include "motion/windowing.h"

namespace stylus::model {
namespace {

constexpr char kInfo[] = "/guard.txt";

std::string GuardPath(const std::string& dir, int k) {
  return absl::StrCat(dir, "/guard_", k, ".pt");
}

// What the guard needs of a package of either family: its statistics and
// how it windows clips.
struct GuardedPackage : DataFiles {
  int window = 0, hop = 0;
};

absl::StatusOr<GuardedPackage> ReadGuardedPackage(const std::string& dir) {
  absl::StatusOr<std::string> family = ReadConfigFamily(dir);
  if (!family.ok()) return family.status();
  GuardedPackage out;
  if (*family == "cyclic") {
    absl::StatusOr<CyclicConfig> config = CyclicConfig::Read(dir);
    if (!config.ok()) return config.status();
    absl::StatusOr<DataFiles> data = ReadDataFiles(dir);
    if (!data.ok()) return data.status();
    static_cast<DataFiles&>(out) = *std::move(data);
    out.window = config->window, out.hop = config->hop;
    return out;
  }
  absl::StatusOr<PackageContents> package = ReadPackage(dir);
  if (!package.ok()) return package.status();
  out.window = package->config.window, out.hop = package->config.hop;
  static_cast<DataFiles&>(out) = *std::move(package);
  return out;
}

int IndexOf(const std::vector<std::string>& labels, const std::string& label) {
  const auto it = std::find(labels.begin(), labels.end(), label);
  return it == labels.end() ? -1 : static_cast<int>(it - labels.begin());
}

// The softmax of the content logits averaged over the clip's windows (kFloat64).
torch::Tensor ClipProbabilities(LabelCritic& net, motion::FeatureClip f, int window, int hop) {
  PadToLength(&f, window);
  const std::vector<int> starts = *motion::WindowStarts(f.frames, {window, hop}, true);
  return torch::softmax(net->forward(WindowTensor(f, starts, window)).content.mean(0), 0)
      .to(torch::kFloat64);
}

}  // namespace

absl::StatusOr<ContentGuardAccuracy> TrainContentGuard(const ContentGuardTrainOptions& o) {
  auto log = [&](const std::string& s) {
    if (o.log) {
      o.log(s);
    } else {
      std::fprintf(stderr, "%s\n", s.c_str());
    }
  };
  if (o.guards < 1 || o.guards > 16) {
    return absl::InvalidArgumentError("content guard: the number of guards must be in [1, 16]");
  }
  absl::StatusOr<GuardedPackage> package = ReadGuardedPackage(o.model);
  if (!package.ok()) return package.status();
  const int window = package->window, hop = package->hop;
  absl::StatusOr<TrainingSet> train =
      LoadTrainingSet(o.data, {window, hop}, {}, /*test=*/false, &package->norm);
  if (!train.ok()) return train.status();
  // The held-out split of the directories among `data` (single files have none).
  std::vector<std::string> dirs;
  for (const std::string& d : o.data) {
    if (std::filesystem::is_directory(d)) dirs.push_back(d);
  }
  TrainingSet test;
  if (!dirs.empty()) {
    absl::StatusOr<TrainingSet> loaded =
        LoadTrainingSet(dirs, {window, hop}, {}, /*test=*/true, &package->norm);
    if (!loaded.ok()) return loaded.status();
    test = *std::move(loaded);
  }
  if (train->windows.empty()) {
    return absl::InvalidArgumentError("content guard: no training clip is a window long");
  }
  absl::StatusOr<ClipClasses> classes = ClipClasses::FromPaths(train->paths, {});
  if (!classes.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("content guard: ", classes.status().message()));
  }
  const std::vector<std::string>& styles = classes->styles;
  const std::vector<std::string>& contents = classes->contents;
  if (contents.size() < 2) {
    return absl::InvalidArgumentError(
        "content guard: the training clips need at least two content labels");
  }
  // A held-out clip's content label: -1 when training has no such action.
  auto test_content = [&](int clip) {
    const auto l = motion::ParseClipName(test.paths[clip]);
    return l ? IndexOf(contents, l->content) : -1;
  };
  // Batches balanced over actions: an action uniformly, then one of its windows.
  std::vector<std::vector<int>> windows_of(contents.size());
  for (size_t w = 0; w < train->windows.size(); ++w) {
    windows_of[classes->content_of[train->windows[w].clip]].push_back(static_cast<int>(w));
  }
  ContentGuardAccuracy acc;
  acc.clips = static_cast<int>(test.clips.size());
  std::vector<torch::Tensor> probabilities(test.clips.size());  // Summed over guards.
  try {
    for (int g = 1; g <= o.guards; ++g) {
      const uint64_t seed = o.seed + g - 1;
      torch::manual_seed(seed);
      std::mt19937_64 rng(seed);
      LabelCritic net(train->dim(), static_cast<int>(styles.size()),
                      static_cast<int>(contents.size()));
      torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(o.lr));
      const int d = train->dim();
      for (int it = 1; it <= o.iterations; ++it) {
        torch::Tensor x = torch::empty({o.batch, d, window});
        torch::Tensor style = torch::empty({o.batch}, torch::kLong);
        torch::Tensor content = torch::empty({o.batch}, torch::kLong);
        for (int b = 0; b < o.batch; ++b) {
          int c;
          do c = static_cast<int>(rng() % contents.size());
          while (windows_of[c].empty());
          const TrainingSet::Window& w =
              train->windows[windows_of[c][rng() % windows_of[c].size()]];
          x[b] = WindowTensor(train->clips[w.clip], {w.start}, window)[0];
          content[b] = c;
          style[b] = classes->style_of[w.clip];
        }
        // Noise, so that the verdict does not hinge on exact values. The style
        // head is trained too (the critic's design); only the content is read.
        const torch::Tensor loss =
            LabelLoss(net->forward(x + 0.05 * torch::randn_like(x)), style, content);
        opt.zero_grad();
        loss.backward();
        opt.step();
        if (it % 250 == 0 || it == o.iterations) {
          log(absl::StrFormat("content guard %d/%d: iter %d/%d loss %.4f", g, o.guards, it,
                              o.iterations, loss.item<double>()));
        }
      }
      net->eval();
      c10::InferenceMode guard;
      int right = 0;
      for (size_t i = 0; i < test.clips.size(); ++i) {
        const torch::Tensor p = ClipProbabilities(net, test.clips[i], window, hop);
        right += p.argmax().item<int64_t>() == test_content(static_cast<int>(i));
        probabilities[i] = probabilities[i].defined() ? probabilities[i] + p : p;
      }
      acc.each.push_back(acc.clips ? static_cast<double>(right) / acc.clips : 0);
      // Written aside and moved into place once every guard is trained, so a
      // run that fails half-way leaves the package's guard as it was.
      torch::save(net, GuardPath(o.model, g) + ".tmp");
    }
    int right = 0;
    for (size_t i = 0; i < test.clips.size(); ++i) {
      right += probabilities[i].argmax().item<int64_t>() == test_content(static_cast<int>(i));
    }
    if (acc.clips > 0) acc.content = static_cast<double>(right) / acc.clips;
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training the content guard: ", e.what()));
  }
  for (int g = 1; g <= o.guards; ++g) {
    std::error_code ec;
    std::filesystem::rename(GuardPath(o.model, g) + ".tmp", GuardPath(o.model, g), ec);
    if (ec) {
      return absl::InternalError(
          absl::StrCat("content guard: cannot move ", GuardPath(o.model, g), " into place: ",
                       ec.message()));
    }
  }
  const std::string info = absl::StrFormat(
      "styles = %s\ncontents = %s\nguards = %d\niterations = %d\nseed = %d\ndata = %s\n"
      "held_out_content_accuracy = %.4f\neach_guards_held_out_content_accuracy = %s\n"
      "held_out_clips = %d\n",
      absl::StrJoin(styles, ","), absl::StrJoin(contents, ","), o.guards, o.iterations, o.seed,
      absl::StrJoin(o.data, ","), acc.content,
      absl::StrJoin(acc.each, ",", [](std::string* out, double a) {
        absl::StrAppendFormat(out, "%.4f", a);
      }),
      acc.clips);
  if (absl::Status s = motion::WriteFileAtomically(o.model + kInfo, info); !s.ok()) return s;
  return acc;
}

struct ContentGuard::Impl {
  std::vector<std::string> styles, contents;
  int guards = 1;
  int window = 0, hop = 0;
  std::vector<LabelCritic> nets;
};

ContentGuard::ContentGuard(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ContentGuard::~ContentGuard() = default;
const std::vector<std::string>& ContentGuard::contents() const { return impl_->contents; }

absl::StatusOr<std::unique_ptr<ContentGuard>> ContentGuard::Load(const std::string& dir, int dim,
                                                                 int window, int hop) {
  const std::string info_path = dir + kInfo;
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
    const std::string path = GuardPath(dir, k);
    if (!std::filesystem::exists(path)) {
      return absl::NotFoundError(path + ": missing (train it with stylus-tool train-guard)");
    }
    LabelCritic net(dim, static_cast<int>(impl->styles.size()),
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
  for (LabelCritic& net : impl_->nets) {
    const torch::Tensor p = ClipProbabilities(net, normalized, impl_->window, impl_->hop);
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
