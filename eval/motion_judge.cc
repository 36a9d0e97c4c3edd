#include "eval/motion_judge.h"

#include <torch/torch.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "eval/classifier_net.h"
#include "model/package.h"
#include "motion/files.h"
#include "motion/normalization.h"
#include "train/training_run.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

constexpr char kWeights[] = "motion_style.pt";
constexpr char kNorm[] = "motion_norm.txt";
constexpr char kInfo[] = "motion.txt";

std::vector<std::string> ChannelNames(const motion::Skeleton& skeleton) {
  std::vector<std::string> names;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    for (const char* axis : {".vx", ".vy", ".vz"}) names.push_back(skeleton.joint(j).name + axis);
  }
  for (const char* n : {"root.vx", "root.vz", "root.yaw_rate", "root.vy"}) names.push_back(n);
  return names;
}

// The training or held-out clips' judge channels, normalized by `norm`
// (computed from them when null) .
absl::StatusOr<std::vector<motion::FeatureClip>> ChannelsOf(const TrainingSet& set,
                                                            motion::NormStats* norm,
                                                            bool compute_norm) {
  std::vector<motion::FeatureClip> out;
  for (const motion::FeatureClip& clip : set.clips) {
    motion::FeatureClip raw = clip;
    set.norm.Denormalize(&raw);
    out.push_back(MotionChannels(raw, set.skeleton, set.roles, set.frame_time));
  }
  if (compute_norm) {
    std::vector<const motion::FeatureClip*> ptrs;
    for (const motion::FeatureClip& c : out) ptrs.push_back(&c);
    absl::StatusOr<motion::NormStats> stats =
        motion::NormStats::Compute(ptrs, ChannelNames(set.skeleton));
    if (!stats.ok()) return stats.status();
    *norm = *std::move(stats);
  }
  for (motion::FeatureClip& c : out) norm->Normalize(&c);
  return out;
}

// Each clip's index into `styles`; INVALID_ARGUMENT for an unlabelled clip.
absl::StatusOr<std::vector<int>> StyleClasses(const TrainingSet& set,
                                              const std::vector<std::string>& styles) {
  std::vector<int> out;
  for (size_t i = 0; i < set.clips.size(); ++i) {
    if (!set.labels[i]) {
      return absl::InvalidArgumentError(
          absl::StrCat(set.paths[i], ": no style label (the judge learns from labelled clips)"));
    }
    const auto it = std::find(styles.begin(), styles.end(), set.labels[i]->style);
    out.push_back(it == styles.end() ? -1 : static_cast<int>(it - styles.begin()));
  }
  return out;
}

}  // namespace

motion::FeatureClip MotionChannels(const motion::FeatureClip& f, const motion::Skeleton& skeleton,
                                   const motion::HumanoidRoles& roles, double frame_time) {
  const int num_joints = skeleton.num_joints();
  const motion::FeatureLayout layout(num_joints);
  const std::vector<bool> above = motion::AbovePelvis(skeleton, roles);
  motion::FeatureClip out;
  out.frames = f.frames;
  out.dim = 3 * num_joints + 4;
  out.values.assign(static_cast<size_t>(out.frames) * out.dim, 0.0f);
  const float per_second = static_cast<float>(1.0 / frame_time);
  for (int t = 0; t < f.frames; ++t) {
    float* o = out.row(t);
    if (f.frames >= 2) {
      const int a = std::min(t, f.frames - 2);
      const float *p = f.row(a), *q = f.row(a + 1);
      for (int j = 0; j < num_joints; ++j) {
        if (above[j]) continue;
        for (int c = 3 * j; c < 3 * j + 3; ++c) o[c] = (q[c] - p[c]) * per_second;
      }
    }
    for (int c = 0; c < 4; ++c) o[3 * num_joints + c] = f.row(t)[layout.trajectory() + c];
  }
  return out;
}

motion::Motion Frozen(const motion::Motion& clip) {
  motion::Motion out = clip;
  if (clip.num_frames == 0) return out;
  const int mid = clip.num_frames / 2;
  const size_t width = clip.values.size() / clip.num_frames;
  for (int t = 0; t < clip.num_frames; ++t) {
    std::copy(clip.values.begin() + mid * width, clip.values.begin() + (mid + 1) * width,
              out.values.begin() + t * width);
  }
  return out;
}

