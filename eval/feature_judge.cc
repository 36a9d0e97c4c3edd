#include "eval/feature_judge.h"

#include <torch/torch.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "model/window_tensor.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

namespace nn = torch::nn;
constexpr int kWindow = 32, kHop = 24, kWidth = 128, kHidden = 64;

torch::Tensor Lrelu(const torch::Tensor& x) { return torch::leaky_relu(x, 0.2); }

// Holden-style convolutional autoencoder: conv k7 -> conv k4 stride 2 (the
// hidden layer, half the frames) -> nearest upsampling -> conv k7 -> conv k7.
struct DaeImpl : nn::Module {
  explicit DaeImpl(int dim) {
    enc1 = register_module("enc1", nn::Conv1d(nn::Conv1dOptions(dim, kWidth, 7).padding(3)));
    enc2 = register_module("enc2",
                           nn::Conv1d(nn::Conv1dOptions(kWidth, kHidden, 4).stride(2).padding(1)));
    dec1 = register_module("dec1", nn::Conv1d(nn::Conv1dOptions(kHidden, kWidth, 7).padding(3)));
    dec2 = register_module("dec2", nn::Conv1d(nn::Conv1dOptions(kWidth, dim, 7).padding(3)));
  }
  torch::Tensor encode(const torch::Tensor& x) {
    return Lrelu(enc2->forward(Lrelu(enc1->forward(x))));
  }
  torch::Tensor forward(const torch::Tensor& x) {
    torch::Tensor h = torch::nn::functional::interpolate(
        encode(x), torch::nn::functional::InterpolateFuncOptions()
                       .scale_factor(std::vector<double>{2.0})
                       .mode(torch::kNearest));
    return dec2->forward(Lrelu(dec1->forward(h)));
  }
  nn::Conv1d enc1{nullptr}, enc2{nullptr}, dec1{nullptr}, dec2{nullptr};
};
TORCH_MODULE(Dae);

// The corruption: Gaussian noise and 10% of the channels zeroed.
torch::Tensor Corrupt(const torch::Tensor& x) {
  const torch::Tensor keep = (torch::rand({x.size(0), x.size(1), 1}) > 0.1).to(torch::kFloat32);
  return (x + 0.3 * torch::randn_like(x)) * keep;
}

torch::Tensor ToTensor(const std::vector<std::vector<double>>& s) {
  torch::Tensor t = torch::empty(
      {static_cast<int64_t>(s.size()), static_cast<int64_t>(s[0].size())}, torch::kFloat64);
  auto a = t.accessor<double, 2>();
  for (size_t i = 0; i < s.size(); ++i)
    for (size_t j = 0; j < s[i].size(); ++j) a[i][j] = s[i][j];
  return t;
}

// Symmetric positive semi-definite square root.
torch::Tensor SqrtPsd(const torch::Tensor& m) {
  auto [values, vectors] = torch::linalg::eigh(m, "L");
  return vectors.matmul(torch::diag(values.clamp_min(0).sqrt())).matmul(vectors.t());
}

}  // namespace

struct FeatureJudge::Impl {
  std::string dir;
  DataFiles shape;
  Dae net{nullptr};
};

