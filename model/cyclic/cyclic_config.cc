#include "model/cyclic/cyclic_config.h"

#include "absl/strings/str_cat.h"
#include "model/config_text.h"

namespace stylus::model {

std::string CyclicConfig::Serialize() const {
  std::string s;
  auto put = [&](const char* k, const std::string& v) { AppendConfigLine(&s, k, v); };
  auto num = [&](const char* k, double v) { put(k, absl::StrCat(v)); };
  put("family", family);
  num("window", window);
  num("hop", hop);
  num("dim", dim);
  num("hidden", hidden);
  num("kernel", kernel);
  num("dropout", dropout);
  num("rec_weight", rec_weight);
  num("style_weight", style_weight);
  num("content_weight", content_weight);
  num("gan_weight", gan_weight);
  num("cycle_weight", cycle_weight);
  num("smooth_weight", smooth_weight);
  num("bone_weight", bone_weight);
  num("traj_weight", traj_weight);
  num("foot_weight", foot_weight);
  if (keep_weight > 0) num("keep_weight", keep_weight);
  put("residual", residual ? "1" : "0");
  if (style_dim > 0) {
    num("style_dim", style_dim);
    num("blocks", blocks);
    if (adain_skip) put("adain_skip", "1");
  }
  if (rotations) put("rotations", "1");
  if (random_starts) put("random_starts", "1");
  if (mirror) put("mirror", "1");
  if (keep_path) put("keep_path", "1");
  AppendGuardKeys(*this, &s);
  AppendMovementKeys(*this, &s);
  put("use_cycle", use_cycle ? "1" : "0");
  put("use_kc", use_kc ? "1" : "0");
  if (guided) {
    put("guided", "1");
    num("class_weight", class_weight);
    if (pair_gan) put("pair_gan", "1");
    if (content_class_weight != 1) num("content_class_weight", content_class_weight);
    if (content_balance > 0) num("content_balance", content_balance);
  }
  num("kc_iters", kc_iters);
  num("kc_lr", kc_lr);
  num("ae_iterations", ae_iterations);
  if (average_from > 0) {
    num("average_from", average_from);
    num("average_every", average_every);
  }
  num("batch", batch);
  num("lr", lr);
  num("iterations", iterations);
  put("seed", absl::StrCat(seed));
  num("trained_iterations", trained_iterations);
  put("data", data);
  put("commit", commit);
  return s;
}

absl::StatusOr<CyclicConfig> CyclicConfig::Parse(const std::string& text,
                                                 const std::string& source) {
  CyclicConfig c;
  c.residual = false;  // Packages from before the key existed decode the output alone.
  absl::Status parsed = ParseConfigText(text, source, [&c](const ConfigEntry& e) -> absl::Status {
    const std::string& key = e.key;
    if (key == "family") {
      if (e.value != "cyclic") return e.Error("family must be 'cyclic', found '" + e.value + "'");
      return absl::OkStatus();
    }
    if (key == "window" || key == "hop") {
      absl::Status s = e.Int(key == "window" ? &c.window : &c.hop, 2, 4096);
      if (s.ok() && c.window % 2) s = e.Error("window must be even");
      return s;
    }
    if (key == "dim") return e.Int(&c.dim, 1, 100000);
    if (key == "hidden") return e.Int(&c.hidden, 1, 4096);
    if (key == "kernel") {
      absl::Status s = e.Int(&c.kernel, 1, 63);
      if (s.ok() && c.kernel % 2 == 0) s = e.Error("kernel must be odd");
      return s;
    }
    if (key == "dropout") return e.Double(&c.dropout, 0, 0.95);
    if (key == "style_dim") return e.Int(&c.style_dim, 0, 4096);
    if (key == "blocks") return e.Int(&c.blocks, 1, 16);
    struct Weight {
      const char* name;
      double* value;
    };
    for (const Weight& w : {Weight{"rec_weight", &c.rec_weight},
                            {"style_weight", &c.style_weight},
                            {"content_weight", &c.content_weight},
                            {"gan_weight", &c.gan_weight},
                            {"cycle_weight", &c.cycle_weight},
                            {"smooth_weight", &c.smooth_weight},
                            {"bone_weight", &c.bone_weight},
                            {"traj_weight", &c.traj_weight},
                            {"foot_weight", &c.foot_weight},
                            {"keep_weight", &c.keep_weight}}) {
      if (key == w.name) return e.Double(w.value, 0, 1e6);
    }
    if (key == "use_cycle") return e.Bool(&c.use_cycle);
    if (key == "random_starts") return e.Bool(&c.random_starts);
    if (key == "mirror") return e.Bool(&c.mirror);
    if (key == "keep_path") return e.Bool(&c.keep_path);
    if (key == "residual") return e.Bool(&c.residual);
    if (key == "adain_skip") return e.Bool(&c.adain_skip);
    if (key == "rotations") return e.Bool(&c.rotations);
    if (std::optional<absl::Status> s = ParseGuardKey(e, &c)) return *s;
    if (std::optional<absl::Status> s = ParseMovementKey(e, &c)) return *s;
    if (key == "use_kc") return e.Bool(&c.use_kc);
    if (key == "guided") return e.Bool(&c.guided);
    if (key == "class_weight") return e.Double(&c.class_weight, 0, 1e6);
    if (key == "pair_gan") return e.Bool(&c.pair_gan);
    if (key == "content_class_weight") return e.Double(&c.content_class_weight, 0, 1e6);
    if (std::optional<absl::Status> s = RefuseRemovedKey(e, {"critics"})) return *s;
    if (key == "content_balance") return e.Double(&c.content_balance, 0, 1);
    if (key == "kc_iters") return e.Int(&c.kc_iters, 0, 100000);
    if (key == "kc_lr") return e.Double(&c.kc_lr, 0, 10);
    if (key == "ae_iterations") return e.Int(&c.ae_iterations, 0, 1 << 30);
    if (key == "average_from") return e.Int(&c.average_from, 0, 1 << 30);
    if (key == "average_every") return e.Int(&c.average_every, 1, 1 << 30);
    if (std::optional<absl::Status> s = ParseTrainingKey(
            e,
            {&c.batch, &c.lr, &c.iterations, &c.trained_iterations, &c.seed, &c.data, &c.commit}))
      return *s;
    return e.Error("unknown key '" + key + "'");
  });
  if (!parsed.ok()) return parsed;
  if (c.dim <= 0) return absl::InvalidArgumentError(source + ": missing 'dim'");
  if (c.adain_skip && c.style_dim == 0) {
    return absl::InvalidArgumentError(source +
                                      ": 'adain_skip' needs a style network ('style_dim')");
  }
  return c;
}

const std::vector<std::string>& CyclicConfig::InferenceKeys() {
  static const std::vector<std::string>* keys = [] {
    auto* k = new std::vector<std::string>{"keep_path", "kc_iters", "kc_lr", "use_kc"};
    k->insert(k->end(), GuardKeyNames().begin(), GuardKeyNames().end());
    k->insert(k->end(), MovementKeyNames().begin(), MovementKeyNames().end());
    return k;
  }();
  return *keys;
}

absl::StatusOr<CyclicConfig> CyclicConfig::Read(const std::string& dir,
                                                const std::string& overrides) {
  return ReadConfig<CyclicConfig>(dir, overrides);
}

}  // namespace stylus::model
