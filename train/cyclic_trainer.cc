#include "train/cyclic_trainer.h"

#include <torch/torch.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "model/config_text.h"
#include "model/cyclic/cyclic_net.h"
#include "model/guard_net.h"
#include "model/package.h"
#include "model/runtime.h"
#include "model/weights_io.h"
#include "motion/files.h"
#include "train/clip_classes.h"
#include "train/label_critic.h"
#include "train/pair_discriminator.h"
#include "train/torch_files.h"
#include "train/training_set.h"
#include "train/weight_average.h"

namespace stylus::model {

const std::vector<std::string>& CyclicLossNames() {
  static const std::vector<std::string> names = {"rec",    "style",  "content", "gan",  "cycle",
                                                 "smooth", "bone",   "traj",    "foot", "disc",
                                                 "cls",    "labels", "total"};
  return names;
}

namespace {

// Gradient norm cap of the generator's and encoder's steps: one bad batch
// must not throw the autoencoder out of its basin.
constexpr double kMaxGradNorm = 5.0;

struct CyclicTrainer {
  explicit CyclicTrainer(const CyclicTrainOptions& options)
      : opt(options), config(options.config) {}

  const CyclicTrainOptions& opt;
  CyclicConfig config;
  TrainingSet data;
  CyclicNet net{nullptr};
  WeightAverage<CyclicNet> average;  // With config.average_from.
  CyclicCritic critic{nullptr};
  std::unique_ptr<KinematicLoss> kinematic;
  std::unique_ptr<torch::optim::Adam> opt_e, opt_g, opt_d;
  torch::Tensor channels;
  torch::Tensor keep_mask;  // (1, C, 1): channels of the content-keeping term.
  // Label-guided training only.
  ClipClasses classes;
  LabelCritic label_critic;
  PairGan pair_gan;  // With `pair_gan` only.

  std::vector<torch::Tensor> EncoderParameters() { return net->enc_conv->parameters(); }
  // Everything but the encoder: decoder, style transform (and style network).
  std::vector<torch::Tensor> GeneratorParameters() {
    std::vector<torch::Tensor> p;
    for (const auto& named : net->named_parameters()) {
      if (named.key().rfind("enc_conv.", 0) != 0) p.push_back(named.value());
    }
    return p;
  }

  // The legs' joint positions (the hips and everything below them), the
  // root trajectory and the contacts, in the network's channels.
  torch::Tensor KeepMask() const {
    const motion::Skeleton& sk = data.skeleton;
    const int joints = sk.num_joints();
    torch::Tensor mask = torch::zeros({1, config.net_channels(joints), 1});
    const std::vector<bool> leg = motion::LegJoints(sk, data.roles);
    for (int j = 0; j < joints; ++j)
      if (leg[j])
        for (int a = 0; a < 3; ++a) mask[0][3 * j + a][0] = 1;
    for (int c = 0; c < motion::FeatureLayout::kPathChannels; ++c) mask[0][3 * joints + c][0] = 1;
    return mask;
  }

  // The style code of clip `x` whose hidden features are `hx`.
  torch::Tensor CodeOf(const torch::Tensor& x, const torch::Tensor& hx) {
    return config.style_dim > 0 ? net->code(x) : net->stats(hx);
  }

  // --init-from: every tensor of the package's network that this network
  // also has is copied (a style network can start from a v1 autoencoder);
  // logs how many. INVALID_ARGUMENT when a shared tensor has another shape.
  absl::Status InitFrom(const std::string& dir, int width) {
    absl::StatusOr<CyclicConfig> source = CyclicConfig::Read(dir);
    if (!source.ok()) return source.status();
    CyclicNet from(*source, width);
    if (absl::Status s = LoadWeights(from, dir + "/weights.pt"); !s.ok()) return s;
    absl::StatusOr<TensorCopy> copy = CopyTensorsByName(from, net, dir);
    if (!copy.ok()) return copy.status();
    if (copy->copied == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(dir, ": no tensor of its network is in this one"));
    }
    LogLine(opt.log,
            absl::StrCat("initialized ", copy->copied, " of ", copy->total, " tensors from ", dir));
    return absl::OkStatus();
  }

  torch::Tensor NetChannels(std::vector<float>* buf) const {
    return torch::from_blob(buf->data(), {config.batch, config.dim, config.window}, torch::kFloat32)
        .index_select(1, channels)
        .clone();
  }

  // A batch of windows; `clips` (if not null) gets the clip of each.
  torch::Tensor Batch(std::mt19937_64* rng, std::vector<int>* clips = nullptr) {
    std::vector<float> buf;
    data.SampleBatch(config.batch, config.window, rng, &buf, clips);
    return NetChannels(&buf);
  }

