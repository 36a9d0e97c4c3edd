// train --family cyclic.
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "tool/cli_support.h"
#include "train/cyclic_trainer.h"

namespace stylus::tool {

int TrainCyclicModel(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool train --family cyclic --data DIR... --out models/cyclic/VERSION\n"
      "         [--iters 8000] [--ae-iters 2000] [--batch 16] [--lr 5e-4] [--seed S]\n"
      "         [--window 60] [--hop 30] [--hidden 256] [--kernel 15] [--dropout 0.25]\n"
      "         [--no-cycle] [--no-kc] [--no-residual] [--kc-iters 100]\n"
      "         [--style-weight W] [--content-weight W] [--gan-weight W] [--cycle-weight W]\n"
      "         [--smooth-weight W] [--bone-weight W] [--traj-weight W] [--foot-weight W]\n"
      "         [--keep-weight 0] [--random-starts] [--mirror] [--keep-path] [--rotations]\n"
      "         [--threads N] [--checkpoint-every 500] [--log-every 50] [--commit SHA]\n"
      "         [--init-from PACKAGE] [--resume] [--guided [--class-weight 1]]\n"
      "         [--style-dim 0 [--blocks 4] [--adain-skip]] [--pair-gan]\n"
      "         [--content-class-weight 1] [--content-balance 0]\n"
      "         [--average-from K [--average-every 50]]\n\n"
      "Trains the cycle-consistent convolutional autoencoder of paper 004\n"
      "(docs/families.md) on the training split of each DIR, without labels: the\n"
      "autoencoder alone for --ae-iters, then the generator with the Gram style\n"
      "loss, content loss, adversarial loss, cycle loss (off with --no-cycle) and\n"
      "the kinematic constraints (off with --no-kc, which also turns off the\n"
      "inference-time optimization; --kc-iters caps that optimization).\n"
      "--no-residual decodes the output from the hidden features alone (the paper)\n"
      "instead of adding the decoded change to the content. Prints the\n"
      "losses, it/s and ETA; writes a checkpoint and a usable package into --out\n"
      "every --checkpoint-every iterations; --resume continues after a kill.\n"
      "--init-from starts from another package's weights (same architecture),\n"
      "e.g. with --ae-iters 0 to train only the generator stage on its autoencoder.\n"
      "--guided uses the clips' style and content labels (Bandai file names) in\n"
      "the generator stage: each content clip's style clip has another style, and\n"
      "a critic trained on real labelled windows scores the transfer against that\n"
      "style and the content's content (--class-weight). --pair-gan (with\n"
      "--guided) makes the adversarial term (--gan-weight) label-conditional;\n"
      "--content-class-weight scales the content half of the critic's verdict;\n"
      "--content-balance P (0..1) draws a content class with n\n"
      "windows in proportion to n^(1-P): 1 draws every action alike.\n"
      "--keep-weight W adds W x the L1 distance between the transfer and the\n"
      "content over the legs' joint positions, root trajectory and contacts.\n"
      "--random-starts starts each training window anywhere in its clip instead\n"
      "of on the hop grid, so the clips' last frames are trained on too.\n"
      "--mirror adds a left-right mirrored copy of every training clip (content\n"
      "labels' sides swapped: a raise of the left hand becomes one of the right).\n"
      "--keep-path makes the package's transfers keep the content's root\n"
      "trajectory and foot contacts (keep_path in config.txt).\n"
      "--style-dim D gives the generator a style network of its own: a style\n"
      "encoder mapping the style clip to D values and --blocks residual blocks\n"
      "modulated by them (default 0: the style code is the encoder features'\n"
      "mean and spread, as in v1). --init-from then copies what fits (e.g. a v1\n"
      "autoencoder). --adain-skip (with --style-dim) first gives the content's\n"
      "hidden features the style clip's per-channel mean and spread (AdaIN), so\n"
      "the content's own statistics do not pass the blocks' skip path.\n"
      "--rotations adds the joints' rotations to the network's channels, so the\n"
      "output's bone twists and head, hand and toe orientations are generated\n"
      "instead of taken from the content clip (a new network: train the\n"
      "autoencoder stage too; docs/notes/cyclic.md).\n"
      "--average-from K: the package holds the mean of the network's weights\n"
      "sampled every --average-every iterations from iteration K on.\n";
  int code = 0;
  const std::vector<std::string> weights = {
      "style-weight",  "content-weight",       "gan-weight",  "cycle-weight",
      "smooth-weight", "bone-weight",          "traj-weight", "foot-weight",
      "class-weight",  "content-class-weight", "keep-weight", "content-balance"};
  ArgSpec spec{{"family",
                "data",
                "out",
                "iters",
                "ae-iters",
                "batch",
                "lr",
                "seed",
                "window",
                "hop",
                "hidden",
                "kernel",
                "dropout",
                "kc-iters",
                "threads",
                "checkpoint-every",
                "log-every",
                "commit",
                "init-from",
                "style-dim",
                "blocks",
                "average-from",
                "average-every",
                "labels",
                "skeleton",
                "leave-out-style"},
               {"no-cycle", "no-kc", "no-residual", "resume", "guided", "pair-gan", "random-starts",
                "mirror", "keep-path", "adain-skip", "rotations"}};
  for (const std::string& w : weights) spec.options.insert(w);
  auto args = ParseOrExit("train", argv, spec, kHelp, &code);
  if (!args) return code;
  model::CyclicTrainOptions opt;
  opt.data = DataSources(*args);
  opt.data_options = DataOptions(*args);
  opt.out = args->Get("out");
  if (opt.data.empty() || opt.out.empty()) {
    std::fprintf(stderr, "stylus-tool train: --data and --out are required\n\n%s", kHelp);
    return 2;
  }
  model::CyclicConfig& c = opt.config;
  struct IntFlag {
    const char* name;
    int* value;
    int lo;
  };
  int seed = static_cast<int>(c.seed);
  opt.threads = 0;
  for (const IntFlag& f : {IntFlag{"iters", &c.iterations, 0},
                           {"ae-iters", &c.ae_iterations, 0},
                           {"batch", &c.batch, 1},
                           {"seed", &seed, 0},
                           {"window", &c.window, 2},
                           {"hop", &c.hop, 1},
                           {"hidden", &c.hidden, 1},
                           {"kernel", &c.kernel, 1},
                           {"kc-iters", &c.kc_iters, 0},
                           {"threads", &opt.threads, 0},
                           {"style-dim", &c.style_dim, 0},
                           {"blocks", &c.blocks, 1},
                           {"average-from", &c.average_from, 0},
                           {"average-every", &c.average_every, 1},
                           {"checkpoint-every", &opt.checkpoint_every, 1},
                           {"log-every", &opt.log_every, 1}}) {
    absl::StatusOr<int> v = args->GetInt(f.name, *f.value);
    if (!v.ok()) return Fail("train", v.status());
    if (*v < f.lo) {
      return Fail("train", absl::InvalidArgumentError(
                               absl::StrFormat("--%s must be at least %d", f.name, f.lo)));
    }
    *f.value = *v;
  }
  c.seed = seed;
  double* weight_fields[] = {&c.style_weight,         &c.content_weight, &c.gan_weight,
                             &c.cycle_weight,         &c.smooth_weight,  &c.bone_weight,
                             &c.traj_weight,          &c.foot_weight,    &c.class_weight,
                             &c.content_class_weight, &c.keep_weight,    &c.content_balance};
  for (size_t i = 0; i < weights.size(); ++i) {
    absl::StatusOr<double> v = args->GetDouble(weights[i], *weight_fields[i]);
    if (!v.ok() || *v < 0) {
      return Fail("train",
                  absl::InvalidArgumentError("--" + weights[i] + " must be a number >= 0"));
    }
    *weight_fields[i] = *v;
  }
  if (c.content_balance > 1) {
    return Fail("train", absl::InvalidArgumentError("--content-balance must be in [0, 1]"));
  }
  absl::StatusOr<double> lr = args->GetDouble("lr", c.lr);
  if (!lr.ok() || *lr <= 0) return Fail("train", absl::InvalidArgumentError("--lr must be > 0"));
  c.lr = *lr;
  if (c.window % 2) return Fail("train", absl::InvalidArgumentError("--window must be even"));
  if (c.kernel % 2 == 0) return Fail("train", absl::InvalidArgumentError("--kernel must be odd"));
  absl::StatusOr<double> dropout = args->GetDouble("dropout", c.dropout);
  if (!dropout.ok() || *dropout < 0 || *dropout > 0.95) {
    return Fail("train", absl::InvalidArgumentError("--dropout must be a number in [0, 0.95]"));
  }
  c.dropout = *dropout;
  c.guided = args->switches.count("guided") > 0;
  for (const char* name : {"class-weight", "content-class-weight", "content-balance"}) {
    if (args->Has(name) && !c.guided) {
      return Fail("train", absl::InvalidArgumentError(absl::StrCat("--", name, " needs --guided")));
    }
  }
  c.pair_gan = args->switches.count("pair-gan") > 0;
  c.random_starts = args->switches.count("random-starts") > 0;
  c.mirror = args->switches.count("mirror") > 0;
  c.keep_path = args->switches.count("keep-path") > 0;
  if (c.pair_gan && !c.guided) {
    return Fail("train", absl::InvalidArgumentError("--pair-gan needs --guided"));
  }
  c.use_cycle = !args->switches.count("no-cycle");
  c.use_kc = !args->switches.count("no-kc");
  c.residual = !args->switches.count("no-residual");
  c.adain_skip = args->switches.count("adain-skip") > 0;
  c.rotations = args->switches.count("rotations") > 0;
  if (c.adain_skip && c.style_dim == 0) {
    return Fail("train", absl::InvalidArgumentError("--adain-skip needs --style-dim"));
  }
  opt.resume = args->switches.count("resume") > 0;
  opt.commit = args->Get("commit");
  opt.init_from = args->Get("init-from");
  if (absl::Status s = model::TrainCyclic(opt); !s.ok()) return Fail("train", s);
  absl::PrintF("model written to %s\n", opt.out);
  return 0;
}

}  // namespace stylus::tool
