#include "model/contrastive/contrastive_config.h"

#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "model/config_text.h"

namespace stylus::model {

std::string ContrastiveConfig::Serialize() const {
  std::string s;
  auto put = [&](const char* k, const std::string& v) { AppendConfigLine(&s, k, v); };
  put("family", family);
  put("window", absl::StrCat(window));
  put("hop", absl::StrCat(hop));
  put("dim", absl::StrCat(dim));
  put("channels", absl::StrCat(channels));
  put("res_kernel", absl::StrCat(res_kernel));
  if (style_from_motion) put("style_from_motion", "1");
  if (bottleneck_channels > 0) {
    put("bottleneck_channels", absl::StrCat(bottleneck_channels));
    put("bottleneck_pool", absl::StrCat(bottleneck_pool));
  }
  if (style_filter_taps > 0) put("style_filter_taps", absl::StrCat(style_filter_taps));
  if (live) {
    put("live", "1");
    put("lookahead", absl::StrCat(lookahead));
    if (frame_residual) put("frame_residual", "1");
    if (dilation_growth > 1) put("dilation_growth", absl::StrCat(dilation_growth));
  }
  put("alpha", absl::StrCat(alpha));
  put("beta", absl::StrCat(beta));
  put("gamma", absl::StrCat(gamma));
  put("margin", absl::StrCat(margin));
  put("temperature", absl::StrCat(temperature));
  put("use_nce", use_nce ? "1" : "0");
  put("use_tri", use_tri ? "1" : "0");
  put("cross_view", cross_view ? "1" : "0");
  if (random_starts) put("random_starts", "1");
  if (mirror) put("mirror", "1");
  if (content_weight > 0) put("content_weight", absl::StrCat(content_weight));
  if (dynamics_weight > 0) put("dynamics_weight", absl::StrCat(dynamics_weight));
  if (motion_gan_weight > 0) put("motion_gan_weight", absl::StrCat(motion_gan_weight));
  if (motion_class_weight > 0) put("motion_class_weight", absl::StrCat(motion_class_weight));
  if (motion_content_weight)
    put("motion_content_weight", absl::StrCat(*motion_content_weight));
  if (paired_weight > 0) put("paired_weight", absl::StrCat(paired_weight));
  if (motion_rec_weight > 0) put("motion_rec_weight", absl::StrCat(motion_rec_weight));
  if (own_rec_weight > 0) put("own_rec_weight", absl::StrCat(own_rec_weight));
  if (teacher_weight > 0) {
    put("teacher_weight", absl::StrCat(teacher_weight));
    put("teacher", teacher);
    if (teacher_strength != 1) put("teacher_strength", absl::StrCat(teacher_strength));
  }
  if (guided) {
    put("guided", "1");
    put("class_weight", absl::StrCat(class_weight));
    put("cycle_weight", absl::StrCat(cycle_weight));
    if (content_class_weight != 1) put("content_class_weight", absl::StrCat(content_class_weight));
    if (content_balance > 0) put("content_balance", absl::StrCat(content_balance));
    if (pair_gan) put("pair_gan", "1");
  }
  if (keep_path) put("keep_path", "1");
  if (smooth_sigma > 0) put("smooth_sigma", absl::StrCat(smooth_sigma));
  if (style_strength != 1) put("style_strength", absl::StrCat(style_strength));
  if (residual) put("residual", "1");
  if (content_detail > 0) put("content_detail", absl::StrCat(content_detail));
  if (detail_sigma > 0) put("detail_sigma", absl::StrCat(detail_sigma));
  AppendGuardKeys(*this, &s);
  AppendMovementKeys(*this, &s);
  if (average_from > 0) {
    put("average_from", absl::StrCat(average_from));
    put("average_every", absl::StrCat(average_every));
  }
  put("batch", absl::StrCat(batch));
  put("lr", absl::StrCat(lr));
  put("iterations", absl::StrCat(iterations));
  put("seed", absl::StrCat(seed));
  put("trained_iterations", absl::StrCat(trained_iterations));
  put("data", data);
  put("commit", commit);
  return s;
}

absl::StatusOr<ContrastiveConfig> ContrastiveConfig::Parse(const std::string& text,
                                                           const std::string& source) {
  ContrastiveConfig c;
  absl::Status parsed = ParseConfigText(text, source, [&c](const ConfigEntry& e) -> absl::Status {
    const std::string& key = e.key;
    if (key == "family") {
      if (e.value != "contrastive")
        return e.Error("family must be 'contrastive', found '" + e.value + "'");
      return absl::OkStatus();
    }
    if (key == "window") {
      absl::Status s = e.Int(&c.window, 4, 4096);
      if (s.ok() && c.window % 2) s = e.Error("window must be even");
      return s;
    }
    if (key == "hop") return e.Int(&c.hop, 1, 4096);
    if (key == "dim") return e.Int(&c.dim, 1, 100000);
    if (key == "channels") return e.Int(&c.channels, 1, 4096);
    if (key == "res_kernel") {
      absl::Status s = e.Int(&c.res_kernel, 1, 31);
      if (s.ok() && c.res_kernel % 2 == 0) s = e.Error("res_kernel must be odd");
      return s;
    }
    if (key == "live") return e.Bool(&c.live);
    if (key == "style_from_motion") return e.Bool(&c.style_from_motion);
    if (key == "bottleneck_channels") return e.Int(&c.bottleneck_channels, 0, 4096);
    if (key == "bottleneck_pool") return e.Int(&c.bottleneck_pool, 1, 64);
    if (key == "style_filter_taps") {
      absl::Status s = e.Int(&c.style_filter_taps, 0, 31);
      if (s.ok() && c.style_filter_taps > 0 && c.style_filter_taps % 2 == 0)
        s = e.Error("style_filter_taps must be odd (or 0: off)");
      return s;
    }
    if (key == "lookahead") return e.Int(&c.lookahead, 1, 8);
    if (key == "frame_residual") return e.Bool(&c.frame_residual);
    if (key == "dilation_growth") return e.Int(&c.dilation_growth, 1, 4);
    if (key == "alpha") return e.Double(&c.alpha, 0, 1e6);
    if (key == "beta") return e.Double(&c.beta, 0, 1e6);
    if (key == "gamma") return e.Double(&c.gamma, 0, 1e6);
    if (key == "content_weight") return e.Double(&c.content_weight, 0, 1e6);
    if (key == "dynamics_weight") return e.Double(&c.dynamics_weight, 0, 1e6);
    if (key == "motion_gan_weight") return e.Double(&c.motion_gan_weight, 0, 1e6);
    if (key == "motion_class_weight") return e.Double(&c.motion_class_weight, 0, 1e6);
    if (key == "motion_content_weight") {
      double w = 0;
      absl::Status s = e.Double(&w, 0, 1e6);
      if (s.ok()) c.motion_content_weight = w;
      return s;
    }
    if (key == "paired_weight") return e.Double(&c.paired_weight, 0, 1e6);
    if (key == "motion_rec_weight") return e.Double(&c.motion_rec_weight, 0, 1e6);
    if (key == "own_rec_weight") return e.Double(&c.own_rec_weight, 0, 1e6);
    if (key == "teacher_weight") return e.Double(&c.teacher_weight, 0, 1e6);
    if (key == "teacher_strength") return e.Double(&c.teacher_strength, 0, 1);
    if (key == "teacher") {
      c.teacher = e.value;
      return absl::OkStatus();
    }
    if (key == "guided") return e.Bool(&c.guided);
    if (key == "keep_path") return e.Bool(&c.keep_path);
    if (key == "pair_gan") return e.Bool(&c.pair_gan);
    if (key == "smooth_sigma") return e.Double(&c.smooth_sigma, 0, 100);
    if (key == "style_strength") return e.Double(&c.style_strength, 0, 1);
    if (key == "residual") return e.Bool(&c.residual);
    if (key == "content_detail") return e.Double(&c.content_detail, 0, 1);
    if (key == "detail_sigma") return e.Double(&c.detail_sigma, 0, 100);
    if (std::optional<absl::Status> s = ParseGuardKey(e, &c)) return *s;
    if (std::optional<absl::Status> s = ParseMovementKey(e, &c)) return *s;
    if (key == "class_weight") return e.Double(&c.class_weight, 0, 1e6);
    if (key == "cycle_weight") return e.Double(&c.cycle_weight, 0, 1e6);
    if (key == "content_class_weight") return e.Double(&c.content_class_weight, 0, 1e6);
    if (key == "content_balance") return e.Double(&c.content_balance, 0, 1);
    if (key == "average_from") return e.Int(&c.average_from, 0, 100000000);
    if (key == "average_every") return e.Int(&c.average_every, 1, 100000000);
    if (key == "margin") return e.Double(&c.margin, 0, 1e6);
    if (key == "temperature") return e.Double(&c.temperature, 1e-6, 1e6);
    if (key == "use_nce") return e.Bool(&c.use_nce);
    if (key == "use_tri") return e.Bool(&c.use_tri);
    if (key == "cross_view") return e.Bool(&c.cross_view);
    if (std::optional<absl::Status> s =
            RefuseRemovedKey(e, {"local_style", "keep_amplitude", "replicate_pad",
                                 "full_rate_content", "centred_style", "self_rec_weight",
                                 "pair_offset_weight", "content_body", "critics"}))
      return *s;
    if (key == "random_starts") return e.Bool(&c.random_starts);
    if (key == "mirror") return e.Bool(&c.mirror);
    if (std::optional<absl::Status> s = ParseTrainingKey(
            e,
            {&c.batch, &c.lr, &c.iterations, &c.trained_iterations, &c.seed, &c.data, &c.commit}))
      return *s;
    return e.Error("unknown key '" + key + "'");
  });
  if (!parsed.ok()) return parsed;
  if (c.dim <= 0) return absl::InvalidArgumentError(source + ": missing 'dim'");
  if (c.content_detail > 0 && c.residual) {
    return absl::InvalidArgumentError(
        source +
        ": 'content_detail' cannot be used with 'residual' (its output already is the "
        "content window plus a change)");
  }
  if (c.frame_residual && !c.live) {
    return absl::InvalidArgumentError(source +
                                      ": 'frame_residual' is for live packages (live = 1)");
  }
  if (c.dilation_growth > 1 && !c.live) {
    return absl::InvalidArgumentError(source +
                                      ": 'dilation_growth' is for live packages (live = 1)");
  }
  if (c.bottleneck_channels > 0 && c.live) {
    return absl::InvalidArgumentError(
        source + ": 'bottleneck_channels' is for offline packages (not with live = 1)");
  }
  if (c.style_filter_taps > 0 && c.live) {
    return absl::InvalidArgumentError(
        source + ": 'style_filter_taps' is for offline packages (not with live = 1)");
  }
  if (c.bottleneck_pool > 1 && c.bottleneck_channels == 0) {
    return absl::InvalidArgumentError(source +
                                      ": 'bottleneck_pool' needs 'bottleneck_channels' above 0");
  }
  if (c.live) {
    const char* whole_window = c.smooth_sigma > 0     ? "smooth_sigma"
                               : c.residual           ? "residual"
                               : c.content_detail > 0 ? "content_detail"
                               : c.content_guard      ? "content_guard"
                                                      : nullptr;
    if (whole_window != nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": '", whole_window,
                       "' needs whole windows of frames; a live package (live = 1) has none"));
    }
  }
  if (c.content_detail > 0 && c.DetailSigma() <= 0) {
    return absl::InvalidArgumentError(
        source + ": 'content_detail' needs 'detail_sigma' or 'smooth_sigma' above 0");
  }
  return c;
}

const std::vector<std::string>& ContrastiveConfig::InferenceKeys() {
  static const std::vector<std::string>* keys = [] {
    auto* k = new std::vector<std::string>{"keep_path", "smooth_sigma",   "style_strength",
                                           "residual",  "content_detail", "detail_sigma"};
    k->insert(k->end(), GuardKeyNames().begin(), GuardKeyNames().end());
    k->insert(k->end(), MovementKeyNames().begin(), MovementKeyNames().end());
    return k;
  }();
  return *keys;
}

absl::StatusOr<ContrastiveConfig> ContrastiveConfig::Read(const std::string& dir,
                                                          const std::string& overrides) {
  return ReadConfig<ContrastiveConfig>(dir, overrides);
}

}  // namespace stylus::model
