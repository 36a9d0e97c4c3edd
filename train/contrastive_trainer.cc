#include "train/contrastive_trainer.h"

#include <torch/torch.h>

#include <algorithm>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "model/contrastive/contrastive_net.h"
#include "model/guard_net.h"
#include "model/package.h"
#include "model/runtime.h"
#include "model/weights_io.h"
#include "motion/files.h"
#include "train/clip_classes.h"
#include "train/dynamics_style.h"
#include "train/label_critic.h"
#include "train/pair_discriminator.h"
#include "train/paired_target.h"
#include "train/teacher.h"
#include "train/torch_files.h"
#include "train/training_run.h"
#include "train/training_set.h"
#include "train/weight_average.h"

namespace stylus::model {
namespace {

// --init-from: loads the package in `dir` into a network of its own
// configuration and copies its tensors into `net` by name (CopyTensorsByName);
// tensors only `net` has (a style filter the package lacks) start afresh.
// INVALID_ARGUMENT naming the package and the tensor when one of its tensors
// has another shape or no place in `net`.
absl::Status LoadInitWeights(const std::string& dir, ContrastiveNet& net,
                             const std::function<void(const std::string&)>& log) {
  absl::StatusOr<ContrastiveConfig> theirs = ContrastiveConfig::Read(dir);
  if (!theirs.ok()) return theirs.status();
  ContrastiveNet from(*theirs);
  if (absl::Status s = LoadWeights(from, dir + "/weights.pt"); !s.ok()) return s;
  const std::string source = "--init-from " + dir;
  absl::StatusOr<TensorCopy> copy = CopyTensorsByName(from, net, source);
  if (!copy.ok()) return copy.status();
  if (!copy->unplaced.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": its '", copy->unplaced[0], "' has no place in this network"));
  }
  if (copy->copied < copy->total) {
    LogLine(log, absl::StrCat("initialized ", copy->copied, " of ", copy->total, " tensors from ",
                              dir, "; the rest start afresh"));
  }
  return absl::OkStatus();
}

struct Trainer {
  explicit Trainer(const ContrastiveTrainOptions& options) : opt(options), config(options.config) {}

  const ContrastiveTrainOptions& opt;
  ContrastiveConfig config;
  TrainingSet data;
  ContrastiveNet net{nullptr};
  WeightAverage<ContrastiveNet> average;  // With config.average_from.
  Discriminator disc{nullptr};
  std::unique_ptr<torch::optim::Adam> opt_g, opt_d;
  // Label-guided training only.
  ClipClasses classes;
  LabelCritic critic;
  PairGan pair_gan;                // With `pair_gan` only.
  torch::Tensor content_mask;      // (1, dim, 1): channels of the content-keeping term.
  torch::Tensor pose_mask;         // (1, dim, 1): every channel but the root path's.
  DynamicsStyle dynamics;          // With dynamics_weight or a motion critic.
  PairGan motion_gan;              // With motion_gan_weight: reads dynamics.
  LabelCritic motion_critic;       // With motion_class_weight: reads dynamics.
  Teacher teacher;                 // With teacher_weight.
  std::mt19937_64* rng = nullptr;  // The run's (checkpointed with it).

  void Log(const std::string& s) const { LogLine(opt.log, s); }

  torch::Tensor ToTensor(std::vector<float>* buf) const {
    return torch::from_blob(buf->data(), {config.batch, config.dim, config.window}, torch::kFloat32)
        .clone();
  }

  // A batch of windows and, with cross_view, a second window of the same clip
  // for each (its style view); without, the same windows.
  std::pair<torch::Tensor, torch::Tensor> Batch() {
    std::vector<float> buf;
    std::vector<int> clips;
    data.SampleBatch(config.batch, config.window, rng, &buf, &clips);
    torch::Tensor x = ToTensor(&buf);
    if (!config.cross_view) return {x, x};
    data.SampleFromClips(clips, config.window, rng, &buf);
    return {x, ToTensor(&buf)};
  }

  // L1 distance of a transfer to its content input over content_mask.
  torch::Tensor ContentKeeping(const torch::Tensor& transfer, const torch::Tensor& content) const {
    return MaskedL1Loss(transfer, content, content_mask);
  }

