#include "model/cyclic/cyclic_model.h"

#include <torch/torch.h>

#include "absl/strings/str_cat.h"
#include "model/config_text.h"
#include "model/content_guard.h"
#include "model/cyclic/cyclic_net.h"
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
    torch::Tensor x = torch::from_blob(norm.values.data(), {norm.frames, norm.dim}, torch::kFloat32)
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
  return {c.family, c.window, c.hop, c.dim, c.trained_iterations};
}
int CyclicModel::code_size() const { return impl_->config.code_size(); }
const ContentGuard* CyclicModel::content_guard() const { return impl_->guard.get(); }
const GuardKeys& CyclicModel::guard_keys() const { return impl_->config; }
const MovementKeys& CyclicModel::movement_keys() const { return impl_->config; }

absl::StatusOr<std::unique_ptr<CyclicModel>> CyclicModel::Load(const std::string& dir,
                                                               const std::string& overrides) {
  absl::StatusOr<CyclicConfig> config = CyclicConfig::Read(dir, overrides);
  if (!config.ok()) return config.status();
  absl::StatusOr<DataFiles> data = ReadPackageData(dir, config->dim);
  if (!data.ok()) return data.status();
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->config = *config;
  impl->data = *std::move(data);
  const int joints = impl->data.skeleton.num_joints();
  impl->channels = torch::tensor(CyclicChannels(joints, impl->config.rotations));
  impl->kinematic = std::make_unique<KinematicLoss>(impl->data.skeleton, impl->data.roles,
                                                    impl->data.norm, impl->data.frame_time);
  impl->net = CyclicNet(impl->config, impl->config.net_channels(joints));
  if (absl::Status s = LoadWeights(impl->net, dir + "/weights.pt"); !s.ok()) return s;
  impl->net->eval();
  for (torch::Tensor& p : impl->net->parameters()) p.requires_grad_(false);
  if (impl->config.content_guard ||
      (impl->config.movement_examples && impl->config.movement_action_gate > 0)) {
    absl::StatusOr<std::unique_ptr<ContentGuard>> guard =
        ContentGuard::Load(dir, impl->config.dim, impl->config.window, impl->config.hop);
    if (!guard.ok()) return guard.status();
    impl->guard = *std::move(guard);
  }
  return std::unique_ptr<CyclicModel>(new CyclicModel(std::move(impl)));
}

absl::StatusOr<StyleCode> CyclicModel::EncodeModelRateStyle(const motion::Motion& clip) const {
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

absl::StatusOr<torch::Tensor> CyclicModel::Impl::Restyle(const torch::Tensor& hx,
                                                         const std::vector<StyleCode>& styles,
                                                         const StyleWeights& weights, int frames) {
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
  return net->transform(hx, style);
}

absl::StatusOr<motion::Motion> CyclicModel::Impl::Render(bool optimize,
                                                         const motion::Motion& content,
                                                         const motion::FeatureClip& real,
                                                         const torch::Tensor& x,
                                                         const torch::Tensor& hx, torch::Tensor h) {
  const int frames = real.frames;
  motion::FeatureClip out = real;  // Rotations: the content's, as the fit's twist.
  try {
    if (optimize && config.use_kc && config.kc_iters > 0) {
      const torch::Tensor offset = config.residual ? (x - net->decode(hx)) : torch::zeros_like(x);
      OptimizeHidden(net, *kinematic, config, x, offset, &h);
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

// The content's network input and hidden features, and the restyled ones;
// form k lies k of the way from the content's to the restyled.
class CyclicModel::ClipForms : public StyleModel::Forms {
 public:
  ClipForms(Impl* impl, const motion::Motion& content, motion::FeatureClip real, torch::Tensor x,
            torch::Tensor hx, torch::Tensor restyled)
      : impl_(impl),
        content_(content),
        real_(std::move(real)),
        x_(std::move(x)),
        hx_(std::move(hx)),
        restyled_(std::move(restyled)) {}

  absl::StatusOr<motion::Motion> Draft(size_t step) override {
    return impl_->Render(false, content_, real_, x_, hx_, Hidden(step));
  }
  absl::StatusOr<motion::Motion> Final(size_t step, const motion::Motion* draft) override {
    const bool optimize = impl_->config.use_kc && impl_->config.kc_iters > 0;
    if (draft != nullptr && !optimize) return *draft;
    return impl_->Render(optimize, content_, real_, x_, hx_, Hidden(step));
  }

 private:
  torch::Tensor Hidden(size_t step) const {
    if (step == 0) return restyled_;
    const double k = impl_->config.guard_strengths[step - 1];
    return hx_ + k * (restyled_ - hx_);
  }

  Impl* impl_;
  const motion::Motion& content_;
  motion::FeatureClip real_;
  torch::Tensor x_, hx_, restyled_;
};

absl::StatusOr<std::unique_ptr<StyleModel::Forms>> CyclicModel::PrepareTransfer(
    const motion::Motion& content, const std::vector<StyleCode>& styles,
    const StyleWeights& weights, PassBatcher* /*batcher: whole clips of any length*/) const {
  auto input = impl_->Input(content, "content clip");
  if (!input.ok()) return input.status();
  torch::Tensor hx, restyled;
  try {
    torch::NoGradGuard no_grad;
    hx = impl_->net->encode(input->second);
    absl::StatusOr<torch::Tensor> h = impl_->Restyle(hx, styles, weights, input->first.frames);
    if (!h.ok()) return h.status();
    restyled = *std::move(h);
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
  return std::make_unique<ClipForms>(impl_.get(), content, std::move(input->first),
                                     std::move(input->second), std::move(hx), std::move(restyled));
}

ModelFamily CyclicFamily() { return MakeFamily<CyclicModel, CyclicConfig>("cyclic"); }

}  // namespace stylus::model