absl::StatusOr<MotionJudgeAccuracy> TrainMotionJudge(const JudgeTrainOptions& o) {
  auto log = [&](const std::string& s) { LogLine(o.log, s); };
  absl::StatusOr<TrainingSet> train = LoadTrainingSet(o.data, {kJudgeWindow, kJudgeHop});
  if (!train.ok()) return train.status();
  std::vector<motion::Motion> test_motions;
  absl::StatusOr<TrainingSet> test = LoadTrainingSet(o.data, {kJudgeWindow, kJudgeHop}, {},
                                                     /*test=*/true, &train->norm, &test_motions);
  if (!test.ok()) return test.status();
  std::map<std::string, int> seen;
  for (const auto& label : train->labels) {
    if (label) seen[label->style] = 0;
  }
  std::vector<std::string> styles;
  for (const auto& [style, unused] : seen) styles.push_back(style);
  if (styles.size() < 2) {
    return absl::InvalidArgumentError("the training split has fewer than two labelled styles");
  }
  motion::NormStats norm;
  absl::StatusOr<std::vector<motion::FeatureClip>> train_channels =
      ChannelsOf(*train, &norm, /*compute_norm=*/true);
  if (!train_channels.ok()) return train_channels.status();
  absl::StatusOr<std::vector<motion::FeatureClip>> test_channels =
      ChannelsOf(*test, &norm, /*compute_norm=*/false);
  if (!test_channels.ok()) return test_channels.status();
  absl::StatusOr<std::vector<int>> train_classes = StyleClasses(*train, styles);
  if (!train_classes.ok()) return train_classes.status();
  absl::StatusOr<std::vector<int>> test_classes = StyleClasses(*test, styles);
  if (!test_classes.ok()) return test_classes.status();
  std::vector<motion::FeatureClip> frozen;
  for (const motion::Motion& m : test_motions) {
    absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(Frozen(m), train->roles);
    if (!f.ok()) return f.status();
    frozen.push_back(MotionChannels(*f, train->skeleton, train->roles, train->frame_time));
    norm.Normalize(&frozen.back());
  }
  MotionJudgeAccuracy acc;
  acc.clips = static_cast<int>(test->clips.size());
  std::vector<int> per_style(styles.size(), 0);
  for (int c : *test_classes) {
    if (c >= 0) acc.chance = std::max(acc.chance, double(++per_style[c]) / test_classes->size());
  }
  torch::manual_seed(o.seed);
  std::mt19937_64 rng(o.seed);
  Classifier net(norm.dim(), static_cast<int>(styles.size()));
  try {
    ClassifierData data;
    data.clips = &*train_channels;
    for (const TrainingSet::Window& w : train->windows) data.windows.push_back({w.clip, w.start});
    data.class_of_clip = *train_classes;
    data.classes = static_cast<int>(styles.size());
    ClassifierTraining training;
    training.iterations = o.iterations;
    training.batch = o.batch;
    training.lr = o.lr;
    training.random_starts = o.random_starts;
    training.name = "motion-only style";
    training.log = log;
    TrainClassifier(net, data, training, &rng);
    acc.held_out = ClipAccuracy(net, *test_channels, *test_classes);
    acc.frozen = ClipAccuracy(net, frozen, *test_classes);
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    torch::save(net, o.out + "/" + kWeights);
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training the motion-only judge: ", e.what()));
  }
  if (!std::filesystem::exists(o.out + "/norm.txt")) {
    if (absl::Status s = WriteDataFiles(o.out, train->norm, train->skeleton, train->frame_time);
        !s.ok()) {
      return s;
    }
  }
  if (absl::Status s = norm.Save(o.out + "/" + kNorm); !s.ok()) return s;
  const std::string info = absl::StrFormat(
      "styles = %s\nheld_out_accuracy = %.4f\nfrozen_accuracy = %.4f\nchance = %.4f\n"
      "held_out_clips = %d\niterations = %d\nrandom_starts = %d\n",
      absl::StrJoin(styles, ","), acc.held_out, acc.frozen, acc.chance, acc.clips, o.iterations,
      o.random_starts ? 1 : 0);
  if (absl::Status s = motion::WriteFileAtomically(o.out + "/" + kInfo, info); !s.ok()) return s;
  return acc;
}

struct MotionJudge::Impl {
  std::string dir;
  DataFiles shape;  // Skeleton, frame time and roles of the training data.
  motion::NormStats norm;
  std::vector<std::string> styles;
  MotionJudgeAccuracy trained;
  Classifier net{nullptr};