  // For each clip, a window of a clip of another style (guided training).
  torch::Tensor OtherStyleBatch(const std::vector<int>& clips, std::mt19937_64* rng,
                                std::vector<int>* chosen) {
    chosen->clear();
    for (int c : clips) chosen->push_back(classes.OtherStyle(c, rng));
    std::vector<float> buf;
    data.SampleFromClips(*chosen, config.window, rng, &buf);
    return NetChannels(&buf);
  }

  Losses Step(int iteration, std::mt19937_64* rng) {
    Losses r;
    for (const std::string& name : CyclicLossNames()) r[name] = 0;
    const bool autoencoder_only = iteration < config.ae_iterations;
    for (const torch::Tensor& p : EncoderParameters()) p.requires_grad_(autoencoder_only);
    std::vector<int> content_clips, style_clips;
    const torch::Tensor c = Batch(rng, &content_clips);
    const torch::Tensor h_c = net->encode(c);
    const torch::Tensor reconstruction = net->decode(h_c);
    const torch::Tensor rec = torch::mse_loss(reconstruction, c) +
                              torch::mse_loss(net->decode(net->transform(h_c, CodeOf(c, h_c))), c);
    torch::Tensor total = config.rec_weight * rec;
    r["rec"] = rec.item<double>();
    torch::Tensor out;  // What the kinematic constraints judge.
    if (autoencoder_only) {
      out = reconstruction;
    } else {
      const torch::Tensor s =
          config.guided ? OtherStyleBatch(content_clips, rng, &style_clips) : Batch(rng);
      const torch::Tensor h_s = net->encode(s).detach();
      const torch::Tensor gm =
          net->output(c, h_c.detach(), net->transform(h_c.detach(), CodeOf(s, h_s)));
      const torch::Tensor h_gm = net->encode(gm);
      const torch::Tensor style = torch::mse_loss(Gram(h_gm), Gram(h_s));
      const torch::Tensor content = torch::mse_loss(h_gm, h_c.detach());
      total = total + config.style_weight * style + config.content_weight * content;
      if (config.keep_weight > 0) {
        const torch::Tensor keep =
            ((gm - c).abs() * keep_mask).sum() / (keep_mask.sum() * gm.size(0) * gm.size(2));
        total = total + config.keep_weight * keep;
      }
      r["style"] = style.item<double>(), r["content"] = content.item<double>();
      if (config.gan_weight > 0 && config.pair_gan) {
        double d_loss = 0;
        const torch::Tensor gan =
            pair_gan.Step(c, LabelTensor(content_clips, classes.style_of),
                          LabelTensor(content_clips, classes.content_of), s,
                          LabelTensor(style_clips, classes.style_of),
                          LabelTensor(style_clips, classes.content_of), gm, &d_loss);
        total = total + config.gan_weight * gan;
        r["disc"] = d_loss, r["gan"] = gan.item<double>();
      } else if (config.gan_weight > 0) {
        opt_d->zero_grad();
        const torch::Tensor real = critic->forward(s), fake = critic->forward(gm.detach());
        const torch::Tensor d_loss =
            torch::binary_cross_entropy_with_logits(real, torch::ones_like(real)) +
            torch::binary_cross_entropy_with_logits(fake, torch::zeros_like(fake));
        d_loss.backward();
        opt_d->step();
        r["disc"] = d_loss.item<double>();
        const torch::Tensor judged = critic->forward(gm);
        const torch::Tensor gan =
            torch::binary_cross_entropy_with_logits(judged, torch::ones_like(judged));
        total = total + config.gan_weight * gan;
        r["gan"] = gan.item<double>();
      }
      if (config.guided) {
        const torch::Tensor target_style = LabelTensor(style_clips, classes.style_of);
        const torch::Tensor content_label = LabelTensor(content_clips, classes.content_of);
        // The label critic learns real windows' labels, never transfers'.
        r["labels"] =
            label_critic.Learn({{c, LabelTensor(content_clips, classes.style_of), content_label},
                                {s, target_style, LabelTensor(style_clips, classes.content_of)}});
        const torch::Tensor cls =
            label_critic.Verdict(gm, target_style, content_label, config.content_class_weight);
        total = total + config.class_weight * cls;
        r["cls"] = cls.item<double>();
      }
      if (config.use_cycle) {
        const torch::Tensor back =
            net->output(gm, h_gm, net->transform(h_gm, CodeOf(c, h_c.detach())));
        const torch::Tensor cycle = torch::mse_loss(back, c);
        total = total + config.cycle_weight * cycle;
        r["cycle"] = cycle.item<double>();
      }
      out = gm;
    }
    const KinematicLoss::Terms kc = kinematic->Compute(out, c);
    r["smooth"] = kc.smooth.item<double>(), r["bone"] = kc.bone.item<double>();
    r["traj"] = kc.traj.item<double>(), r["foot"] = kc.foot.item<double>();
    if (config.use_kc) total = total + kinematic->Weighted(kc, config);
    opt_g->zero_grad();
    opt_e->zero_grad();
    total.backward();
    // The optimizers' own parameter lists (built once).
    torch::nn::utils::clip_grad_norm_(opt_g->param_groups()[0].params(), kMaxGradNorm);
    opt_g->step();
    if (autoencoder_only) {
      torch::nn::utils::clip_grad_norm_(opt_e->param_groups()[0].params(), kMaxGradNorm);
      opt_e->step();
    }
    r["total"] = total.item<double>();
    return r;
  }

