#include "model/cyclic_model.h"

#include <torch/torch.h>

#include <fstream>

#include "absl/strings/str_cat.h"
#include "model/config_text.h"
#include "model/content_guard.h"
#include "model/contrastive_model.h"
#include "model/cyclic_net.h"
#include "model/weights_io.h"
#include "motion/features.h"
#include "motion/position_fit.h"

namespace stylus::model {

struct CyclicModel::Impl {
  std::string dir;
  CyclicConfig config;
  DataFiles data;
  CyclicNet net{nullptr};
  std::unique_ptr<KinematicLoss> kinematic;
  torch::Tensor channels;
  int kc_iters = 0;
  bool adain = false;
  std::unique_ptr<ContentGuard> guard;  // With config.content_guard.

  absl::Status Internal(const std::exception& e) const {
    return absl::InternalError(absl::StrCat("model ", dir, ": ", e.what()));
  }

  // The clip's real features and its normalized network channels as
  // (1, C, T), T padded to even by repeating the last frame.
  absl::StatusOr<std::pair<motion::FeatureClip, torch::Tensor>> Input(
      const motion::Motion& clip, const std::string& what) const {
    if (absl::Status s = CheckClipFitsModel(clip, data, what); !s.ok()) return s;
    absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, data.roles);
    if (!f.ok()) return f.status();
    motion::FeatureClip norm = *f;
    data.norm.Normalize(&norm);
    torch::Tensor x = torch::from_blob(norm.values.data(), {norm.frames, norm.dim},
                                       torch::kFloat32)
                          .index_select(1, channels)
                          .t()
                          .unsqueeze(0);
    if (norm.frames % 2) x = torch::cat({x, x.slice(2, norm.frames - 1, norm.frames)}, 2);
    return std::make_pair(*std::move(f), x.contiguous());
  }

  // The content's hidden features `hx` restyled by the mix of `styles`.
  absl::StatusOr<torch::Tensor> Restyle(const torch::Tensor& hx,
                                        const std::vector<StyleCode>& styles,
                                        const StyleWeights& weights, int frames);
  // The motion of restyled hidden features `h` of the content clip (real
  // features `real`, network input `x`, own hidden features `hx`): the
  // kinematic optimization when on (and `optimize`), the output channels in
  // real units, rotations fitted to the positions. Not post-processed.
  absl::StatusOr<motion::Motion> Render(bool optimize, const motion::Motion& content,
                                        const motion::FeatureClip& real, const torch::Tensor& x,
                                        const torch::Tensor& hx, torch::Tensor h);
};

CyclicModel::CyclicModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CyclicModel::~CyclicModel() = default;
const CyclicConfig& CyclicModel::config() const { return impl_->config; }
const std::string& CyclicModel::dir() const { return impl_->dir; }
const DataFiles& CyclicModel::data() const { return impl_->data; }
ModelSummary CyclicModel::summary() const {
  const CyclicConfig& c = impl_->config;
  return {c.family, c.window, c.hop, c.trained_iterations};
}

absl::StatusOr<std::unique_ptr<CyclicModel>> CyclicModel::Load(const std::string& dir,
                                                               CyclicOptions options) {
  absl::StatusOr<CyclicConfig> config = CyclicConfig::Read(dir);
  if (!config.ok()) return config.status();
  absl::StatusOr<DataFiles> data = ReadDataFiles(dir);
  if (!data.ok()) return data.status();
  if (config->dim != data->norm.dim()) {
    return absl::InvalidArgumentError(absl::StrCat(dir, ": config.txt says ", config->dim,
                                                   " feature channels, norm.txt has ",
                                                   data->norm.dim()));
  }
  if (options.adain && config->style_dim > 0) {
    return absl::InvalidArgumentError(
        dir + ": the AdaIN probe needs the statistics style code (style_dim = 0)");
  }
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->config = *config;
  impl->data = *std::move(data);
  impl->kc_iters = options.kc_iters >= 0 ? options.kc_iters : config->kc_iters;
  impl->adain = options.adain;
  const int joints = impl->data.skeleton.num_joints();
  impl->channels = torch::tensor(CyclicChannels(joints, impl->config.rotations));
  impl->kinematic = std::make_unique<KinematicLoss>(impl->data.skeleton, impl->data.roles,
                                                    impl->data.norm, impl->data.frame_time);
  impl->net = CyclicNet(impl->config, impl->config.net_channels(joints));
  const std::string weights = dir + "/weights.pt";
  if (!std::ifstream(weights)) return absl::NotFoundError(weights + ": missing");
  if (absl::Status s = LoadWeights(impl->net, weights); !s.ok()) return s;
  impl->net->eval();
  for (torch::Tensor& p : impl->net->parameters()) p.requires_grad_(false);
  if (impl->config.content_guard) {
    absl::StatusOr<std::unique_ptr<ContentGuard>> guard =
        ContentGuard::Load(dir, impl->config.dim, impl->config.window, impl->config.hop);
    if (!guard.ok()) return guard.status();
    impl->guard = *std::move(guard);
  }
  return std::unique_ptr<CyclicModel>(new CyclicModel(std::move(impl)));
}

