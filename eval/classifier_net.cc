#include "eval/classifier_net.h"

#include <random>

#include "absl/strings/str_format.h"
#include "model/window_tensor.h"
#include "motion/windowing.h"

namespace stylus::model {
namespace {

namespace nn = torch::nn;
constexpr int kWidth = 128;

}  // namespace

ClassifierImpl::ClassifierImpl(int dim, int classes) {
  conv1 = register_module("conv1", nn::Conv1d(nn::Conv1dOptions(dim, kWidth, 5).padding(2)));
  conv2 = register_module("conv2",
                          nn::Conv1d(nn::Conv1dOptions(kWidth, kWidth, 4).stride(2).padding(1)));
  conv3 = register_module("conv3", nn::Conv1d(nn::Conv1dOptions(kWidth, kWidth, 5).padding(2)));
  fc = register_module("fc", nn::Linear(kWidth, classes));
}

torch::Tensor ClassifierImpl::forward(torch::Tensor x) {
  const auto lrelu = [](const torch::Tensor& t) { return torch::leaky_relu(t, 0.2); };
  x = lrelu(conv1->forward(x));
  x = lrelu(conv2->forward(x));
  x = lrelu(conv3->forward(x));
  return fc->forward(x.mean(2));
}

torch::Tensor ClipLogits(Classifier& net, motion::FeatureClip f) {
  PadToLength(&f, kJudgeWindow);
  const std::vector<int> starts = *motion::WindowStarts(f.frames, {kJudgeWindow, kJudgeHop}, true);
  return net->forward(WindowTensor(f, starts, kJudgeWindow)).mean(0);
}

void TrainClassifier(Classifier& net, const ClassifierData& data, const ClassifierTraining& o,
                     std::mt19937_64* rng) {
  const std::vector<motion::FeatureClip>& clips = *data.clips;
  std::uniform_real_distribution<double> uniform(0, 1);
  std::vector<torch::Tensor> part_channels;
  for (const std::vector<int64_t>& c : o.part_channels) {
    part_channels.push_back(torch::tensor(c, torch::kLong));
  }
  std::vector<std::vector<int>> windows_of(data.classes);
  for (size_t w = 0; w < data.windows.size(); ++w) {
    windows_of[data.class_of_clip[data.windows[w].clip]].push_back(static_cast<int>(w));
  }
  torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(o.lr));
  const int d = clips.front().dim;
  auto draw_window = [&](int c) -> torch::Tensor {
    const auto& w = data.windows[windows_of[c][(*rng)() % windows_of[c].size()]];
    const motion::FeatureClip& clip = clips[w.clip];
    const int start =
        o.random_starts && clip.frames >= kJudgeWindow
            ? static_cast<int>((*rng)() % static_cast<uint64_t>(clip.frames - kJudgeWindow + 1))
            : w.start;
    return WindowTensor(clip, {start}, kJudgeWindow)[0];
  };
  for (int it = 1; it <= o.iterations; ++it) {
    torch::Tensor x = torch::empty({o.batch, d, kJudgeWindow});
    torch::Tensor y = torch::empty({o.batch}, torch::kLong);
    for (int b = 0; b < o.batch; ++b) {
      int c;
      do c = static_cast<int>((*rng)() % data.classes);
      while (windows_of[c].empty());
      x[b] = draw_window(c);
      y[b] = c;
      if (o.swap_parts > 0 && !part_channels.empty() && uniform(*rng) < o.swap_parts) {
        const torch::Tensor& part = part_channels[(*rng)() % part_channels.size()];
        x[b].index_copy_(0, part, draw_window(c).index_select(0, part));
      }
    }
    // Small Gaussian noise: the judges must not hinge on exact values.
    const torch::Tensor loss =
        torch::nn::functional::cross_entropy(net->forward(x + 0.05 * torch::randn_like(x)), y);
    opt.zero_grad();
    loss.backward();
    opt.step();
    if (o.log && (it % 250 == 0 || it == o.iterations)) {
      o.log(absl::StrFormat("%s judge: iter %d/%d loss %.4f", o.name, it, o.iterations,
                            loss.item<double>()));
    }
  }
  net->eval();
}

double ClipAccuracy(Classifier& net, const std::vector<motion::FeatureClip>& clips,
                    const std::vector<int>& class_of_clip) {
  if (clips.empty()) return 0;
  c10::InferenceMode guard;
  int right = 0;
  for (size_t i = 0; i < clips.size(); ++i) {
    right += ClipLogits(net, clips[i]).argmax().item<int64_t>() == class_of_clip[i];
  }
  return static_cast<double>(right) / clips.size();
}

}  // namespace stylus::model