  absl::Status WritePackage(int iterations, const std::string& csv) {
    CyclicConfig c = config;
    c.trained_iterations = iterations;
    return WriteTrainedPackage(opt.out, c.Serialize(), data,
                               Tensors("weights.pt", average.ForPackage(iterations, &net)), csv);
  }

  absl::Status Run() {
    SetComputeThreads(opt.threads);
    absl::StatusOr<TrainingSet> loaded = LoadRunData(opt, &config);
    if (!loaded.ok()) return loaded.status();
    data = *std::move(loaded);
    const int joints = data.skeleton.num_joints();
    channels = torch::tensor(CyclicChannels(joints, config.rotations));
    keep_mask = KeepMask();
    kinematic =
        std::make_unique<KinematicLoss>(data.skeleton, data.roles, data.norm, data.frame_time);
    const int width = config.net_channels(joints);
    if (config.average_from > 0)  // Before the seed (see WeightAverage).
      average = WeightAverage<CyclicNet>(config.average_from, config.average_every,
                                         CyclicNet(config, width));
    torch::manual_seed(config.seed);
    net = CyclicNet(config, width);
    critic = CyclicCritic(config, width);
    if (config.guided) {
      absl::StatusOr<ClipClasses> labelled =
          GuidedClasses(&data, config.window, config.content_balance, opt.log);
      if (!labelled.ok()) return labelled.status();
      classes = *std::move(labelled);
      label_critic = LabelCritic(width, static_cast<int>(classes.styles.size()),
                                 static_cast<int>(classes.contents.size()));
      if (config.pair_gan) {
        pair_gan = PairGan(width, static_cast<int>(classes.styles.size()),
                           static_cast<int>(classes.contents.size()), config.lr);
      }
    }
    const auto adam = torch::optim::AdamOptions(config.lr).betas({0.5, 0.999});
    opt_e = std::make_unique<torch::optim::Adam>(EncoderParameters(), adam);
    opt_g = std::make_unique<torch::optim::Adam>(GeneratorParameters(), adam);
    opt_d = std::make_unique<torch::optim::Adam>(critic->parameters(), adam);

    TrainingRun::Spec spec;
    spec.log = opt.log;
    spec.out = opt.out;
    spec.loss_names = CyclicLossNames();
    spec.config_text = config.Serialize();
    spec.iterations = config.iterations;
    spec.log_every = opt.log_every;
    spec.checkpoint_every = opt.checkpoint_every;
    spec.on_record = opt.on_record;
    std::vector<TorchFile> files = {
        Tensors("net.pt", &net), Tensors("critic.pt", &critic), Tensors("opt_e.pt", opt_e.get()),
        Tensors("opt_g.pt", opt_g.get()), Tensors("opt_d.pt", opt_d.get())};
    if (config.guided) {
      label_critic.AddFiles("label_critic", "opt_l", &files);
    }
    if (config.pair_gan) pair_gan.AddFiles(&files);
    if (average.on()) files.push_back(Tensors("average.pt", average.mean()));
    CheckpointTorchFiles(std::move(files), &spec);
    spec.write_package = [this](int iterations, const std::string& csv) {
      return WritePackage(iterations, csv);
    };
    if (!opt.init_from.empty()) {
      if (absl::Status s = InitFrom(opt.init_from, width); !s.ok())
        return absl::Status(s.code(), absl::StrCat("--init-from: ", s.message()));
    }
    TrainingRun run(std::move(spec));
    run.rng().seed(config.seed);
    if (opt.resume) {
      if (absl::Status s = run.Resume(ComparableConfigText<CyclicConfig>); !s.ok()) return s;
    }
    net->train();
    critic->train();
    return run.Run([&](int iteration) {
      Losses losses = Step(iteration, &run.rng());
      average.Update(iteration + 1, net);
      return losses;
    });
  }
};

}  // namespace

absl::Status TrainCyclic(const CyclicTrainOptions& options) {
  if (absl::Status s = CheckTrainingOptions(options, options.config); !s.ok()) return s;
  if (options.config.window % 2 != 0) return absl::InvalidArgumentError("window must be even");
  if (options.config.adain_skip && options.config.style_dim == 0) {
    return absl::InvalidArgumentError("the normalized skip (adain_skip) needs a style network");
  }
  CyclicTrainer t(options);
  try {
    return t.Run();
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training failed: ", e.what()));
  }
}

}  // namespace stylus::model
