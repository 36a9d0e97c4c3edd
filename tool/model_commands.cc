// train and transfer.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "formats/scene_file.h"
#include "model/package.h"
#include "model/runtime.h"
#include "model/style_model.h"
#include "motion/bvh.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"
#include "train/contrastive_trainer.h"

namespace stylus::tool {

int Train(const Argv& argv) {
  for (size_t i = 0; i < argv.size(); ++i) {
    if ((argv[i] == "--family" && i + 1 < argv.size() && argv[i + 1] == "cyclic") ||
        argv[i] == "--family=cyclic") {
      return TrainCyclicModel(argv);
    }
  }
  static const char kHelp[] =
      "usage: stylus-tool train --family contrastive --data DIR... --out "
      "models/contrastive/VERSION\n"
      "         [--iters N] [--batch 16] [--lr 1e-4] [--alpha A] [--beta B] [--gamma C]\n"
      "         [--no-nce] [--no-tri] [--same-view] [--style-from-motion] [--seed S] [--resume]\n"
      "         [--random-starts] [--mirror] [--residual] [--channels 144]\n"
      "         [--bottleneck-channels K [--bottleneck-pool 1]] [--style-filter-taps K]\n"
      "         [--content-weight W] [--dynamics-weight W] [--smooth-sigma S] [--threads N]\n"
      "         [--teacher PACKAGE [--teacher-weight 1] [--teacher-strength 1]]\n"
      "         [--guided [--class-weight 1] [--cycle-weight 1] [--pair-gan]\n"
      "          [--content-class-weight 1] [--content-balance 0]\n"
      "          [--motion-gan-weight W] [--motion-class-weight W [--motion-content-weight W]]\n"
      "          [--paired-weight W] [--motion-rec-weight W] [--own-rec-weight W]]\n"
      "         [--keep-path] [--average-from K [--average-every 50]]\n"
      "         [--live [--lookahead 2] [--frame-residual] [--dilation-growth 1]]\n"
      "         [--window 32] [--hop 24]\n"
      "         [--init-from PACKAGE] [--checkpoint-every 500] [--log-every 50] [--commit SHA]\n\n"
      "Trains a style-transfer model on the training split of each DIR (or on\n"
      ".bvh files given directly), by default without using any label. Prints the losses,\n"
      "it/s and ETA; every --checkpoint-every iterations writes a checkpoint and a\n"
      "usable package (config.txt, norm.txt, skeleton.bvh, weights.pt, loss.csv)\n"
      "into --out. --resume continues from that checkpoint after a kill.\n"
      "--same-view takes each window's style code from the window itself (the\n"
      "paper); by default it comes from another window of the same clip\n"
      "(docs/families.md).\n"
      "--style-from-motion feeds the style encoder each feature's change from\n"
      "frame to frame instead of the features: style codes say how the body\n"
      "moves, not how it is posed.\n"
      "--smooth-sigma S stores the inference smoothing of generated windows\n"
      "(smooth_sigma in config.txt; the shipped default model uses 3; 0: off).\n"
      "--random-starts starts each content window anywhere in its clip instead\n"
      "of on the hop grid, so the clips' last frames are trained on too.\n"
      "--mirror adds a left-right mirrored copy of every training clip (content\n"
      "labels' sides swapped: a raise of the left hand becomes one of the right).\n"
      "--content-weight W adds W x the L1 distance between the transfer and its\n"
      "content input over the root trajectory, foot contacts and legs (default 0:\n"
      "off).\n"
      "--dynamics-weight W adds W x the L1 distance between Gram matrices of the\n"
      "transfer's joint velocities and accelerations and a real window's of the\n"
      "target style (with --guided: doing the content's action when the data has\n"
      "it), so the style shows in how the body moves, not only in its pose\n"
      "(default 0: off).\n"
      "--teacher PACKAGE distils an offline contrastive package (trained on the\n"
      "same data): --teacher-weight W x the L1 distance between each transfer's\n"
      "pose and the teacher's transfer of the same windows (its content guard,\n"
      "which reads whole clips, is not applied). For live packages, which then\n"
      "learn frame by frame what a model that sees whole windows does.\n"
      "--teacher-strength K (0..1) distils the teacher's weaker form, the one its\n"
      "content guard backs off to: the content plus K x the change the style makes.\n"
      "--guided trains with the clips' style and content labels (from the Bandai\n"
      "file names): the reconstruction takes its style code from a clip of the\n"
      "same style doing something else, the transfer from a clip of another\n"
      "style, and a critic trained on real labelled windows scores each transfer\n"
      "against the target style and the content input's content (--class-weight),\n"
      "plus a cycle back to the content's own style (--cycle-weight);\n"
      "--content-class-weight scales the content half of that verdict.\n"

      "--content-balance P (0..1) draws a content class with n windows in\n"
      "proportion to n^(1-P): 1 draws every action alike, 0 (default) every window.\n"
      "--pair-gan (with --guided) conditions the discriminator (--alpha) on the\n"
      "(style, content) label pair; it also rejects the unchanged content and the\n"
      "style clip itself under the transfer's labels.\n"
      "--motion-gan-weight W and --motion-class-weight W (with --guided) add critics\n"
      "that read only how the body moves (the joints' velocities and accelerations\n"
      "as --dynamics-weight computes them): a label-conditional discriminator, and\n"
      "a style and content classifier trained on real windows, whose verdicts on\n"
      "each transfer weigh W (default 0: off). --motion-content-weight W scales the\n"
      "content half of the motion classifier's verdict (default: as\n"
      "--content-class-weight scales the pose critic's).\n"
      "--paired-weight W (with --guided) adds W x the L1 distance between each\n"
      "transfer and a real clip of the content's action in the target style (where\n"
      "the data has one), at the window whose content code is nearest the content\n"
      "window's: the pose and how it moves, all but the root path (default 0: off).\n"
      "--motion-rec-weight W (with --guided) adds W x the L1 distance between the\n"
      "frame-to-frame changes of the pose in the reconstruction and the cycle and\n"
      "those of the content window: the generator gives back how a clip moves, not\n"
      "only its poses (default 0: off).\n"
      "--own-rec-weight W (with --guided) adds W x the L1 distance, on the\n"
      "features and on their frame-to-frame changes, between each content window\n"
      "and its rendering with its own style code (default 0: off).\n"
      "--channels N sets the width of the encoders, the generator and the codes\n"
      "(a new network: it cannot start from a package of another width).\n"
      "--bottleneck-channels K squeezes the content code through K channels\n"
      "(instance-normalized), averaged over --bottleneck-pool P of its steps: a\n"
      "code that says what is done and when, and less of how (a new network;\n"
      "offline packages only; default 0: off).\n"
      "--style-filter-taps K (odd) filters each generator channel over time with\n"
      "K weights the style code chooses, so a style can delay, smooth or sharpen\n"
      "a joint's motion, not only scale it (offline packages only; default 0:\n"
      "off). With --init-from a package without it, the filter starts as none.\n"
      "Measured: it moves the raw output's steps, not the motion-only judge.\n"

      "--residual trains each transfer as the content window plus the change the\n"
      "style makes in the generator's output, G(Ec(x), s) - G(Ec(x), Es(x)), and\n"
      "the package transfers in that form (residual in config.txt).\n"
      "--keep-path makes the package's transfers keep the content's root\n"
      "trajectory and foot contacts (stored as keep_path in config.txt).\n"
      "--average-from K: the package holds the mean of the generator's weights\n"
      "sampled every --average-every iterations from iteration K on (weight\n"
      "averaging; steadier than the last iteration's weights).\n"
      "--live trains a live package (docs/families.md \"Live packages\"): causal\n"
      "networks that stream one frame per step, each output frame final once\n"
      "--lookahead (1 to 8) more input frames have arrived. --frame-residual makes\n"
      "its generator give the change to each content frame. --dilation-growth G\n"
      "dilates residual block b's convolutions by G^b (networks that see further\n"
      "back at the same cost per frame; train them on longer windows).\n"
      "--window / --hop set the training windows (frames); a live package's\n"
      "network sees about 30 frames of history, so it trains on 64-frame windows.\n"
      "--init-from PACKAGE starts the networks from a trained package of the\n"
      "same shape (fine-tuning; critics and optimizers start afresh).\n"
      "For the cyclic family's options: stylus-tool train --family cyclic --help\n\n"
      "Data: --data takes folders and .bvh files on any humanoid rig. Clips on\n"
      "another rig than the package's are retargeted onto it (docs/rigs.md), other\n"
      "frame rates resampled; a clip that cannot be used is skipped and listed.\n"
      "The package's skeleton is the first clip's, or --skeleton PACKAGE_DIR|FILE.bvh.\n"
      "Labels (for --guided; the contrastive method itself needs none) come from\n"
      "Bandai names (dataset-N_{content}_{style}_{take}.bvh) or --labels FILE.csv\n"
      "(clip,content,style; clip paths relative to the CSV).\n"
      "--leave-out-style STYLE (repeatable) leaves every clip of that style out of\n"
      "training, to measure how the package does on a style it has never seen.\n";
  int code = 0;
  auto args =
      ParseOrExit("train", argv,
                  {{"family",
                    "data",
                    "out",
                    "iters",
                    "batch",
                    "lr",
                    "alpha",
                    "beta",
                    "gamma",
                    "seed",
                    "threads",
                    "checkpoint-every",
                    "log-every",
                    "commit",
                    "content-weight",
                    "dynamics-weight",
                    "motion-gan-weight",
                    "motion-class-weight",
                    "motion-content-weight",
                    "paired-weight",
                    "motion-rec-weight",
                    "own-rec-weight",
                    "smooth-sigma",
                    "class-weight",
                    "cycle-weight",
                    "content-class-weight",
                    "content-balance",
                    "init-from",
                    "average-from",
                    "average-every",
                    "channels",
                    "bottleneck-channels",
                    "bottleneck-pool",
                    "style-filter-taps",
                    "lookahead",
                    "dilation-growth",
                    "window",
                    "hop",
                    "labels",
                    "skeleton",
                    "leave-out-style",
                    "teacher",
                    "teacher-weight",
                    "teacher-strength"},
                   {"no-nce", "no-tri", "same-view", "resume", "guided", "keep-path", "pair-gan",
                    "random-starts", "mirror", "residual", "live", "frame-residual",
                    "style-from-motion"}},
                  kHelp, &code);
  if (!args) return code;
  if (args->Get("family", "contrastive") != "contrastive") {
    return Fail("train",
                absl::InvalidArgumentError("--family: families are 'contrastive' and 'cyclic'"));
  }
  model::ContrastiveTrainOptions opt;
  opt.data = DataSources(*args);
  opt.data_options = DataOptions(*args);
  opt.out = args->Get("out");
  if (opt.data.empty() || opt.out.empty()) {
    std::fprintf(stderr, "stylus-tool train: --data and --out are required\n\n%s", kHelp);
    return 2;
  }
  model::ContrastiveConfig& c = opt.config;
  absl::StatusOr<int> iters = args->GetInt("iters", c.iterations),
                      batch = args->GetInt("batch", c.batch);
  absl::StatusOr<int> seed = args->GetInt("seed", static_cast<int>(c.seed)),
                      threads = args->GetInt("threads", 0);
  absl::StatusOr<int> ckpt = args->GetInt("checkpoint-every", 500),
                      log_every = args->GetInt("log-every", 50);
  absl::StatusOr<double> lr = args->GetDouble("lr", c.lr),
                         alpha = args->GetDouble("alpha", c.alpha);
  absl::StatusOr<double> beta = args->GetDouble("beta", c.beta),
                         gamma = args->GetDouble("gamma", c.gamma);
  for (const absl::Status& s :
       {iters.status(), batch.status(), seed.status(), threads.status(), ckpt.status(),
        log_every.status(), lr.status(), alpha.status(), beta.status(), gamma.status()}) {
    if (!s.ok()) return Fail("train", s);
  }
  c.iterations = *iters, c.batch = *batch, c.seed = *seed, c.lr = *lr, c.alpha = *alpha,
  c.beta = *beta, c.gamma = *gamma;
  c.use_nce = !args->switches.count("no-nce");
  c.use_tri = !args->switches.count("no-tri");
  c.cross_view = !args->switches.count("same-view");
  c.style_from_motion = args->switches.count("style-from-motion") > 0;
  c.random_starts = args->switches.count("random-starts") > 0;
  c.mirror = args->switches.count("mirror") > 0;
  c.residual = args->switches.count("residual") > 0;
  absl::StatusOr<double> content_weight = args->GetDouble("content-weight", 0);
  if (!content_weight.ok() || *content_weight < 0) {
    return Fail("train", absl::InvalidArgumentError("--content-weight must be a number >= 0"));
  }
  c.content_weight = *content_weight;
  absl::StatusOr<double> dynamics_weight = args->GetDouble("dynamics-weight", 0);
  if (!dynamics_weight.ok() || *dynamics_weight < 0) {
    return Fail("train", absl::InvalidArgumentError("--dynamics-weight must be a number >= 0"));
  }
  c.dynamics_weight = *dynamics_weight;
  c.teacher = args->Get("teacher");
  absl::StatusOr<double> teacher_weight =
      args->GetDouble("teacher-weight", c.teacher.empty() ? 0 : 1);
  if (!teacher_weight.ok() || *teacher_weight < 0) {
    return Fail("train", absl::InvalidArgumentError("--teacher-weight must be a number >= 0"));
  }
  if (args->Has("teacher-weight") && c.teacher.empty()) {
    return Fail("train", absl::InvalidArgumentError("--teacher-weight needs --teacher"));
  }
  c.teacher_weight = c.teacher.empty() ? 0 : *teacher_weight;
  absl::StatusOr<double> teacher_strength = args->GetDouble("teacher-strength", 1);
  if (!teacher_strength.ok() || *teacher_strength < 0 || *teacher_strength > 1) {
    return Fail("train",
                absl::InvalidArgumentError("--teacher-strength must be a number in [0, 1]"));
  }
  if (args->Has("teacher-strength") && c.teacher.empty()) {
    return Fail("train", absl::InvalidArgumentError("--teacher-strength needs --teacher"));
  }
  c.teacher_strength = *teacher_strength;
  if (c.teacher_weight == 0) c.teacher.clear();
  absl::StatusOr<double> smooth_sigma = args->GetDouble("smooth-sigma", 0);
  if (!smooth_sigma.ok() || *smooth_sigma < 0 || *smooth_sigma > 100) {
    return Fail("train", absl::InvalidArgumentError("--smooth-sigma must be a number in [0, 100]"));
  }
  c.smooth_sigma = *smooth_sigma;
  c.guided = args->switches.count("guided") > 0;
  c.keep_path = args->switches.count("keep-path") > 0;
  c.pair_gan = args->switches.count("pair-gan") > 0;
  if (c.pair_gan && !c.guided) {
    return Fail("train", absl::InvalidArgumentError("--pair-gan needs --guided"));
  }
  for (auto [name, field] : {std::pair<const char*, double*>{"class-weight", &c.class_weight},
                             {"cycle-weight", &c.cycle_weight},
                             {"content-class-weight", &c.content_class_weight},
                             {"content-balance", &c.content_balance},
                             {"motion-gan-weight", &c.motion_gan_weight},
                             {"motion-class-weight", &c.motion_class_weight},
                             {"paired-weight", &c.paired_weight},
                             {"motion-rec-weight", &c.motion_rec_weight},
                             {"own-rec-weight", &c.own_rec_weight}}) {
    if (!args->Has(name)) continue;
    absl::StatusOr<double> w = args->GetDouble(name, *field);
    if (!c.guided) {
      return Fail("train", absl::InvalidArgumentError(absl::StrCat("--", name, " needs --guided")));
    }
    if (!w.ok() || *w < 0) {
      return Fail("train",
                  absl::InvalidArgumentError(absl::StrCat("--", name, " must be a number >= 0")));
    }
    if (field == &c.content_balance && *w > 1) {
      return Fail("train", absl::InvalidArgumentError("--content-balance must be in [0, 1]"));
    }
    *field = *w;
  }
  if (args->Has("motion-content-weight")) {
    absl::StatusOr<double> w = args->GetDouble("motion-content-weight", 0);
    if (c.motion_class_weight <= 0) {
      return Fail("train", absl::InvalidArgumentError(
                               "--motion-content-weight needs --motion-class-weight"));
    }
    if (!w.ok() || *w < 0) {
      return Fail("train",
                  absl::InvalidArgumentError("--motion-content-weight must be a number >= 0"));
    }
    c.motion_content_weight = *w;
  }
  absl::StatusOr<int> average_from = args->GetInt("average-from", 0),
                      average_every = args->GetInt("average-every", c.average_every);
  if (!average_from.ok() || *average_from < 0) {
    return Fail("train", absl::InvalidArgumentError("--average-from must be a number >= 0"));
  }
  if (!average_every.ok() || *average_every < 1) {
    return Fail("train", absl::InvalidArgumentError("--average-every must be a number >= 1"));
  }
  c.average_from = *average_from, c.average_every = *average_every;
  absl::StatusOr<int> channels = args->GetInt("channels", c.channels);
  if (!channels.ok() || *channels < 1 || *channels > 4096) {
    return Fail("train", absl::InvalidArgumentError("--channels must be a number in [1, 4096]"));
  }
  c.channels = *channels;
  absl::StatusOr<int> bottleneck = args->GetInt("bottleneck-channels", 0),
                      pool = args->GetInt("bottleneck-pool", 1);
  if (!bottleneck.ok() || *bottleneck < 0 || *bottleneck > c.channels) {
    return Fail("train", absl::InvalidArgumentError(
                             "--bottleneck-channels must be a number in [0, --channels]"));
  }
  if (!pool.ok() || *pool < 1 || *pool > 64) {
    return Fail("train", absl::InvalidArgumentError("--bottleneck-pool must be a number in [1, 64]"));
  }
  if (args->Has("bottleneck-pool") && *bottleneck == 0) {
    return Fail("train", absl::InvalidArgumentError("--bottleneck-pool needs --bottleneck-channels"));
  }
  c.bottleneck_channels = *bottleneck, c.bottleneck_pool = *pool;
  absl::StatusOr<int> taps = args->GetInt("style-filter-taps", 0);
  if (!taps.ok() || *taps < 0 || *taps > 31 || (*taps > 0 && *taps % 2 == 0)) {
    return Fail("train", absl::InvalidArgumentError(
                             "--style-filter-taps must be an odd number in [1, 31] (or 0: off)"));
  }
  c.style_filter_taps = *taps;
  c.live = args->switches.count("live") > 0;
  if (c.live && (c.bottleneck_channels > 0 || c.style_filter_taps > 0)) {
    return Fail("train", absl::InvalidArgumentError(
                             c.bottleneck_channels > 0
                                 ? "--bottleneck-channels is for offline packages, not with --live"
                                 : "--style-filter-taps is for offline packages, not with --live"));
  }
  if (c.live) c.window = 64, c.hop = 32;
  absl::StatusOr<int> lookahead = args->GetInt("lookahead", c.lookahead),
                      window = args->GetInt("window", c.window), hop = args->GetInt("hop", c.hop);
  if (args->Has("lookahead") && !c.live) {
    return Fail("train", absl::InvalidArgumentError("--lookahead needs --live"));
  }
  if (!lookahead.ok() || *lookahead < 1 || *lookahead > 8) {
    return Fail("train", absl::InvalidArgumentError("--lookahead must be from 1 to 8"));
  }
  if (!window.ok() || *window < 4 || *window > 4096 || *window % 2) {
    return Fail("train",
                absl::InvalidArgumentError("--window must be an even number in [4, 4096]"));
  }
  if (!hop.ok() || *hop < 1 || *hop > *window) {
    return Fail("train", absl::InvalidArgumentError("--hop must be a number in [1, --window]"));
  }
  c.lookahead = *lookahead, c.window = *window, c.hop = *hop;
  c.frame_residual = args->switches.count("frame-residual") > 0;
  absl::StatusOr<int> growth = args->GetInt("dilation-growth", 1);
  if (args->Has("dilation-growth") && !c.live) {
    return Fail("train", absl::InvalidArgumentError("--dilation-growth needs --live"));
  }
  if (!growth.ok() || *growth < 1 || *growth > 4) {
    return Fail("train", absl::InvalidArgumentError("--dilation-growth must be 1, 2, 3 or 4"));
  }
  c.dilation_growth = *growth;
  if (c.frame_residual && !c.live) {
    return Fail("train", absl::InvalidArgumentError("--frame-residual needs --live"));
  }
  if (c.live && c.smooth_sigma > 0) {
    return Fail("train", absl::InvalidArgumentError(
                             "--smooth-sigma needs whole windows; a live package has none"));
  }
  if (c.live && c.residual) {
    return Fail("train", absl::InvalidArgumentError(
                             "--residual needs whole windows; a live package has none"));
  }
  opt.threads = *threads;
  opt.checkpoint_every = *ckpt;
  opt.log_every = *log_every;
  opt.resume = args->switches.count("resume") > 0;
  opt.init_from = args->Get("init-from");
  opt.commit = args->Get("commit");
  if (absl::Status s = model::TrainContrastive(opt); !s.ok()) return Fail("train", s);
  absl::PrintF("model written to %s\n", opt.out);
  return 0;
}

namespace {

std::string Stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

// " (content guard: ...)" when the model's content guard backed the transfer off.
std::string GuardNote(const model::TransferNote& note) {
  if (!note.backed_off) return "";
  return absl::StrFormat(
      " (content guard: the configured transfer read as another action than the content's; "
      "returned instead: the content plus %g x the change the style makes%s%s; docs/families.md "
      "\"The content guard\")",
      note.residual_strength, note.residual_strength == 0 ? ", i.e. no style" : "",
      note.last_form ? ", the last form" : "");
}

// " (style timing: ...)" for a transfer asked for the style's timing.
std::string WarpNote(const model::TransferOptions& options, const model::TimeWarpNote& warp,
                     int content_frames, int frames) {
  if (options.timing != model::Timing::kStyle && options.fit_frames == 0) return "";
  if (!warp.applied) return absl::StrCat(" (style timing not applied: ", warp.reason, ")");
  if (warp.style_period_s <= 0) {
    return absl::StrFormat(" (played %.2fx as long: %d frames -> %d)", warp.ratio, content_frames,
                           frames);
  }
  return absl::StrFormat(
      " (style timing: cadence %.2f s -> %.2f s, played %.2fx as long: %d frames -> %d)",
      warp.content_period_s, warp.style_period_s, warp.ratio, content_frames, frames);
}

// " (movement: ...)" for a package whose movement comes from examples.
std::string MovementText(const model::StyleModel& m, const model::MovementNote& note) {
  if (!m.moves_from_examples()) return "";
  if (!note.applied) return absl::StrCat(" (movement: the network's; ", note.reason, ")");
  return absl::StrFormat(" (movement: %s from %s, fit %.3f, played %.2fx)", note.kind, note.example,
                         note.cost, note.rate);
}

// Transfers one pair and writes it; `note` gets GuardNote's, WarpNote's and
// MovementText's text.
absl::Status TransferOne(const model::StyleModel& m, const std::string& content_path,
                         const std::string& style_path, const std::string& out_path,
                         const model::TransferOptions& options, bool stream,
                         const std::string& animation, std::string* note) {
  const motion::JointMap& joint_map = options.joint_map;
  formats::ReadOptions read;
  read.animation = animation;
  absl::StatusOr<motion::Motion> content = formats::ReadMotionFile(content_path, read);
  if (!content.ok()) return content.status();
  absl::StatusOr<motion::Motion> style = formats::ReadMotionFile(style_path, read);
  if (!style.ok()) return style.status();
  // The joint map names the content's rig; a style clip on that rig uses it too.
  absl::StatusOr<model::StyleCode> code = m.EncodeStyle(
      *style, style->skeleton.SameTopology(content->skeleton) ? joint_map : motion::JointMap{});
  if (!code.ok())
    return absl::Status(code.status().code(),
                        absl::StrCat(style_path, ": ", code.status().message()));
  if (stream) {
    absl::StatusOr<motion::Motion> streamed =
        model::StreamClip(m, *content, *code, options.post, options.movement);
    if (!streamed.ok())
      return absl::Status(streamed.status().code(),
                          absl::StrCat(content_path, ": ", streamed.status().message()));
    *note = " (through a stream)";
    return formats::WriteMotionFile(*streamed, out_path, {content_path});
  }
  absl::StatusOr<model::TransferResult> out = m.Transfer(*content, *code, options);
  if (!out.ok())
    return absl::Status(out.status().code(),
                        absl::StrCat(content_path, ": ", out.status().message()));
  *note = GuardNote(out->note) +
          WarpNote(options, out->warp, content->num_frames, out->motion.num_frames) +
          MovementText(m, out->movement);
  return formats::WriteMotionFile(out->motion, out_path, {content_path});
}

}  // namespace

int Transfer(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool transfer --model DIR --content C.bvh --style S.bvh -o OUT.bvh\n"
      "       stylus-tool transfer --model DIR --pairs PAIRS.csv --out-dir DIR\n\n"
      "Gives the content clip the style of the style clip and writes the result as\n"
      "BVH on the content's skeleton. The batch form loads the model once and\n"
      "transfers every row of PAIRS.csv (columns content_bvh,style_bvh; a header\n"
      "line is allowed) into DIR/<content>__<style>.bvh; a failed row is reported\n"
      "and the others still run (exit 1 if any failed). --threads N sets the\n"
      "compute threads (default: one per core). --postprocess none|feet|full\n"
      "(default full): feet locked where the content's feet are planted, bone\n"
      "lengths restored, rotations smoothed and written continuously.\n\n"
      "Clips on another humanoid rig than the model's (other joint names, rest\n"
      "pose, units, up axis, extra joints) are retargeted onto the model's\n"
      "skeleton and the result back onto the content's rig: same joints, offsets\n"
      "and channels as the input (stylus-tool rig-info shows the mapping).\n"
      "--joint-map FILE fixes roles the finder gets wrong or cannot find\n"
      "(lines like 'left_foot = MyFootL'; docs/rigs.md).\n\n"
      "--timing content|style (default content): with style, the output takes the\n"
      "style's pace, so it is longer or shorter than the content (0.5-2x): with a\n"
      "package whose movement comes from examples (the default), the content's\n"
      "path at the example's speed and a gesture in the example's time; else the\n"
      "style clip's cadence by a uniform time warp (the note gives both\n"
      "cadences). A clip whose motion does not repeat has no cadence: the\n"
      "content's timing is kept and the note says so. --fit-frames N asks for\n"
      "exactly N frames (0.5-2x the content's).\n\n"
      "--style-library DIR [--style-library-labels CSV]: with a package whose\n"
      "movement comes from examples (movement = examples), the takes under DIR\n"
      "(BVH, any rig; labels from dataset-N_{action}_{style}_{take}.bvh names or\n"
      "the CSV's clip,action,style rows) compete with the style clip to give the\n"
      "output's legs, pelvis and arms their movement; --style-label NAME says\n"
      "which of the library's styles is wanted (default: the nearest to the\n"
      "style clip's code). The printed note says which example moved it\n"
      "(docs/movement.md).\n\n"
      "--stream plays the content through a stream, one frame per push as a stage\n"
      "sends it, and writes what the stream returns (a live package: its causal\n"
      "network and its movement from examples within the look-ahead; the stream's\n"
      "own post-processing; --timing and --fit-frames do not apply).\n\n"
      "Clips may be BVH, FBX, glTF (.gltf, .glb) or COLLADA (.dae) files\n"
      "(--animation NAME picks one of several in a file); -o's extension (.bvh,\n"
      ".gltf, .glb) picks the output's format, and a glTF of an FBX or glTF\n"
      "content keeps its meshes and skins (docs/pipelines.md).\n\n"
      "--shard-count N [--shard-index I] runs only rows I, I+N, I+2N, ... (rows\n"
      "counted from 0, header excluded), so N workers share a library; I defaults\n"
      "to $JOB_COMPLETION_INDEX, which a Kubernetes Indexed Job sets\n"
      "(deploy/k8s/jobs/transfer-library.yaml).\n";
  int code = 0;
  auto args = ParseOrExit("transfer", argv,
                          {{"model", "content", "style", "out", "pairs", "out-dir", "threads",
                            "postprocess", "shard-count", "shard-index", "joint-map", "timing",
                            "style-library", "style-library-labels", "style-label", "fit-frames",
                            "animation"},
                           {"stream"}},
                          kHelp, &code);
  if (!args) return code;
  const bool batch = args->Has("pairs");
  if (!args->Has("model") ||
      (batch ? !args->Has("out-dir")
             : (!args->Has("content") || !args->Has("style") || !args->Has("out")))) {
    std::fprintf(stderr, "stylus-tool transfer: missing arguments\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<int> threads = args->GetInt("threads", 0);
  if (!threads.ok()) return Fail("transfer", threads.status());
  model::SetComputeThreads(*threads);
  absl::StatusOr<motion::PostProcessMode> post =
      motion::ParsePostProcessMode(args->Get("postprocess", "full"));
  if (!post.ok()) return Fail("transfer", post.status());
  motion::JointMap joint_map;
  if (args->Has("joint-map")) {
    absl::StatusOr<motion::JointMap> map = motion::ReadJointMapFile(args->Get("joint-map"));
    if (!map.ok()) return Fail("transfer", map.status());
    joint_map = *std::move(map);
  }
  model::TransferOptions options(*post);
  options.joint_map = joint_map;
  const std::string timing = args->Get("timing", "content");
  if (timing != "content" && timing != "style") {
    return Fail("transfer", absl::InvalidArgumentError(
                                absl::StrCat("--timing must be content or style, not '", timing, "'")));
  }
  options.timing = timing == "style" ? model::Timing::kStyle : model::Timing::kContent;
  if (args->Has("fit-frames")) {
    absl::StatusOr<int> fit = args->GetInt("fit-frames", 0);
    if (!fit.ok()) return Fail("transfer", fit.status());
    if (*fit < 2) {
      return Fail("transfer", absl::InvalidArgumentError("--fit-frames wants 2 frames or more"));
    }
    options.fit_frames = *fit;
  }
  std::unique_ptr<model::StyleLibrary> library;
  if (args->Has("style-library")) {
    absl::StatusOr<std::unique_ptr<model::StyleLibrary>> lib =
        model::StyleLibrary::Load(args->Get("style-library"), args->Get("style-library-labels"));
    if (!lib.ok()) return Fail("transfer", lib.status());
    library = *std::move(lib);
    for (const std::string& s : library->skipped()) {
      std::fprintf(stderr, "stylus-tool transfer: style library: skipped %s\n", s.c_str());
    }
    options.movement.library = library.get();
    options.movement.style_label = args->Get("style-label");
    const std::vector<std::string> styles = library->Styles();
    if (!options.movement.style_label.empty() &&
        std::find(styles.begin(), styles.end(), options.movement.style_label) == styles.end()) {
      return Fail("transfer", absl::InvalidArgumentError(
                                  absl::StrCat("--style-label ", options.movement.style_label,
                                               ": the library has no take of that style (it has ",
                                               absl::StrJoin(styles, ", "), ")")));
    }
  } else if (args->Has("style-label") || args->Has("style-library-labels")) {
    return Fail("transfer", absl::InvalidArgumentError(
                                "--style-label and --style-library-labels need --style-library"));
  }
  absl::StatusOr<std::unique_ptr<model::StyleModel>> loaded = LoadModelSpec(args->Get("model"));
  if (!loaded.ok()) return Fail("transfer", loaded.status());
  const std::shared_ptr<model::StyleModel> model = *std::move(loaded);  // Streams hold it.
  const bool stream = args->switches.count("stream") > 0;
  if (stream && (options.timing == model::Timing::kStyle || options.fit_frames > 0)) {
    return Fail("transfer", absl::InvalidArgumentError(
                                "--stream keeps the content's timing: drop --timing style and "
                                "--fit-frames"));
  }
  if (!batch) {
    absl::StatusOr<formats::FileFormat> out_format = formats::FormatOfPath(args->Get("out"));
    if (out_format.ok() && !formats::CanWrite(*out_format)) {
      out_format = absl::InvalidArgumentError(absl::StrCat(
          "-o ", args->Get("out"), ": stylus-tool writes ", formats::WritableFormats()));
    }
    if (!out_format.ok()) return Fail("transfer", out_format.status());
    std::string note;
    if (absl::Status s = TransferOne(*model, args->Get("content"), args->Get("style"),
                                     args->Get("out"), options, stream, args->Get("animation"),
                                     &note);
        !s.ok()) {
      return Fail("transfer", s);
    }
    absl::PrintF("wrote %s%s\n", args->Get("out"), note);
    return 0;
  }
  absl::StatusOr<int> shards = args->GetInt("shard-count", 1);
  if (!shards.ok()) return Fail("transfer", shards.status());
  const char* job_index = std::getenv("JOB_COMPLETION_INDEX");
  int env_index = 0;
  if (job_index != nullptr && !absl::SimpleAtoi(job_index, &env_index)) env_index = -1;
  absl::StatusOr<int> shard = args->GetInt("shard-index", env_index);
  if (!shard.ok()) return Fail("transfer", shard.status());
  if (*shards < 1 || *shard < 0 || *shard >= *shards) {
    return Fail("transfer",
                absl::InvalidArgumentError(absl::StrCat("--shard-index ", *shard,
                                                        " (or $JOB_COMPLETION_INDEX) must be "
                                                        "from 0 to --shard-count - 1 = ",
                                                        *shards - 1)));
  }
  std::ifstream csv(args->Get("pairs"));
  if (!csv) return Fail("transfer", absl::NotFoundError(args->Get("pairs") + ": cannot open"));
  std::filesystem::create_directories(args->Get("out-dir"));
  std::string line;
  int line_no = 0, row = -1, ok = 0, failed = 0;
  while (std::getline(csv, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || (line_no == 1 && line.rfind("content_bvh", 0) == 0)) continue;
    if (++row % *shards != *shard) continue;  // Another shard's row.
    std::vector<std::string> cols = absl::StrSplit(line, ',');
    if (cols.size() != 2) {
      std::fprintf(stderr, "%s:%d: expected content_bvh,style_bvh\n", args->Get("pairs").c_str(),
                   line_no);
      ++failed;
      continue;
    }
    const std::string out =
        absl::StrCat(args->Get("out-dir"), "/", Stem(cols[0]), "__", Stem(cols[1]), ".bvh");
    std::string note;
    if (absl::Status s = TransferOne(*model, cols[0], cols[1], out, options, stream, args->Get("animation"), &note);
        !s.ok()) {
      std::fprintf(stderr, "%s:%d: %s\n", args->Get("pairs").c_str(), line_no,
                   std::string(s.message()).c_str());
      ++failed;
      continue;
    }
    absl::PrintF("wrote %s%s\n", out, note);
    ++ok;
  }
  if (*shards > 1) absl::PrintF("shard %d of %d: ", *shard, *shards);
  absl::PrintF("%d transferred, %d failed\n", ok, failed);
  return failed ? 1 : 0;
}

int RigInfo(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool rig-info FILE [--model DIR] [--joint-map FILE]\n\n"
      "Shows how a BVH file's rig maps onto a model's skeleton: the joint found\n"
      "for each humanoid role and how (joint map, name, hierarchy, geometry, End\n"
      "Site), the up axis, and the scale (model units per rig unit). Exits 1\n"
      "naming the roles it cannot find. --model defaults to the package models/DEFAULT\n"
      "names (run from the repository or the image's /opt/stylus).\n"
      "Known naming conventions: docs/rigs.md.\n";
  int code = 0;
  auto args =
      ParseOrExit("rig-info", argv, {{"model", "joint-map", "animation"}, {}}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 1) {
    std::fprintf(stderr, "stylus-tool rig-info: expected one FILE\n\n%s", kHelp);
    return 2;
  }
  formats::ReadOptions read;
  read.animation = args->Get("animation");
  absl::StatusOr<motion::Motion> clip = formats::ReadMotionFile(args->positional[0], read);
  if (!clip.ok()) return Fail("rig-info", clip.status());
  if (clip->num_frames == 0) {
    return Fail("rig-info", absl::InvalidArgumentError(args->positional[0] + ": no frames"));
  }
  motion::JointMap joint_map;
  if (args->Has("joint-map")) {
    absl::StatusOr<motion::JointMap> map = motion::ReadJointMapFile(args->Get("joint-map"));
    if (!map.ok()) return Fail("rig-info", map.status());
    joint_map = *std::move(map);
  }
  std::string model_spec = args->Get("model", "");
  if (model_spec.empty()) {
    absl::StatusOr<std::string> default_package = model::ReadDefaultPackage("models");
    if (!default_package.ok()) return Fail("rig-info", default_package.status());
    if (default_package->empty()) {
      return Fail("rig-info",
                  absl::InvalidArgumentError(
                      "no models/DEFAULT here to name the default model: give --model"));
    }
    model_spec = "models/" + *default_package;
  }
  absl::StatusOr<std::unique_ptr<model::StyleModel>> m = LoadModelSpec(model_spec);
  if (!m.ok()) return Fail("rig-info", m.status());
  absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
      (*m)->RetargeterFor(*clip, joint_map, args->positional[0]);
  if (!r.ok()) return Fail("rig-info", r.status());
  absl::PrintF("file: %s (%d joints)\nmodel: %s\n", args->positional[0],
               clip->skeleton.num_joints(), (*m)->dir());
  if (clip->skeleton.SameTopology((*m)->data().skeleton)) {
    absl::PrintF("the model's own rig: clips go in as they are\n");
  }
  absl::PrintF("%-16s %-32s %s\n", "role", "joint", "found by");
  absl::PrintF("%s", motion::DescribeRigRoles(clip->skeleton, (*r)->roles()));
  absl::PrintF("scale: %.6g model units per rig unit\n", (*r)->scale());
  int unmapped = 0;
  for (int j = 0; j < clip->skeleton.num_joints(); ++j) {
    bool mapped = false;
    for (int k : (*r)->roles().joint) mapped |= k == j;
    unmapped += !mapped;
  }
  absl::PrintF("joints without a role (keep their input motion): %d\n", unmapped);
  return 0;
}

}  // namespace stylus::tool
