#include "eval/judges.h"

#include <torch/torch.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "model/package.h"
#include "model/window_tensor.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"
#include "motion/files.h"
#include "motion/splice.h"
#include "motion/windowing.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

namespace nn = torch::nn;
constexpr int kWindow = 32, kHop = 24, kWidth = 128;

// Conv1d x3 (one stride 2), temporal mean, linear: logits per class.
struct ClassifierImpl : nn::Module {
  ClassifierImpl(int dim, int classes) {
    conv1 = register_module("conv1", nn::Conv1d(nn::Conv1dOptions(dim, kWidth, 5).padding(2)));
    conv2 = register_module("conv2",
                            nn::Conv1d(nn::Conv1dOptions(kWidth, kWidth, 4).stride(2).padding(1)));
    conv3 = register_module("conv3", nn::Conv1d(nn::Conv1dOptions(kWidth, kWidth, 5).padding(2)));
    fc = register_module("fc", nn::Linear(kWidth, classes));
  }
  torch::Tensor forward(torch::Tensor x) {
    const auto lrelu = [](const torch::Tensor& t) { return torch::leaky_relu(t, 0.2); };
    x = lrelu(conv1->forward(x));
    x = lrelu(conv2->forward(x));
    x = lrelu(conv3->forward(x));
    return fc->forward(x.mean(2));
  }
  nn::Conv1d conv1{nullptr}, conv2{nullptr}, conv3{nullptr};
  nn::Linear fc{nullptr};
};
TORCH_MODULE(Classifier);

std::vector<std::string> SortedLabels(const TrainingSet& set, bool style) {
  std::map<std::string, int> seen;
  for (const std::string& p : set.paths) {
    auto l = motion::ParseClipName(p);
    if (l) seen[style ? l->style : l->content] = 0;
  }
  std::vector<std::string> out;
  for (const auto& [k, v] : seen) out.push_back(k);
  return out;
}

// The feature channels of each body part (positions and rotations of its
// joints; motion/features.h).
std::vector<std::vector<int64_t>> BodyPartChannels(const TrainingSet& set) {
  const motion::FeatureLayout layout(set.skeleton.num_joints());
  std::vector<std::vector<int64_t>> parts;
  for (motion::BodyPart p : motion::kBodyParts) {
    std::vector<int64_t> channels;
    for (int j : motion::BodyPartJoints(set.skeleton, set.roles, p)) {
      for (int k = 0; k < 3; ++k) channels.push_back(layout.position(j) + k);
      for (int k = 0; k < 4; ++k) channels.push_back(layout.rotation(j) + k);
    }
    parts.push_back(std::move(channels));
  }
  return parts;
}

// Clip-level logits: the mean over the clip's windows.
torch::Tensor ClipLogits(Classifier& net, motion::FeatureClip f) {
  PadToLength(&f, kWindow);
  const std::vector<int> starts = *motion::WindowStarts(f.frames, {kWindow, kHop}, true);
  return net->forward(WindowTensor(f, starts, kWindow)).mean(0);
}

}  // namespace

struct Judges::Impl {
  std::string dir;
  DataFiles shape;  // Skeleton, frame time, roles and norm of the training data.
  std::vector<std::string> styles, contents;
  Classifier style{nullptr}, content{nullptr};

  absl::StatusOr<torch::Tensor> Logits(Classifier& net, const motion::Motion& clip) {
    if (absl::Status s = CheckClipFitsModel(clip, shape, "clip"); !s.ok()) return s;
    absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, shape.roles);
    if (!f.ok()) return f.status();
    shape.norm.Normalize(&*f);
    try {
      c10::InferenceMode guard;
      return ClipLogits(net, *f);
    } catch (const std::exception& e) {
      return absl::InternalError(absl::StrCat("judges ", dir, ": ", e.what()));
    }
  }
  absl::StatusOr<int> Classify(Classifier& net, const motion::Motion& clip) {
    absl::StatusOr<torch::Tensor> logits = Logits(net, clip);
    if (!logits.ok()) return logits.status();
    return static_cast<int>(logits->argmax().item<int64_t>());
  }
  absl::StatusOr<std::vector<double>> Probabilities(Classifier& net, const motion::Motion& clip) {
    absl::StatusOr<torch::Tensor> logits = Logits(net, clip);
    if (!logits.ok()) return logits.status();
    const torch::Tensor p = torch::softmax(logits->to(torch::kFloat64), 0).contiguous();
    return std::vector<double>(p.data_ptr<double>(), p.data_ptr<double>() + p.numel());
  }
};