absl::StatusOr<DaeTrainResult> TrainFeatureJudge(
    const std::vector<std::string>& data, const std::string& out, int iterations, uint64_t seed,
    const std::function<void(const std::string&)>& log) {
  absl::StatusOr<DataFiles> shape = ReadDataFiles(out);
  if (!shape.ok()) return shape.status();
  absl::StatusOr<TrainingSet> train =
      LoadTrainingSet(data, {kWindow, kHop}, {}, false, &shape->norm);
  if (!train.ok()) return train.status();
  absl::StatusOr<TrainingSet> test = LoadTrainingSet(data, {kWindow, kHop}, {}, true, &shape->norm);
  if (!test.ok()) return test.status();
  DaeTrainResult result;
  try {
    torch::manual_seed(seed);
    std::mt19937_64 rng(seed);
    Dae net(train->dim());
    torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(1e-3));
    for (int it = 1; it <= iterations; ++it) {
      std::vector<float> buf;
      train->SampleBatch(32, kWindow, &rng, &buf);
      const torch::Tensor x =
          torch::from_blob(buf.data(), {32, train->dim(), kWindow}, torch::kFloat32).clone();
      const torch::Tensor loss = torch::mse_loss(net->forward(Corrupt(x)), x);
      opt.zero_grad();
      loss.backward();
      opt.step();
      if (log && (it % 250 == 0 || it == iterations)) {
        log(absl::StrFormat("feature judge (denoising autoencoder): iter %d/%d loss %.4f", it,
                            iterations, loss.item<double>()));
      }
    }
    net->eval();
    c10::InferenceMode guard;
    torch::manual_seed(seed + 1);
    double noisy = 0, denoised = 0;
    for (const motion::FeatureClip& clip : test->clips) {
      motion::FeatureClip f = clip;
      PadToLength(&f, kWindow);
      const torch::Tensor x =
          WindowTensor(f, *motion::WindowStarts(f.frames, {kWindow, kHop}, true), kWindow);
      const torch::Tensor noisy_x = Corrupt(x);
      noisy += torch::mse_loss(noisy_x, x).item<double>();
      denoised += torch::mse_loss(net->forward(noisy_x), x).item<double>();
    }
    result.clips = static_cast<int>(test->clips.size());
    result.noisy_mse = noisy / result.clips;
    result.denoised_mse = denoised / result.clips;
    torch::save(net, out + "/dae.pt");
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training the feature judge: ", e.what()));
  }
  return result;
}

FeatureJudge::FeatureJudge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FeatureJudge::~FeatureJudge() = default;

absl::StatusOr<std::unique_ptr<FeatureJudge>> FeatureJudge::Load(const std::string& dir) {
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  absl::StatusOr<DataFiles> shape = ReadDataFiles(dir);
  if (!shape.ok()) return shape.status();
  impl->shape = *std::move(shape);
  try {
    impl->net = Dae(impl->shape.norm.dim());
    torch::load(impl->net, dir + "/dae.pt");
    impl->net->eval();
  } catch (const std::exception& e) {
    std::string what = e.what();
    return absl::InvalidArgumentError(absl::StrCat(
        dir, "/dae.pt: cannot load the feature judge (train it with stylus-tool train-judges): ",
        what.substr(0, what.find('\n'))));
  }
  return std::unique_ptr<FeatureJudge>(new FeatureJudge(std::move(impl)));
}

absl::StatusOr<FeatureMap> FeatureJudge::Features(const motion::Motion& clip) const {
  if (absl::Status s = CheckClipFitsModel(clip, impl_->shape, "clip"); !s.ok()) return s;
  absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, impl_->shape.roles);
  if (!f.ok()) return f.status();
  impl_->shape.norm.Normalize(&*f);
  PadToLength(&*f, 4);
  try {
    c10::InferenceMode guard;
    const torch::Tensor h = impl_->net->encode(WindowTensor(*f, {0}, f->frames))[0].contiguous();
    FeatureMap out;
    out.channels = static_cast<int>(h.size(0));
    out.frames = static_cast<int>(h.size(1));
    out.values.assign(h.data_ptr<float>(), h.data_ptr<float>() + h.numel());
    return out;
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("feature judge ", impl_->dir, ": ", e.what()));
  }
}

std::vector<double> Embedding(const FeatureMap& f) {
  std::vector<double> e(2 * f.channels, 0.0);
  for (int c = 0; c < f.channels; ++c) {
    double sum = 0, sq = 0;
    for (int t = 0; t < f.frames; ++t) {
      sum += f.row(c)[t];
      sq += static_cast<double>(f.row(c)[t]) * f.row(c)[t];
    }
    const double mean = sum / f.frames;
    e[c] = mean;
    e[f.channels + c] = std::sqrt(std::max(0.0, sq / f.frames - mean * mean));
  }
  return e;
}

