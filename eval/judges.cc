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
#include "eval/classifier_net.h"
#include "model/package.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"
#include "motion/files.h"
#include "motion/splice.h"
#include "train/training_run.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

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
  auto log = [&](const std::string& s) { LogLine(o.log, s); };
  absl::StatusOr<TrainingSet> train = LoadTrainingSet(o.data, {kJudgeWindow, kJudgeHop});
  if (!train.ok()) return train.status();
  absl::StatusOr<TrainingSet> test =
      LoadTrainingSet(o.data, {kJudgeWindow, kJudgeHop}, {}, /*test=*/true, &train->norm);
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
  Classifier style_net(train->dim(), static_cast<int>(styles.size()));
  Classifier content_net(train->dim(), static_cast<int>(contents.size()));
  JudgeAccuracy acc;
  try {
    for (bool style : {true, false}) {
      ClassifierData data;
      data.clips = &train->clips;
      for (const TrainingSet::Window& w : train->windows) data.windows.push_back({w.clip, w.start});
      for (size_t c = 0; c < train->clips.size(); ++c) {
        data.class_of_clip.push_back(label_of(*train, static_cast<int>(c), style));
      }
      data.classes = static_cast<int>((style ? styles : contents).size());
      ClassifierTraining training;
      training.iterations = o.iterations;
      training.batch = o.batch;
      training.lr = o.lr;
      training.random_starts = o.random_starts;
      training.swap_parts = o.swap_parts;
      training.part_channels = BodyPartChannels(*train);
      training.name = style ? "style" : "content";
      training.log = log;
      Classifier& net = style ? style_net : content_net;
      TrainClassifier(net, data, training, &rng);
      std::vector<int> test_classes;
      for (size_t c = 0; c < test->clips.size(); ++c) {
        test_classes.push_back(label_of(*test, static_cast<int>(c), style));
      }
      (style ? acc.style : acc.content) = ClipAccuracy(net, test->clips, test_classes);
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