absl::StatusOr<StyleCode> CyclicModel::EncodeStyle(const motion::Motion& clip) const {
  auto input = impl_->Input(clip, "style clip");
  if (!input.ok()) return input.status();
  try {
    torch::NoGradGuard no_grad;
    const torch::Tensor s = impl_->net->code(input->second).flatten();
    return StyleCode{std::vector<float>(s.data_ptr<float>(), s.data_ptr<float>() + s.numel())};
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
}

absl::StatusOr<motion::Motion> CyclicModel::Interpolate(const motion::Motion& content,
                                                        const std::vector<StyleCode>& styles,
                                                        const StyleWeights& weights,
                                                        motion::PostProcessMode post) const {
  return InterpolateNoted(content, styles, weights, post, nullptr);
}

absl::StatusOr<torch::Tensor> CyclicModel::Impl::Restyle(const torch::Tensor& hx,
                                                         const std::vector<StyleCode>& styles,
                                                         const StyleWeights& weights,
                                                         int frames) {
  const int code_size = config.code_size();
  const int64_t steps = hx.size(2);
  std::vector<StyleCode> codes;
  if (weights.per_frame.empty()) {
    codes.push_back(MixStyles(styles, weights.fixed));
  } else {
    for (int64_t k = 0; k < steps; ++k) {
      codes.push_back(MixStyles(styles, weights.per_frame[std::min<int64_t>(2 * k, frames - 1)]));
    }
  }
  torch::Tensor style = torch::empty({1, code_size, static_cast<int64_t>(codes.size())});
  for (size_t k = 0; k < codes.size(); ++k) {
    style.select(2, static_cast<int64_t>(k))
        .copy_(torch::from_blob(codes[k].values.data(), {1, code_size}, torch::kFloat32));
  }
  if (!adain) return net->transform(hx, style);
  const torch::Tensor own = CyclicNetImpl::stats(hx);
  const int64_t n = config.hidden;
  return (hx - own.slice(1, 0, n)) / own.slice(1, n, 2 * n) * style.slice(1, n, 2 * n) +
         style.slice(1, 0, n);
}

absl::StatusOr<motion::Motion> CyclicModel::Impl::Render(bool optimize,
                                                         const motion::Motion& content,
                                                         const motion::FeatureClip& real,
                                                         const torch::Tensor& x,
                                                         const torch::Tensor& hx,
                                                         torch::Tensor h) {
  const int frames = real.frames;
  motion::FeatureClip out = real;  // Rotations: the content's, as the fit's twist.
  try {
    if (optimize && config.use_kc && kc_iters > 0) {
      CyclicConfig run = config;
      run.kc_iters = kc_iters;
      const torch::Tensor offset = config.residual ? (x - net->decode(hx)) : torch::zeros_like(x);
      OptimizeHidden(net, *kinematic, run, x, offset, &h);
    }
    torch::NoGradGuard no_grad;
    // Back to real units in the full feature layout.
    const torch::Tensor y = net->output(x, hx, h)[0].slice(1, 0, frames).t().contiguous();
    const int joints = content.skeleton.num_joints();
    const std::vector<int64_t> channels = CyclicChannels(joints, config.rotations);
    const float* yp = y.data_ptr<float>();
    const int width = static_cast<int>(channels.size());
    // keep_path: the path channels (root trajectory, contacts) stay the content's.
    const int path_from = 3 * joints, path_to = path_from + motion::FeatureLayout::kPathChannels;
    for (int f = 0; f < frames; ++f) {
      for (int i = 0; i < width; ++i) {
        if (config.keep_path && i >= path_from && i < path_to) continue;
        const int64_t c = channels[i];
        out.row(f)[c] = yp[f * width + i] * data.norm.std[c] + data.norm.mean[c];
      }
    }
  } catch (const std::exception& e) {
    return Internal(e);
  }
  // With generated rotations, the content's still say which joints are
  // hinges (a generated knee turns about its axis only nearly).
  motion::FitRotationsToPositions(content.skeleton, data.roles, &out,
                                  config.rotations ? &real : nullptr);
  return motion::MotionFromFeatures(out, content.skeleton, data.roles, content.frame_time,
                                    motion::RootAt(content, data.roles, 0));
}

absl::StatusOr<motion::Motion> CyclicModel::InterpolateNoted(const motion::Motion& content,
                                                             const std::vector<StyleCode>& styles,
                                                             const StyleWeights& weights,
                                                             motion::PostProcessMode post,
                                                             TransferNote* note) const {
  const CyclicConfig& config = impl_->config;
  if (absl::Status s = CheckStyleMix(styles, weights, content.num_frames, config.code_size());
      !s.ok())
    return s;
  auto input = impl_->Input(content, "content clip");
  if (!input.ok()) return input.status();
  const motion::FeatureClip& real = input->first;
  const torch::Tensor& x = input->second;
  torch::Tensor hx, restyled;
  try {
    torch::NoGradGuard no_grad;
    hx = impl_->net->encode(x);
    absl::StatusOr<torch::Tensor> h = impl_->Restyle(hx, styles, weights, real.frames);
    if (!h.ok()) return h.status();
    restyled = *std::move(h);
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
  absl::StatusOr<motion::Motion> out;
  if (!impl_->guard) {
    out = impl_->Render(true, content, real, x, hx, restyled);
  } else {
    // The content guard: the configured transfer, then the hidden features
    // restyled a strength k of the way, for each of guard_strengths, until
    // the guard reads the content's action. The guard reads each form
    // before the kinematic optimization and post-processing (`eval` judges
    // raw rows); only the form it passes is optimized, so a guarded
    // transfer costs one optimization, not one per form.
    motion::FeatureClip normalized = real;
    impl_->data.norm.Normalize(&normalized);
    const int action = impl_->guard->Classify(normalized);
    const std::vector<double>& strengths = config.guard_strengths;
    for (size_t step = 0; step <= strengths.size(); ++step) {
      const double k = step == 0 ? 1.0 : strengths[step - 1];
      const torch::Tensor h = step == 0 ? restyled : hx + k * (restyled - hx);
      out = impl_->Render(false, content, real, x, hx, h);
      if (!out.ok()) return out.status();
      absl::StatusOr<motion::FeatureClip> read = motion::ExtractFeatures(*out, impl_->data.roles);
      if (!read.ok()) return read.status();
      impl_->data.norm.Normalize(&*read);
      if (impl_->guard->Keeps(*read, action, config.guard_min_probability) ||
          step == strengths.size()) {
        if (note != nullptr) *note = TransferNote::Guarded(step, strengths);
        if (config.use_kc && impl_->kc_iters > 0) out = impl_->Render(true, content, real, x, hx, h);
        break;
      }
    }
  }
  if (!out.ok()) return out.status();
  return motion::PostProcess(*out, content, impl_->data.roles, post);
}

absl::StatusOr<std::unique_ptr<StyleModel>> LoadStyleModel(const std::string& dir) {
  absl::StatusOr<std::string> family = ReadConfigFamily(dir);
  if (!family.ok()) return family.status();
  if (*family == "cyclic") {
    absl::StatusOr<std::unique_ptr<CyclicModel>> m = CyclicModel::Load(dir);
    if (!m.ok()) return m.status();
    return std::unique_ptr<StyleModel>(std::move(*m));
  }
  if (*family == "contrastive") {
    absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(dir);
    if (!m.ok()) return m.status();
    return std::unique_ptr<StyleModel>(std::move(*m));
  }
  return absl::InvalidArgumentError(absl::StrCat(dir, "/config.txt: unknown family '", *family,
                                                 "' (known: contrastive, cyclic)"));
}

}  // namespace stylus::model