  // The transfer of content windows `x` (content codes `c`) to style code
  // `s`. With config.residual (the form inference then uses): x plus the
  // change the style makes in the generator's output, G(c, s) - G(c, Es(x));
  // `own`, if given, is Es(x) already computed. Otherwise G(c, s).
  torch::Tensor Transfer(const torch::Tensor& x, const torch::Tensor& c, const torch::Tensor& s,
                         const torch::Tensor* own = nullptr) {
    const torch::Tensor g = net->render(x, c, s);
    if (!config.residual) return g;
    return x + g - net->decode(c, own ? *own : net->style(x));
  }

  // teacher_weight x the distance of the transfer `x_g` to the teacher's
  // transfer of content windows `x` to style windows `style` (recorded in `r`).
  torch::Tensor Distillation(const torch::Tensor& x_g, const torch::Tensor& x,
                             const torch::Tensor& style, LossRecord* r) const {
    const torch::Tensor d = Teacher::PoseL1(x_g, teacher.Transfer(x, style));
    r->teach = d.item<double>();
    return config.teacher_weight * d;
  }

  // One discriminator step on `real` vs the detached `fake`; returns the
  // generator's adversarial loss on `fake` (both recorded in `r`).
  torch::Tensor Adversarial(const torch::Tensor& real, const torch::Tensor& fake, LossRecord* r) {
    opt_d->zero_grad();
    const torch::Tensor d_loss =
        DiscriminatorGanLoss(disc->forward(real), disc->forward(fake.detach()));
    d_loss.backward();
    opt_d->step();
    r->disc = d_loss.item<double>();
    const torch::Tensor gan = GeneratorGanLoss(disc->forward(fake));
    r->gan = gan.item<double>();
    return gan;
  }

  // One step of the label-conditional discriminator (config.pair_gan): real
  // for the content and style windows with their own labels; fake for the
  // transfer, and for the content window (identity) and the style window
  // (copy-style) under the transfer's label pair (target style, content's
  // content). Returns the generator's adversarial loss on the transfer.
  torch::Tensor PairAdversarial(const torch::Tensor& x, const torch::Tensor& x_style,
                                const torch::Tensor& x_content, const torch::Tensor& y,
                                const torch::Tensor& y_style, const torch::Tensor& y_content,
                                const torch::Tensor& fake, LossRecord* r) {
    const torch::Tensor gan =
        pair_gan.Step(x, x_style, x_content, y, y_style, y_content, fake, &r->disc);
    r->gan = gan.item<double>();
    return gan;
  }

  // The terms of the critics that read only dynamics (motion_gan_weight,
  // motion_class_weight): each learns on real windows (the content x and the
  // style window y under their own labels), then judges the transfer x_g
  // under (target style, x's content).
  torch::Tensor MotionCritics(const torch::Tensor& x, const torch::Tensor& x_style,
                              const torch::Tensor& x_content, const torch::Tensor& y,
                              const torch::Tensor& y_style, const torch::Tensor& y_content,
                              const torch::Tensor& x_g, LossRecord* r) {
    const torch::Tensor m_x = dynamics.Stacked(x), m_y = dynamics.Stacked(y);
    const torch::Tensor m_g = dynamics.Stacked(x_g);
    torch::Tensor total = torch::zeros({});
    if (config.motion_gan_weight > 0) {
      const torch::Tensor gan =
          motion_gan.Step(m_x, x_style, x_content, m_y, y_style, y_content, m_g, &r->mdisc);
      r->mgan = gan.item<double>();
      total = total + config.motion_gan_weight * gan;
    }
    if (config.motion_class_weight > 0) {
      r->mcritic = motion_critic.Learn({{m_x, x_style, x_content}, {m_y, y_style, y_content}});
      const torch::Tensor cls =
          motion_critic.Verdict(m_g, y_style, x_content, config.MotionContentWeight());
      r->mcls = cls.item<double>();
      total = total + config.motion_class_weight * cls;
    }
    return total;
  }

  // The L1 distance between the frame-to-frame changes (FrameChanges) of
  // the pose channels of `output` and of `target`.
  torch::Tensor MotionReconstructionLoss(const torch::Tensor& output,
                                         const torch::Tensor& target) const {
    return MaskedL1Loss(FrameChanges(output), FrameChanges(target), pose_mask);
  }

