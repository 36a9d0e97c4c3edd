#include "model/contrastive/contrastive_model.h"

#include <torch/torch.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "model/content_guard.h"
#include "model/contrastive/contrastive_net.h"
#include "model/contrastive/live_engine.h"
#include "model/contrastive/live_streamer.h"
#include "model/contrastive/window_streamer.h"
#include "model/pass_batching.h"
#include "model/weights_io.h"
#include "model/window_blend.h"
#include "model/window_tensor.h"
#include "motion/features.h"
#include "motion/windowing.h"

namespace stylus::model {

struct ContrastiveModel::Impl {
  std::string dir;
  ContrastiveConfig config;
  DataFiles data;
  ContrastiveNet net{nullptr};
  std::unique_ptr<ContentGuard> guard;  // With config.content_guard.
  std::unique_ptr<LiveEngine> engine;   // With config.live.

  // What GenerateWindows takes from the config, so the guard can vary it.
  struct Knobs {
    double strength = 1;
    bool residual = false;
    double content_detail = 0;
  };
  Knobs Configured() const {
    return {config.style_strength, config.residual, config.content_detail};
  }
  // The network passes every form of one clip's transfer shares: its
  // windows, their content codes, their own style codes and the generator's
  // output for those (the residual form's subtrahend). Filled on first use.
  struct SharedPasses {
    torch::Tensor x, content, own_style, own_decode;
    PassBatcher* batcher = nullptr;  // Passes may batch with other calls'.
  };
  // The networks' passes, through `batcher` when there is one.
  enum PassId { kContentPass, kStylePass, kDecodePass };
  torch::Tensor ContentPass(const torch::Tensor& x, PassBatcher* batcher);
  torch::Tensor StylePass(const torch::Tensor& x, PassBatcher* batcher);
  torch::Tensor DecodePass(const torch::Tensor& content, const torch::Tensor& codes,
                           PassBatcher* batcher);
  // `shared` (may be null) carries passes from one form to the next.
  absl::StatusOr<std::vector<float>> Generate(const motion::FeatureClip& features,
                                              const std::vector<int>& starts,
                                              const std::vector<StyleCode>& codes,
                                              const Knobs& knobs, SharedPasses* shared = nullptr);
  // Windows generated for `codes` at `starts`, cross-faded into a motion on
  // `content`'s skeleton (not post-processed).
  absl::StatusOr<motion::Motion> Render(const motion::Motion& content,
                                        const motion::FeatureClip& features,
                                        const std::vector<int>& starts,
                                        const std::vector<StyleCode>& codes, const Knobs& knobs,
                                        SharedPasses* shared = nullptr);

  absl::Status Internal(const std::exception& e) const {
    return absl::InternalError(absl::StrCat("model ", dir, ": ", e.what()));
  }

  std::vector<int> Starts(int frames) const {
    return *motion::WindowStarts(frames, {config.window, config.hop},
                                 /*cover_tail=*/true);
  }

