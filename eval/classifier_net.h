// The judges' window classifier and its training loop (internal to eval/:
// LibTorch). Conv1d x3 (one stride 2), temporal mean, linear: logits per
// class of a window of feature frames; a clip's logits are the mean over its
// windows.
#ifndef STYLUS_EVAL_CLASSIFIER_NET_H_
#define STYLUS_EVAL_CLASSIFIER_NET_H_

#include <torch/torch.h>

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "motion/features.h"

namespace stylus::model {

inline constexpr int kJudgeWindow = 32, kJudgeHop = 24;

struct ClassifierImpl : torch::nn::Module {
  ClassifierImpl(int dim, int classes);
  torch::Tensor forward(torch::Tensor x);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr}, conv3{nullptr};
  torch::nn::Linear fc{nullptr};
};
TORCH_MODULE(Classifier);

// Clip-level logits: the mean over the clip's windows (padded to one window
// when shorter).
torch::Tensor ClipLogits(Classifier& net, motion::FeatureClip clip);

// What TrainClassifier learns from: normalized clips, their windows, each
// clip's class.
struct ClassifierData {
  const std::vector<motion::FeatureClip>* clips = nullptr;
  struct Window {
    int clip, start;
  };
  std::vector<Window> windows;
  std::vector<int> class_of_clip;
  int classes = 0;
};

struct ClassifierTraining {
  int iterations = 3000;
  int batch = 32;
  double lr = 1e-3;
  // Each drawn window starts anywhere in its clip instead of at its start.
  bool random_starts = false;
  // With probability `swap_parts`, a drawn window gets the channels of one
  // of `part_channels` from another window of the same class.
  double swap_parts = 0;
  std::vector<std::vector<int64_t>> part_channels;
  std::string name;                             // For the progress lines.
  std::function<void(const std::string&)> log;  // Progress lines.
};

// Trains `net` with class-balanced batches (a class uniformly, then one of its
// windows) and small Gaussian noise on the input; `rng` draws the windows.
void TrainClassifier(Classifier& net, const ClassifierData& data, const ClassifierTraining& options,
                     std::mt19937_64* rng);

// Clip-level accuracy of `net` on `clips` (class_of_clip[i] is clip i's).
double ClipAccuracy(Classifier& net, const std::vector<motion::FeatureClip>& clips,
                    const std::vector<int>& class_of_clip);

}  // namespace stylus::model

#endif  // STYLUS_EVAL_CLASSIFIER_NET_H_