  LossRecord Step() {
    const auto [x_t, v_t] = Batch();
    const auto [x_s, v_s] = Batch();
    const torch::Tensor c_t = net->content(x_t), s_t = net->style(v_t);
    const torch::Tensor c_s = net->content(x_s), s_s = net->style(v_s);
    const torch::Tensor rec = (ReconstructionLoss(net->render(x_t, c_t, s_t), x_t) +
                               ReconstructionLoss(net->render(x_s, c_s, s_s), x_s)) /
                              2;
    const torch::Tensor x_g = Transfer(x_t, c_t, s_s);
    LossRecord r;
    torch::Tensor total = rec;
    if (config.alpha > 0) total = total + config.alpha * Adversarial(x_s, x_g, &r);
    if (config.content_weight > 0) total = total + config.content_weight * ContentKeeping(x_g, x_t);
    if (teacher.on()) total = total + Distillation(x_g, x_t, x_s, &r);
    if (config.dynamics_weight > 0) {
      const torch::Tensor dyn = dynamics.Loss(x_g, x_s);
      r.dyn = dyn.item<double>();
      total = total + config.dynamics_weight * dyn;
    }
    if (config.use_nce && config.beta > 0) {
      const torch::Tensor nce = NceLoss(net->content(x_g), c_t, net->nce_w, config.temperature);
      r.nce = nce.item<double>();
      total = total + config.beta * nce;
    }
    if (config.use_tri && config.gamma > 0) {
      // Positive: the style clip's code from its own window (the other view
      // already fed G), so the pair is two views of one clip.
      const torch::Tensor tri = TripletLoss(
          net->style(x_g), config.cross_view ? net->style(x_s) : s_s, s_t, config.margin);
      r.tri = tri.item<double>();
      total = total + config.gamma * tri;
    }
    opt_g->zero_grad();
    total.backward();
    opt_g->step();
    r.rec = rec.item<double>();
    r.total = total.item<double>();
    return r;
  }