  absl::StatusOr<torch::Tensor> Logits(const motion::Motion& clip) {
    if (absl::Status s = CheckClipFitsModel(clip, shape, "clip"); !s.ok()) return s;
    absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, shape.roles);
    if (!f.ok()) return f.status();
    motion::FeatureClip channels =
        MotionChannels(*f, shape.skeleton, shape.roles, shape.frame_time);
    norm.Normalize(&channels);
    try {
      c10::InferenceMode guard;
      return ClipLogits(net, std::move(channels));
    } catch (const std::exception& e) {
      return absl::InternalError(absl::StrCat("motion judge ", dir, ": ", e.what()));
    }
  }
};

MotionJudge::MotionJudge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MotionJudge::~MotionJudge() = default;
const std::vector<std::string>& MotionJudge::styles() const { return impl_->styles; }
const MotionJudgeAccuracy& MotionJudge::trained_accuracy() const { return impl_->trained; }

absl::StatusOr<int> MotionJudge::ClassifyStyle(const motion::Motion& clip) const {
  absl::StatusOr<torch::Tensor> logits = impl_->Logits(clip);
  if (!logits.ok()) return logits.status();
  return static_cast<int>(logits->argmax().item<int64_t>());
}

absl::StatusOr<std::vector<double>> MotionJudge::StyleProbabilities(
    const motion::Motion& clip) const {
  absl::StatusOr<torch::Tensor> logits = impl_->Logits(clip);
  if (!logits.ok()) return logits.status();
  const torch::Tensor p = torch::softmax(logits->to(torch::kFloat64), 0).contiguous();
  return std::vector<double>(p.data_ptr<double>(), p.data_ptr<double>() + p.numel());
}

absl::StatusOr<std::unique_ptr<MotionJudge>> MotionJudge::Load(const std::string& dir) {
  const std::string info_path = dir + "/" + kInfo;
  std::ifstream f(info_path);
  if (!f) return absl::NotFoundError(absl::StrCat(info_path, ": missing (no motion-only judge)"));
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  std::string line;
  int line_number = 0;
  while (std::getline(f, line)) {
    ++line_number;
    std::vector<std::string> kv = absl::StrSplit(line, absl::MaxSplits(" = ", 1));
    if (kv.size() != 2) continue;
    const auto number = [&](double* out) -> absl::Status {
      if (absl::SimpleAtod(kv[1], out)) return absl::OkStatus();
      return absl::InvalidArgumentError(
          absl::StrCat(info_path, ":", line_number, ": ", kv[0], " is not a number"));
    };
    absl::Status s;
    if (kv[0] == "styles") impl->styles = absl::StrSplit(kv[1], ',');
    if (kv[0] == "held_out_accuracy") s = number(&impl->trained.held_out);
    if (kv[0] == "frozen_accuracy") s = number(&impl->trained.frozen);
    if (kv[0] == "chance") s = number(&impl->trained.chance);
    if (kv[0] == "held_out_clips") {
      double clips = 0;
      s = number(&clips);
      impl->trained.clips = static_cast<int>(clips);
    }
    if (!s.ok()) return s;
  }
  if (impl->styles.size() < 2) {
    return absl::InvalidArgumentError(info_path + ": no 'styles' line of two or more styles");
  }
  absl::StatusOr<DataFiles> data = ReadDataFiles(dir);
  if (!data.ok()) return data.status();
  impl->shape = *std::move(data);
  absl::StatusOr<motion::NormStats> norm = motion::NormStats::Load(dir + "/" + kNorm);
  if (!norm.ok()) return norm.status();
  const int want = 3 * impl->shape.skeleton.num_joints() + 4;
  if (norm->dim() != want) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/", kNorm, ": ", norm->dim(), " channels, the skeleton needs ", want));
  }
  impl->norm = *std::move(norm);
  try {
    impl->net = Classifier(want, static_cast<int>(impl->styles.size()));
    torch::load(impl->net, dir + "/" + kWeights);
    impl->net->eval();
  } catch (const std::exception& e) {
    std::string what = e.what();
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/", kWeights, ": cannot load: ", what.substr(0, what.find('\n'))));
  }
  return std::unique_ptr<MotionJudge>(new MotionJudge(std::move(impl)));
}

}  // namespace stylus::model