absl::StatusOr<JudgeAccuracy> TrainJudges(const JudgeTrainOptions& o) {
  auto log = [&](const std::string& s) {
    if (o.log) {
      o.log(s);
    } else {
      std::fprintf(stderr, "%s\n", s.c_str());
    }
  };
  absl::StatusOr<TrainingSet> train = LoadTrainingSet(o.data, {kWindow, kHop});
  if (!train.ok()) return train.status();
  absl::StatusOr<TrainingSet> test =
      LoadTrainingSet(o.data, {kWindow, kHop}, {}, /*test=*/true, &train->norm);
  if (!test.ok()) return test.status();
  const std::vector<std::string> styles = SortedLabels(*train, true),
                                 contents = SortedLabels(*train, false);
  auto label_of = [&](const TrainingSet& set, int clip, bool style) {
    const auto l = *motion::ParseClipName(set.paths[clip]);
    const auto& list = style ? styles : contents;
    return static_cast<int>(std::find(list.begin(), list.end(), style ? l.style : l.content) -
                            list.begin());
  };
  torch::manual_seed(o.seed);
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<torch::Tensor> part_channels;
  for (const std::vector<int64_t>& c : BodyPartChannels(*train)) {
    part_channels.push_back(torch::tensor(c, torch::kLong));
  }
  Classifier style_net(train->dim(), static_cast<int>(styles.size()));
  Classifier content_net(train->dim(), static_cast<int>(contents.size()));
  JudgeAccuracy acc;
  try {
    for (bool style : {true, false}) {
      Classifier& net = style ? style_net : content_net;
      const int classes = static_cast<int>((style ? styles : contents).size());
      // Class-balanced batches: a class uniformly, then one of its windows.
      std::vector<std::vector<int>> windows_of(classes);
      for (size_t w = 0; w < train->windows.size(); ++w) {
        windows_of[label_of(*train, train->windows[w].clip, style)].push_back(static_cast<int>(w));
      }
      torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(o.lr));
      const int d = train->dim();
      for (int it = 1; it <= o.iterations; ++it) {
        torch::Tensor x = torch::empty({o.batch, d, kWindow});
        torch::Tensor y = torch::empty({o.batch}, torch::kLong);
        auto draw_window = [&](int c) -> torch::Tensor {
          const auto& w = train->windows[windows_of[c][rng() % windows_of[c].size()]];
          const motion::FeatureClip& clip = train->clips[w.clip];
          const int start =
              o.random_starts && clip.frames >= kWindow
                  ? static_cast<int>(rng() % static_cast<uint64_t>(clip.frames - kWindow + 1))
                  : w.start;
          return WindowTensor(clip, {start}, kWindow)[0];
        };
        for (int b = 0; b < o.batch; ++b) {
          int c;
          do c = static_cast<int>(rng() % classes);
          while (windows_of[c].empty());
          x[b] = draw_window(c);
          y[b] = c;
          if (o.swap_parts > 0 && uniform(rng) < o.swap_parts) {
            // One body part from another window of the same label.
            const torch::Tensor& part = part_channels[rng() % part_channels.size()];
            x[b].index_copy_(0, part, draw_window(c).index_select(0, part));
          }
        }
        // Small Gaussian noise: the judges must not hinge on exact values.
        const torch::Tensor loss =
            torch::nn::functional::cross_entropy(net->forward(x + 0.05 * torch::randn_like(x)), y);
        opt.zero_grad();
        loss.backward();
        opt.step();
        if (it % 250 == 0 || it == o.iterations) {
          log(absl::StrFormat("%s judge: iter %d/%d loss %.4f", style ? "style" : "content", it,
                              o.iterations, loss.item<double>()));
        }
      }
      net->eval();
      c10::InferenceMode guard;
      int right = 0;
      for (size_t i = 0; i < test->clips.size(); ++i) {
        right += ClipLogits(net, test->clips[i]).argmax().item<int64_t>() ==
                 label_of(*test, static_cast<int>(i), style);
      }
      (style ? acc.style : acc.content) = static_cast<double>(right) / test->clips.size();
    }
    acc.clips = static_cast<int>(test->clips.size());
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    torch::save(style_net, o.out + "/style.pt");
    torch::save(content_net, o.out + "/content.pt");
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training judges: ", e.what()));
  }
  if (absl::Status s = WriteDataFiles(o.out, train->norm, train->skeleton, train->frame_time);
      !s.ok()) {
    return s;
  }
  const std::string labels = absl::StrCat(
      "styles = ", absl::StrJoin(styles, ","), "\ncontents = ", absl::StrJoin(contents, ","),
      absl::StrFormat("\nheld_out_style_accuracy = %.4f\nheld_out_content_accuracy = "
                      "%.4f\nheld_out_clips = %d\nrandom_starts = %d\nswap_parts = %g\n",
                      acc.style, acc.content, acc.clips, o.random_starts ? 1 : 0, o.swap_parts));
  if (absl::Status s = motion::WriteFileAtomically(o.out + "/labels.txt", labels); !s.ok())
    return s;
  return acc;
}