  // Label-guided step (docs/notes/contrastive.md): content windows x; for each, a
  // window of a clip of the same style doing something else (the
  // reconstruction's style) and one of a clip of another style (the
  // transfer's style, and the discriminator's real sample).
  LossRecord GuidedStep() {
    std::vector<float> buf;
    std::vector<int> clips;
    data.SampleBatch(config.batch, config.window, rng, &buf, &clips);
    const torch::Tensor x = ToTensor(&buf);
    std::vector<int> same, other;
    for (int c : clips) same.push_back(classes.SameStyle(c, rng));
    for (int c : clips) other.push_back(classes.OtherStyle(c, rng));
    data.SampleFromClips(same, config.window, rng, &buf);
    const torch::Tensor y_same = ToTensor(&buf);
    data.SampleFromClips(other, config.window, rng, &buf);
    const torch::Tensor y_other = ToTensor(&buf);
    const torch::Tensor x_style = LabelTensor(clips, classes.style_of),
                        x_content = LabelTensor(clips, classes.content_of);
    const torch::Tensor target_style = LabelTensor(other, classes.style_of),
                        other_content = LabelTensor(other, classes.content_of);
    LossRecord r;
    // The critic learns the labels of real windows, never of transfers.
    r.critic = critic.Learn({{x, x_style, x_content}, {y_other, target_style, other_content}});

    const torch::Tensor c_x = net->content(x);
    const torch::Tensor s_same = net->style(y_same), s_other = net->style(y_other);
    const torch::Tensor x_rec = net->render(x, c_x, s_same);
    const torch::Tensor rec = ReconstructionLoss(x_rec, x);
    const torch::Tensor s_x = net->style(x);
    const torch::Tensor x_g = Transfer(x, c_x, s_other, &s_x);
    torch::Tensor total = rec;
    if (config.alpha > 0) {
      const torch::Tensor adv = config.pair_gan
                                    ? PairAdversarial(x, x_style, x_content, y_other, target_style,
                                                      other_content, x_g, &r)
                                    : Adversarial(y_other, x_g, &r);
      total = total + config.alpha * adv;
    }
    if (config.content_weight > 0) total = total + config.content_weight * ContentKeeping(x_g, x);
    if (teacher.on()) total = total + Distillation(x_g, x, y_other, &r);
    if (config.dynamics_weight > 0) {
      // The reference: the content's action in the target style where the
      // data has it (the same motion done that way), else the style window.
      std::vector<int> match;
      for (size_t i = 0; i < clips.size(); ++i) {
        const int m = classes.SameContentInStyle(clips[i], classes.style_of[other[i]], rng);
        match.push_back(m >= 0 ? m : other[i]);
      }
      data.SampleFromClips(match, config.window, rng, &buf);
      const torch::Tensor dyn = dynamics.Loss(x_g, ToTensor(&buf));
      r.dyn = dyn.item<double>();
      total = total + config.dynamics_weight * dyn;
    }
    if (config.motion_gan_weight > 0 || config.motion_class_weight > 0)
      total = total + MotionCritics(x, x_style, x_content, y_other, target_style, other_content,
                                    x_g, &r);
    if (config.paired_weight > 0) {
      // The content's action performed in the target style, where the data
      // has it (train/paired_target.h).
      std::vector<int> examples;
      for (size_t i = 0; i < clips.size(); ++i)
        examples.push_back(classes.SameContentInStyle(clips[i], classes.style_of[other[i]], rng));
      const PairedTargets targets = FindPairedTargets(net, data, examples, c_x, config.window);
      const torch::Tensor pair = PairedLoss(x_g, targets, pose_mask);
      r.pair = pair.item<double>();
      total = total + config.paired_weight * pair;
    }
    const torch::Tensor cls =
        critic.Verdict(x_g, target_style, x_content, config.content_class_weight);
    r.cls = cls.item<double>();
    total = total + config.class_weight * cls;
    const torch::Tensor c_g = net->content(x_g);
    const torch::Tensor x_cyc = net->render(x_g, c_g, s_same);
    const torch::Tensor cyc = ReconstructionLoss(x_cyc, x);
    r.cyc = cyc.item<double>();
    total = total + config.cycle_weight * cyc;
    if (config.motion_rec_weight > 0) {
      const torch::Tensor mrec = MotionReconstructionLoss(x_rec, x) +
                                 config.cycle_weight * MotionReconstructionLoss(x_cyc, x);
      r.mrec = mrec.item<double>();
      total = total + config.motion_rec_weight * mrec;
    }
    if (config.own_rec_weight > 0) {
      const torch::Tensor x_own = net->render(x, c_x, s_x);
      const torch::Tensor own = ReconstructionLoss(x_own, x) + MotionReconstructionLoss(x_own, x);
      r.own = own.item<double>();
      total = total + config.own_rec_weight * own;
    }
    if (config.use_nce && config.beta > 0) {
      const torch::Tensor nce = NceLoss(c_g, c_x, net->nce_w, config.temperature);
      r.nce = nce.item<double>();
      total = total + config.beta * nce;
    }
    if (config.use_tri && config.gamma > 0) {
      const torch::Tensor tri = TripletLoss(net->style(x_g), s_other, s_x, config.margin);
      r.tri = tri.item<double>();
      total = total + config.gamma * tri;
    }
    opt_g->zero_grad();
    total.backward();
    opt_g->step();
    r.rec = rec.item<double>();
    r.total = total.item<double>();
    return r;
  }

  absl::Status WritePackage(int iterations, const std::string& csv) {
    ContrastiveConfig c = config;
    c.trained_iterations = iterations;
    return WriteTrainedPackage(opt.out, c.Serialize(), data,
                               Tensors("weights.pt", average.ForPackage(iterations, &net)), csv);
  }

  // Every channel but the root path's (the paired term's).
  torch::Tensor PoseMask() const {
    torch::Tensor mask = torch::ones({1, config.dim, 1});
    mask.slice(1, motion::FeatureLayout(data.skeleton.num_joints()).trajectory()).zero_();
    return mask;
  }

  torch::Tensor ContentMask() const {
    const motion::Skeleton& sk = data.skeleton;
    const motion::FeatureLayout layout(sk.num_joints());
    torch::Tensor mask = torch::zeros({1, config.dim, 1});
    const std::vector<bool> leg = motion::LegJoints(sk, data.roles);
    for (int j = 0; j < sk.num_joints(); ++j) {
      if (!leg[j]) continue;
      for (int c = 0; c < 3; ++c) mask[0][layout.position(j) + c][0] = 1;
      for (int c = 0; c < 4; ++c) mask[0][layout.rotation(j) + c][0] = 1;
    }
    for (int c = 0; c < motion::FeatureLayout::kPathChannels; ++c)
      mask[0][layout.trajectory() + c][0] = 1;
    return mask;
  }