double FrechetDistance(const std::vector<std::vector<double>>& a,
                       const std::vector<std::vector<double>>& b) {
  c10::InferenceMode guard;
  const torch::Tensor x = ToTensor(a), y = ToTensor(b);
  const torch::Tensor mx = x.mean(0), my = y.mean(0);
  const torch::Tensor cx = (x - mx).t().matmul(x - mx) / std::max<int64_t>(1, x.size(0) - 1);
  const torch::Tensor cy = (y - my).t().matmul(y - my) / std::max<int64_t>(1, y.size(0) - 1);
  const torch::Tensor root = SqrtPsd(cx);
  const torch::Tensor cross = SqrtPsd(root.matmul(cy).matmul(root));
  return ((mx - my).pow(2).sum() + cx.trace() + cy.trace() - 2 * cross.trace()).item<double>();
}

std::pair<double, double> KernelInceptionDistance(const std::vector<std::vector<double>>& a,
                                                  const std::vector<std::vector<double>>& b,
                                                  int subsets, int subset_size, uint64_t seed) {
  c10::InferenceMode guard;
  const torch::Tensor x = ToTensor(a), y = ToTensor(b);
  const int64_t m = std::min<int64_t>({subset_size, x.size(0), y.size(0)});
  const double d = static_cast<double>(x.size(1));
  std::mt19937_64 rng(seed);
  std::vector<double> values;
  for (int s = 0; s < subsets; ++s) {
    std::vector<int64_t> ia(x.size(0)), ib(y.size(0));
    std::iota(ia.begin(), ia.end(), 0);
    std::iota(ib.begin(), ib.end(), 0);
    std::shuffle(ia.begin(), ia.end(), rng);
    std::shuffle(ib.begin(), ib.end(), rng);
    ia.resize(m);
    ib.resize(m);
    const torch::Tensor xs = x.index_select(0, torch::tensor(ia));
    const torch::Tensor ys = y.index_select(0, torch::tensor(ib));
    auto k = [&](const torch::Tensor& p, const torch::Tensor& q) {
      return (p.matmul(q.t()) / d + 1).pow(3);
    };
    const torch::Tensor kxx = k(xs, xs), kyy = k(ys, ys), kxy = k(xs, ys);
    const double n = static_cast<double>(m);
    const double mmd = ((kxx.sum() - kxx.diag().sum()) / (n * (n - 1)) +
                        (kyy.sum() - kyy.diag().sum()) / (n * (n - 1)) - 2 * kxy.mean())
                           .item<double>();
    values.push_back(mmd);
  }
  double mean = 0, var = 0;
  for (double v : values) mean += v / values.size();
  for (double v : values) var += (v - mean) * (v - mean) / values.size();
  return {mean, std::sqrt(var)};
}

double Diversity(const std::vector<std::vector<double>>& set, int pairs, uint64_t seed) {
  if (set.size() < 2) return 0;
  std::mt19937_64 rng(seed);
  double sum = 0;
  for (int p = 0; p < pairs; ++p) {
    const size_t i = rng() % set.size();
    size_t j = rng() % (set.size() - 1);
    if (j >= i) ++j;
    double d = 0;
    for (size_t k = 0; k < set[i].size(); ++k)
      d += (set[i][k] - set[j][k]) * (set[i][k] - set[j][k]);
    sum += std::sqrt(d);
  }
  return sum / pairs;
}

double ContentDistance(const FeatureMap& a, const FeatureMap& b) {
  const int t = std::min(a.frames, b.frames);
  double sum = 0;
  for (int c = 0; c < a.channels; ++c)
    for (int i = 0; i < t; ++i) sum += std::pow(a.row(c)[i] - b.row(c)[i], 2);
  return sum / (static_cast<double>(a.channels) * t);
}

double StyleDistance(const FeatureMap& a, const FeatureMap& b) {
  auto gram = [](const FeatureMap& f) {
    std::vector<double> g(static_cast<size_t>(f.channels) * f.channels, 0.0);
    for (int i = 0; i < f.channels; ++i)
      for (int j = 0; j <= i; ++j) {
        double s = 0;
        for (int t = 0; t < f.frames; ++t) s += static_cast<double>(f.row(i)[t]) * f.row(j)[t];
        g[i * f.channels + j] = g[j * f.channels + i] = s / f.frames;
      }
    return g;
  };
  const std::vector<double> ga = gram(a), gb = gram(b);
  double sum = 0;
  for (size_t i = 0; i < ga.size(); ++i) sum += (ga[i] - gb[i]) * (ga[i] - gb[i]);
  return sum / ga.size();
}

}  // namespace stylus::model