Judges::Judges(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Judges::~Judges() = default;
const std::vector<std::string>& Judges::styles() const { return impl_->styles; }
const std::vector<std::string>& Judges::contents() const { return impl_->contents; }
absl::StatusOr<int> Judges::ClassifyStyle(const motion::Motion& clip) const {
  return impl_->Classify(impl_->style, clip);
}
absl::StatusOr<int> Judges::ClassifyContent(const motion::Motion& clip) const {
  return impl_->Classify(impl_->content, clip);
}

absl::StatusOr<std::vector<double>> Judges::StyleProbabilities(const motion::Motion& clip) const {
  return impl_->Probabilities(impl_->style, clip);
}
absl::StatusOr<std::vector<double>> Judges::ContentProbabilities(const motion::Motion& clip) const {
  return impl_->Probabilities(impl_->content, clip);
}

absl::StatusOr<std::unique_ptr<Judges>> Judges::Load(const std::string& dir) {
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  std::ifstream f(dir + "/labels.txt");
  if (!f) return absl::NotFoundError(dir + "/labels.txt: missing");
  std::string line;
  while (std::getline(f, line)) {
    std::vector<std::string> kv = absl::StrSplit(line, absl::MaxSplits(" = ", 1));
    if (kv.size() != 2) continue;
    if (kv[0] == "styles") impl->styles = absl::StrSplit(kv[1], ',');
    if (kv[0] == "contents") impl->contents = absl::StrSplit(kv[1], ',');
  }
  if (impl->styles.empty() || impl->contents.empty()) {
    return absl::InvalidArgumentError(dir + "/labels.txt: no 'styles' or 'contents' line");
  }
  absl::StatusOr<DataFiles> data = ReadDataFiles(dir);
  if (!data.ok()) return data.status();
  impl->shape = *std::move(data);
  const int dim = impl->shape.norm.dim();
  try {
    impl->style = Classifier(dim, static_cast<int>(impl->styles.size()));
    impl->content = Classifier(dim, static_cast<int>(impl->contents.size()));
    torch::load(impl->style, dir + "/style.pt");
    torch::load(impl->content, dir + "/content.pt");
    impl->style->eval();
    impl->content->eval();
  } catch (const std::exception& e) {
    std::string what = e.what();
    return absl::InvalidArgumentError(
        absl::StrCat(dir, ": cannot load judge weights: ", what.substr(0, what.find('\n'))));
  }
  return std::unique_ptr<Judges>(new Judges(std::move(impl)));
}

}  // namespace stylus::model