  absl::Status Run() {
    SetComputeThreads(opt.threads);
    absl::StatusOr<TrainingSet> loaded = LoadRunData(opt, &config);
    if (!loaded.ok()) return loaded.status();
    data = *std::move(loaded);
    content_mask = ContentMask();
    pose_mask = PoseMask();
    if ((config.paired_weight > 0 || config.motion_rec_weight > 0 || config.own_rec_weight > 0) &&
        !config.guided) {
      return absl::InvalidArgumentError(
          "paired_weight, motion_rec_weight and own_rec_weight need label-guided training "
          "(--guided)");
    }
    const bool motion_critics = config.motion_gan_weight > 0 || config.motion_class_weight > 0;
    if (motion_critics && !config.guided) {
      return absl::InvalidArgumentError(
          "motion_gan_weight and motion_class_weight need label-guided training (--guided)");
    }
    if (config.dynamics_weight > 0 || motion_critics) dynamics = DynamicsStyle(data);
    if (motion_critics && !dynamics.on()) {
      return absl::InvalidArgumentError(
          "the motion critics need training clips of at least 3 frames");
    }
    if (config.teacher_weight > 0) {
      absl::StatusOr<Teacher> t =
          Teacher::Load(config.teacher, config.dim, data.norm, config.teacher_strength);
      if (!t.ok()) return t.status();
      teacher = *std::move(t);
      Log("distilling from " + config.teacher);
    }
    if (config.guided) {
      absl::StatusOr<ClipClasses> c =
          GuidedClasses(&data, config.window, config.content_balance, opt.log);
      if (!c.ok()) return c.status();
      classes = *std::move(c);
    }
    if (config.average_from > 0)  // Before the seed (see WeightAverage).
      average = WeightAverage<ContrastiveNet>(config.average_from, config.average_every,
                                              ContrastiveNet(config));
    torch::manual_seed(config.seed);
    net = ContrastiveNet(config);
    if (!opt.init_from.empty() && !opt.resume) {
      // Fine-tuning: the networks start from a trained package's weights
      // (shapes checked); the critics and optimizers start afresh. Weights
      // learned on other normalization statistics would see other inputs.
      absl::StatusOr<motion::NormStats> norm = motion::NormStats::Load(opt.init_from + "/norm.txt");
      if (!norm.ok()) {
        return absl::Status(norm.status().code(),
                            absl::StrCat("--init-from: ", norm.status().message()));
      }
      if (norm->Serialize() != data.norm.Serialize()) {
        return absl::FailedPreconditionError(
            absl::StrCat("--init-from ", opt.init_from,
                         ": its norm.txt differs from this data's statistics (trained on other "
                         "data); fine-tune on the data it was trained on"));
      }
      if (absl::Status s = LoadInitWeights(opt.init_from, net, opt.log); !s.ok()) return s;
      Log("initialized from " + opt.init_from);
    }
    disc = Discriminator(config);
    if (config.guided) {
      critic = LabelCritic(config.dim, static_cast<int>(classes.styles.size()),
                           static_cast<int>(classes.contents.size()));
    }
    if (config.motion_gan_weight > 0) {
      motion_gan = PairGan(2 * dynamics.channels(), static_cast<int>(classes.styles.size()),
                           static_cast<int>(classes.contents.size()), config.lr);
    }
    if (config.motion_class_weight > 0) {
      motion_critic = LabelCritic(2 * dynamics.channels(), static_cast<int>(classes.styles.size()),
                                  static_cast<int>(classes.contents.size()));
    }
    if (config.pair_gan) {
      pair_gan = PairGan(config.dim, static_cast<int>(classes.styles.size()),
                         static_cast<int>(classes.contents.size()), config.lr);
    }
    opt_g = std::make_unique<torch::optim::Adam>(
        net->parameters(), torch::optim::AdamOptions(config.lr).betas({0.5, 0.999}));
    opt_d = std::make_unique<torch::optim::Adam>(
        disc->parameters(), torch::optim::AdamOptions(config.lr).betas({0.5, 0.999}));
    TrainingRun::Spec spec;
    spec.out = opt.out;
    spec.loss_names = {"rec", "gan", "nce", "tri", "disc"};
    if (config.guided) spec.loss_names.insert(spec.loss_names.end(), {"cls", "cyc", "critic"});
    if (config.dynamics_weight > 0) spec.loss_names.push_back("dyn");
    if (config.teacher_weight > 0) spec.loss_names.push_back("teach");
    if (config.motion_gan_weight > 0)
      spec.loss_names.insert(spec.loss_names.end(), {"mgan", "mdisc"});
    if (config.motion_class_weight > 0)
      spec.loss_names.insert(spec.loss_names.end(), {"mcls", "mcritic"});
    if (config.paired_weight > 0) spec.loss_names.push_back("pair");
    if (config.motion_rec_weight > 0) spec.loss_names.push_back("mrec");
    if (config.own_rec_weight > 0) spec.loss_names.push_back("own");
    spec.loss_names.push_back("total");
    spec.config_text = config.Serialize();
    spec.iterations = config.iterations;
    spec.log_every = opt.log_every;
    spec.checkpoint_every = opt.checkpoint_every;
    spec.log = opt.log;
    if (opt.on_record) {
      spec.on_record = [this](const LossRow& row) {
        LossRecord r{row.iteration,  row.Get("rec"),    row.Get("gan"),   row.Get("nce"),
                     row.Get("tri"), row.Get("disc"),   row.Get("total"), row.Get("cls"),
                     row.Get("cyc"), row.Get("critic"), row.Get("dyn"),   row.Get("teach"),
                     row.Get("mgan"), row.Get("mdisc"), row.Get("mcls"),  row.Get("mcritic"),
                     row.Get("pair"), row.Get("mrec"), row.Get("own")};
        opt.on_record(r);
      };
    }
    std::vector<TorchFile> files = {Tensors("net.pt", &net), Tensors("disc.pt", &disc),
                                    Tensors("opt_g.pt", opt_g.get()),
                                    Tensors("opt_d.pt", opt_d.get())};
    if (config.guided) {
      critic.AddFiles("critic", "opt_c", &files);
    }
    if (config.pair_gan) pair_gan.AddFiles(&files);
    if (config.motion_gan_weight > 0) motion_gan.AddFiles(&files, "motion_disc", "opt_md");
    if (config.motion_class_weight > 0) motion_critic.AddFiles("motion_critic", "opt_mc", &files);
    if (average.on()) files.push_back(Tensors("average.pt", average.mean()));
    CheckpointTorchFiles(std::move(files), &spec);
    spec.write_package = [this](int iterations, const std::string& csv) {
      return WritePackage(iterations, csv);
    };
    TrainingRun run(std::move(spec));
    run.rng().seed(config.seed);
    rng = &run.rng();
    if (opt.resume) {
      if (absl::Status s = run.Resume(ComparableConfigText<ContrastiveConfig>); !s.ok()) return s;
    }
    return run.Run([this](int iteration) {
      const LossRecord r = config.guided ? GuidedStep() : Step();
      average.Update(iteration + 1, net);
      Losses losses = {{"rec", r.rec}, {"gan", r.gan},   {"nce", r.nce},
                       {"tri", r.tri}, {"disc", r.disc}, {"total", r.total}};
      if (config.guided) losses.insert({{"cls", r.cls}, {"cyc", r.cyc}, {"critic", r.critic}});
      if (config.dynamics_weight > 0) losses.insert({"dyn", r.dyn});
      if (config.teacher_weight > 0) losses.insert({"teach", r.teach});
      if (config.motion_gan_weight > 0) losses.insert({{"mgan", r.mgan}, {"mdisc", r.mdisc}});
      if (config.motion_class_weight > 0)
        losses.insert({{"mcls", r.mcls}, {"mcritic", r.mcritic}});
      if (config.paired_weight > 0) losses.insert({"pair", r.pair});
      if (config.motion_rec_weight > 0) losses.insert({"mrec", r.mrec});
      if (config.own_rec_weight > 0) losses.insert({"own", r.own});
      return losses;
    });
  }
};

}  // namespace

absl::Status TrainContrastive(const ContrastiveTrainOptions& options) {
  if (absl::Status s = CheckTrainingOptions(options, options.config); !s.ok()) return s;
  Trainer t(options);
  try {
    return t.Run();
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training failed: ", e.what()));
  }
}

}  // namespace stylus::model