  torch::Tensor Windows(const motion::FeatureClip& f, const std::vector<int>& starts) const {
    return WindowTensor(f, starts, config.window);
  }
};

ContrastiveModel::ContrastiveModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ContrastiveModel::~ContrastiveModel() = default;
const ContrastiveConfig& ContrastiveModel::config() const { return impl_->config; }
const DataFiles& ContrastiveModel::data() const { return impl_->data; }
const std::string& ContrastiveModel::dir() const { return impl_->dir; }
ModelSummary ContrastiveModel::summary() const {
  const ContrastiveConfig& c = impl_->config;
  return {c.family,
          c.window,
          c.hop,
          c.dim,
          c.trained_iterations,
          c.live,
          c.live ? c.lookahead : 0,
          impl_->engine ? impl_->engine->macs() : 0};
}
int ContrastiveModel::code_size() const { return impl_->config.channels; }
const ContentGuard* ContrastiveModel::content_guard() const { return impl_->guard.get(); }
const GuardKeys& ContrastiveModel::guard_keys() const { return impl_->config; }
const MovementKeys& ContrastiveModel::movement_keys() const { return impl_->config; }

absl::StatusOr<std::unique_ptr<ContrastiveModel>> ContrastiveModel::Load(
    const std::string& dir, const std::string& overrides) {
  absl::StatusOr<ContrastiveConfig> config = ContrastiveConfig::Read(dir, overrides);
  if (!config.ok()) return config.status();
  absl::StatusOr<DataFiles> data = ReadPackageData(dir, config->dim);
  if (!data.ok()) return data.status();
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->config = *std::move(config);
  impl->data = *std::move(data);
  impl->net = ContrastiveNet(impl->config);
  if (absl::Status s = LoadWeights(impl->net, dir + "/weights.pt"); !s.ok()) return s;
  impl->net->eval();
  if (impl->config.live) impl->engine = std::make_unique<LiveEngine>(*impl->net);
  const ContrastiveConfig& c = impl->config;
  if (c.content_guard || (c.movement_examples && c.movement_action_gate > 0)) {
    absl::StatusOr<std::unique_ptr<ContentGuard>> guard =
        ContentGuard::Load(dir, c.dim, c.window, c.hop);
    if (!guard.ok()) return guard.status();
    impl->guard = *std::move(guard);
  }
  return std::unique_ptr<ContrastiveModel>(new ContrastiveModel(std::move(impl)));
}

absl::StatusOr<StyleCode> ContrastiveModel::EncodeModelRateStyle(const motion::Motion& clip) const {
  absl::StatusOr<motion::FeatureClip> f = NormalizedFeatures(clip, "style clip");
  if (!f.ok()) return f.status();
  PadToLength(&*f, impl_->config.window);
  try {
    c10::InferenceMode guard;
    const torch::Tensor s =
        impl_->net->style(impl_->Windows(*f, impl_->Starts(f->frames))).mean(0).contiguous();
    return StyleCode{std::vector<float>(s.data_ptr<float>(), s.data_ptr<float>() + s.numel())};
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
}

absl::StatusOr<motion::FeatureClip> ContrastiveModel::NormalizedFeatures(
    const motion::Motion& clip, const std::string& what,
    const std::vector<motion::Quat>* sign_reference) const {
  if (absl::Status s = CheckClipFitsModel(clip, impl_->data, what); !s.ok()) return s;
  absl::StatusOr<motion::FeatureClip> f =
      motion::ExtractFeatures(clip, impl_->data.roles, impl_->config.Contacts(), sign_reference);
  if (!f.ok()) return f.status();
  impl_->data.norm.Normalize(&*f);
  return f;
}

absl::StatusOr<std::vector<float>> ContrastiveModel::GenerateWindows(
    const motion::FeatureClip& features, const std::vector<int>& starts,
    const std::vector<StyleCode>& codes) const {
  return impl_->Generate(features, starts, codes, impl_->Configured());
}

absl::StatusOr<std::vector<float>> ContrastiveModel::Impl::Generate(
    const motion::FeatureClip& features, const std::vector<int>& starts,
    const std::vector<StyleCode>& codes, const Knobs& knobs, SharedPasses* shared) {
  if (codes.size() != starts.size()) {
    return absl::InvalidArgumentError("one style code per window is needed");
  }
  for (size_t w = 0; w < starts.size(); ++w) {
    if (starts[w] < 0 || starts[w] + config.window > features.frames) {
      return absl::InvalidArgumentError(absl::StrCat(
          "window at frame ", starts[w], " does not fit in ", features.frames, " frames"));
    }
    if (static_cast<int>(codes[w].values.size()) != config.channels) {
      return absl::InvalidArgumentError(absl::StrCat("style code has ", codes[w].values.size(),
                                                     " values; this model's have ",
                                                     config.channels));
    }
  }
  try {
    c10::InferenceMode guard;
    torch::Tensor code_tensor =
        torch::empty({static_cast<int64_t>(starts.size()), config.channels});
    for (size_t w = 0; w < starts.size(); ++w) {
      code_tensor[w].copy_(torch::from_blob(const_cast<float*>(codes[w].values.data()),
                                            {config.channels}, torch::kFloat32));
    }
    SharedPasses local;
    SharedPasses& passes = shared != nullptr ? *shared : local;
    if (!passes.x.defined()) {
      passes.x = Windows(features, starts);
      passes.content = ContentPass(passes.x, passes.batcher);
    }
    const torch::Tensor& x = passes.x;
    if ((knobs.strength < 1 || knobs.residual) && !passes.own_style.defined()) {
      passes.own_style = StylePass(x, passes.batcher);
    }
    if (knobs.strength < 1) {
      const double k = knobs.strength;
      code_tensor = k * code_tensor + (1 - k) * passes.own_style;
    }
    torch::Tensor y = DecodePass(passes.content, code_tensor, passes.batcher);
    // residual: the content window plus what the style changes in the
    // generator's output; what the generator loses of any window cancels.
    if (knobs.residual) {
      if (!passes.own_decode.defined()) {
        passes.own_decode = DecodePass(passes.content, passes.own_style, passes.batcher);
      }
      y = y - passes.own_decode;
    }
    y = FinishWindows(config, x, y, knobs.content_detail, knobs.residual);
    y = y.contiguous();
    return std::vector<float>(y.data_ptr<float>(), y.data_ptr<float>() + y.numel());
  } catch (const std::exception& e) {
    return Internal(e);
  }
}

torch::Tensor ContrastiveModel::Impl::ContentPass(const torch::Tensor& x, PassBatcher* batcher) {
  return RunPass(batcher, this, kContentPass, {x},
                 [this](const std::vector<torch::Tensor>& in) { return net->content(in[0]); });
}

torch::Tensor ContrastiveModel::Impl::StylePass(const torch::Tensor& x, PassBatcher* batcher) {
  return RunPass(batcher, this, kStylePass, {x},
                 [this](const std::vector<torch::Tensor>& in) { return net->style(in[0]); });
}

torch::Tensor ContrastiveModel::Impl::DecodePass(const torch::Tensor& content,
                                                 const torch::Tensor& codes, PassBatcher* batcher) {
  return RunPass(
      batcher, this, kDecodePass, {content, codes},
      [this](const std::vector<torch::Tensor>& in) { return net->decode(in[0], in[1]); });
}

// One clip's windows and their style codes; the forms share their network
// passes.
class ContrastiveModel::ClipForms : public StyleModel::Forms {
 public:
  ClipForms(Impl* impl, const motion::Motion& content, motion::FeatureClip features,
            std::vector<int> starts, std::vector<StyleCode> codes, PassBatcher* batcher)
      : impl_(impl),
        content_(content),
        features_(std::move(features)),
        starts_(std::move(starts)),
        codes_(std::move(codes)) {
    shared_.batcher = batcher;
  }

  absl::StatusOr<motion::Motion> Draft(size_t step) override {
    const Impl::Knobs knobs =
        step == 0 ? impl_->Configured()
                  : Impl::Knobs{impl_->config.guard_strengths[step - 1], /*residual=*/true, 0};
    return impl_->Render(content_, features_, starts_, codes_, knobs, &shared_);
  }

 private:
  Impl* impl_;
  const motion::Motion& content_;
  motion::FeatureClip features_;
  std::vector<int> starts_;
  std::vector<StyleCode> codes_;
  Impl::SharedPasses shared_;
};

// A live package's transfer of a whole clip: one causal pass, each frame
// with its own style code, the same frames a stream of the clip generates
// before post-processing. It has one form (live packages have no guard).
class ContrastiveModel::LiveForms : public StyleModel::Forms {
 public:
  LiveForms(Impl* impl, const motion::Motion& content, motion::FeatureClip features,
            torch::Tensor codes)
      : impl_(impl), content_(content), features_(std::move(features)), codes_(std::move(codes)) {}

  absl::StatusOr<motion::Motion> Draft(size_t step) override {
    if (step != 0) return absl::InternalError("a live package has one form");
    const ContrastiveConfig& config = impl_->config;
    motion::FeatureClip out;
    try {
      c10::InferenceMode guard;
      const torch::Tensor x = WindowTensor(features_, {0}, features_.frames);
      torch::Tensor y = impl_->net->render(x, impl_->net->content(x), codes_);
      const int64_t path = config.dim - motion::FeatureLayout::kPathChannels;
      if (config.style_strength != 1) {
        const double k = config.style_strength;
        y.slice(1, 0, path).mul_(k).add_((1 - k) * x.slice(1, 0, path));
      }
      if (config.keep_path) y.slice(1, path).copy_(x.slice(1, path));
      // (1, dim, T) -> frames x dim.
      y = y[0].transpose(0, 1).contiguous();
      out.frames = features_.frames;
      out.dim = config.dim;
      out.values.assign(y.data_ptr<float>(), y.data_ptr<float>() + y.numel());
    } catch (const std::exception& e) {
      return impl_->Internal(e);
    }
    impl_->data.norm.Denormalize(&out);
    return motion::MotionFromFeatures(out, content_.skeleton, impl_->data.roles,
                                      content_.frame_time,
                                      motion::RootAt(content_, impl_->data.roles, 0));
  }

 private:
  Impl* impl_;
  const motion::Motion& content_;
  motion::FeatureClip features_;
  torch::Tensor codes_;  // (1, C) or (1, C, T).
};

absl::StatusOr<std::vector<float>> ContrastiveModel::LiveStyleParams(const StyleCode& style) const {
  if (!impl_->config.live) return absl::FailedPreconditionError("not a live package");
  if (static_cast<int>(style.values.size()) != code_size()) {
    return absl::InvalidArgumentError(absl::StrCat("style code has ", style.values.size(),
                                                   " values; this model's have ", code_size()));
  }
  try {
    c10::InferenceMode guard;
    const torch::Tensor code =
        torch::from_blob(const_cast<float*>(style.values.data()), {1, code_size()});
    const torch::Tensor p = impl_->net->live_generator->Params(code).contiguous();
    return std::vector<float>(p.data_ptr<float>(), p.data_ptr<float>() + p.numel());
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
}

LiveCarry ContrastiveModel::NewLiveCarry() const {
  return impl_->engine ? impl_->engine->NewCarry() : LiveCarry{};
}

absl::Status ContrastiveModel::StepLive(const std::vector<LiveStep>& steps) const {
  if (!impl_->engine) return absl::FailedPreconditionError("not a live package");
  for (const LiveStep& s : steps) {
    if (s.carry == nullptr || !impl_->engine->Fits(*s.carry) || s.features == nullptr ||
        s.params == nullptr || s.out == nullptr)
      return absl::InvalidArgumentError("a live step does not fit this model");
  }
  if (steps.empty()) return absl::OkStatus();
  try {
    impl_->engine->Step(steps);
  } catch (const std::exception& e) {
    return impl_->Internal(e);
  }
  return absl::OkStatus();
}

absl::Status ContrastiveModel::StepStreams(const std::vector<FrameStreamer*>& cores) const {
  std::vector<LiveStep> steps(cores.size());
  std::vector<LiveStreamer*> streams(cores.size());
  for (size_t i = 0; i < cores.size(); ++i) {
    streams[i] = dynamic_cast<LiveStreamer*>(cores[i]);
    if (streams[i] == nullptr || !streams[i]->NextStep(&steps[i])) {
      return absl::InvalidArgumentError("a stream in the batch has no live step queued");
    }
  }
  if (absl::Status s = StepLive(steps); !s.ok()) return s;
  for (LiveStreamer* s : streams) s->StepDone();
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<StyleModel::Forms>> ContrastiveModel::PrepareTransfer(
    const motion::Motion& content, const std::vector<StyleCode>& styles,
    const StyleWeights& weights, PassBatcher* batcher) const {
  const ContrastiveConfig& config = impl_->config;
  const bool per_frame = !weights.per_frame.empty();
  absl::StatusOr<motion::FeatureClip> f = NormalizedFeatures(content, "content clip");
  if (!f.ok()) return f.status();
  if (config.live) {
    torch::Tensor codes;
    try {
      c10::InferenceMode guard;
      if (per_frame) {
        codes = torch::empty({1, config.channels, f->frames});
        for (int t = 0; t < f->frames; ++t) {
          const StyleCode code = MixStyles(styles, weights.per_frame[t]);
          codes[0].select(1, t).copy_(
              torch::from_blob(const_cast<float*>(code.values.data()), {config.channels}));
        }
      } else {
        const StyleCode code = MixStyles(styles, weights.fixed);
        codes =
            torch::from_blob(const_cast<float*>(code.values.data()), {1, config.channels}).clone();
      }
    } catch (const std::exception& e) {
      return impl_->Internal(e);
    }
    return std::make_unique<LiveForms>(impl_.get(), content, *std::move(f), std::move(codes));
  }
  PadToLength(&*f, config.window);
  std::vector<int> starts = impl_->Starts(f->frames);
  std::vector<StyleCode> codes(starts.size());
  for (size_t w = 0; w < starts.size(); ++w) {
    const int centre = std::min(content.num_frames - 1, starts[w] + config.window / 2);
    const std::vector<double>& mix = per_frame ? weights.per_frame[centre] : weights.fixed;
    codes[w] = MixStyles(styles, mix);
  }
  return std::make_unique<ClipForms>(impl_.get(), content, *std::move(f), std::move(starts),
                                     std::move(codes), batcher);
}

absl::StatusOr<std::unique_ptr<FrameStreamer>> ContrastiveModel::OpenModelRateStream(
    const StreamSpec& spec) const {
  std::shared_ptr<const StyleModel> self = weak_from_this().lock();
  if (impl_->config.live) {
    absl::StatusOr<std::unique_ptr<LiveStreamer>> s = LiveStreamer::Create(
        std::static_pointer_cast<const ContrastiveModel>(std::move(self)), spec);
    if (!s.ok()) return s.status();
    return std::unique_ptr<FrameStreamer>(*std::move(s));
  }
  absl::StatusOr<std::unique_ptr<WindowStreamer>> s = WindowStreamer::Create(
      std::static_pointer_cast<const ContrastiveModel>(std::move(self)), spec);
  if (!s.ok()) return s.status();
  return std::unique_ptr<FrameStreamer>(*std::move(s));
}

absl::StatusOr<motion::Motion> ContrastiveModel::Impl::Render(
    const motion::Motion& content, const motion::FeatureClip& f, const std::vector<int>& starts,
    const std::vector<StyleCode>& codes, const Knobs& knobs, SharedPasses* shared) {
  absl::StatusOr<std::vector<float>> y = Generate(f, starts, codes, knobs, shared);
  if (!y.ok()) return y.status();
  WindowBlender blender(config.window, config.window - config.hop, f.dim);
  const size_t per_window = static_cast<size_t>(f.dim) * config.window;
  for (size_t w = 0; w < starts.size(); ++w) blender.Add(starts[w], y->data() + w * per_window);
  motion::FeatureClip out = blender.Take(content.num_frames);  // Drops the padding.
  data.norm.Denormalize(&out);
  return motion::MotionFromFeatures(out, content.skeleton, data.roles, content.frame_time,
                                    motion::RootAt(content, data.roles, 0));
}

ModelFamily ContrastiveFamily() {
  return MakeFamily<ContrastiveModel, ContrastiveConfig>("contrastive");
}

}  // namespace stylus::model
