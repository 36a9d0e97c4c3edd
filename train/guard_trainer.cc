#include "train/guard_trainer.h"

#include <torch/torch.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "model/content_guard.h"
#include "model/family_registry.h"
#include "model/guard_net.h"
#include "model/package.h"
#include "model/window_tensor.h"
#include "motion/dataset.h"
#include "motion/files.h"
#include "train/clip_classes.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

// What the guard needs of a package of either family: its statistics and
// how it windows clips.
struct GuardedPackage {
  DataFiles data;
  int window = 0, hop = 0;
};

absl::StatusOr<GuardedPackage> ReadGuardedPackage(const std::string& dir) {
  absl::StatusOr<ModelSummary> header = ReadPackageHeader(dir);
  if (!header.ok()) return header.status();
  absl::StatusOr<DataFiles> data = ReadPackageData(dir, header->dim);
  if (!data.ok()) return data.status();
  return GuardedPackage{*std::move(data), header->window, header->hop};
}

int IndexOf(const std::vector<std::string>& labels, const std::string& label) {
  const auto it = std::find(labels.begin(), labels.end(), label);
  return it == labels.end() ? -1 : static_cast<int>(it - labels.begin());
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
      LoadTrainingSet(o.data, {window, hop}, {}, /*test=*/false, &package->data.norm);
  if (!train.ok()) return train.status();
  // The held-out split of the directories among `data` (single files have none).
  std::vector<std::string> dirs;
  for (const std::string& d : o.data) {
    if (std::filesystem::is_directory(d)) dirs.push_back(d);
  }
  TrainingSet test;
  if (!dirs.empty()) {
    absl::StatusOr<TrainingSet> loaded =
        LoadTrainingSet(dirs, {window, hop}, {}, /*test=*/true, &package->data.norm);
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
      GuardNet net(train->dim(), static_cast<int>(styles.size()),
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
        const torch::Tensor p = ClipContentProbabilities(net, test.clips[i], window, hop);
        right += p.argmax().item<int64_t>() == test_content(static_cast<int>(i));
        probabilities[i] = probabilities[i].defined() ? probabilities[i] + p : p;
      }
      acc.each.push_back(acc.clips ? static_cast<double>(right) / acc.clips : 0);
      // Written aside and moved into place once every guard is trained, so a
      // run that fails half-way leaves the package's guard as it was.
      torch::save(net, ContentGuardWeightsPath(o.model, g) + ".tmp");
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
    std::filesystem::rename(ContentGuardWeightsPath(o.model, g) + ".tmp",
                            ContentGuardWeightsPath(o.model, g), ec);
    if (ec) {
      return absl::InternalError(absl::StrCat("content guard: cannot move ",
                                              ContentGuardWeightsPath(o.model, g),
                                              " into place: ", ec.message()));
    }
  }
  const std::string info = absl::StrFormat(
      "styles = %s\ncontents = %s\nguards = %d\niterations = %d\nseed = %d\ndata = %s\n"
      "held_out_content_accuracy = %.4f\neach_guards_held_out_content_accuracy = %s\n"
      "held_out_clips = %d\n",
      absl::StrJoin(styles, ","), absl::StrJoin(contents, ","), o.guards, o.iterations, o.seed,
      absl::StrJoin(o.data, ","), acc.content,
      absl::StrJoin(acc.each, ",",
                    [](std::string* out, double a) { absl::StrAppendFormat(out, "%.4f", a); }),
      acc.clips);
  if (absl::Status s = motion::WriteFileAtomically(ContentGuardInfoPath(o.model), info); !s.ok())
    return s;
  return acc;
}

}  // namespace stylus::model
