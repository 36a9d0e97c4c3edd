// The `cyclic` family on a tiny configuration and synthesized clips (no
// dataset needed): each loss, the cycle loss falling in training, the
// inference-time kinematic optimization, packaging and inference.
#include "model/cyclic_model.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <fstream>

#include "gtest/gtest.h"
#include "absl/strings/str_cat.h"
#include "model/chunked_stream.h"
#include "model/content_guard.h"
#include "model/cyclic_net.h"
#include "model/cyclic_trainer.h"
#include "model/package.h"
#include "model/weights_io.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/synth.h"
#include "tests/model/synth_clips.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;

std::string Dir(const std::string& name) { return testing::FreshDir("cyclic_" + name); }
using testing::FourClips;

motion::Motion Clip(int i) { return *motion::ReadBvhFile(FourClips()[i]); }

CyclicConfig Tiny() {
  CyclicConfig c;
  c.window = 16;
  c.hop = 8;
  c.hidden = 24;
  c.kernel = 5;
  c.dropout = 0;
  c.batch = 8;
  c.lr = 2e-3;
  c.ae_iterations = 60;
  c.iterations = 200;
  c.seed = 3;
  return c;
}

CyclicTrainOptions TinyOptions(const std::string& out) {
  CyclicTrainOptions o;
  o.data = FourClips();
  o.out = out;
  o.config = Tiny();
  o.log_every = 10;
  o.checkpoint_every = 50;
  o.threads = 1;
  o.log = [](const std::string&) {};
  return o;
}

// Normalized network channels (1, C, T) of a clip, with what the loss needs.
struct ClipChannels {
  motion::Motion clip;
  motion::HumanoidRoles roles;
  motion::NormStats norm;
  torch::Tensor x;
};

ClipChannels MakeClipChannels(int i) {
  ClipChannels s;
  s.clip = Clip(i);
  s.roles = *motion::FindHumanoidRoles(s.clip.skeleton);
  motion::FeatureClip f = *motion::ExtractFeatures(s.clip, s.roles);
  s.norm = *motion::NormStats::Compute({&f});
  s.norm.Normalize(&f);
  s.x = torch::from_blob(f.values.data(), {f.frames, f.dim}, torch::kFloat32)
            .index_select(1, torch::tensor(CyclicChannels(s.clip.skeleton.num_joints(), false)))
            .t()
            .unsqueeze(0)
            .clone();
  return s;
}

TEST(CyclicNetTest, ShapesAndStyleCode) {
  const CyclicConfig c = Tiny();
  const ClipChannels s = MakeClipChannels(0);
  CyclicNet net(c, static_cast<int>(s.x.size(1)));
  const torch::Tensor h = net->encode(s.x);
  EXPECT_EQ(h.sizes(), (std::vector<int64_t>{1, int64_t{c.hidden}, s.x.size(2) / 2}));
  EXPECT_EQ(net->decode(h).sizes(), s.x.sizes());
  EXPECT_EQ(CyclicNetImpl::stats(h).sizes(), (std::vector<int64_t>{1, int64_t{2 * c.hidden}, 1}));
  EXPECT_EQ(net->generate(s.x, MakeClipChannels(1).x).sizes(), s.x.sizes());
  // Residual output: with the content's own hidden features, the content.
  EXPECT_TRUE(torch::allclose(net->output(s.x, h, h), s.x, 1e-4, 1e-4));
  CyclicConfig plain = c;
  plain.residual = false;
  CyclicNet plain_net(plain, static_cast<int>(s.x.size(1)));
  EXPECT_TRUE(torch::allclose(plain_net->output(s.x, h, h), plain_net->decode(h)));
  const torch::Tensor g = Gram(h);
  EXPECT_EQ(g.sizes(), (std::vector<int64_t>{1, int64_t{c.hidden}, int64_t{c.hidden}}));
  EXPECT_TRUE(torch::allclose(g, g.transpose(1, 2)));
  CyclicCritic critic(c, static_cast<int>(s.x.size(1)));
  EXPECT_EQ(critic->forward(s.x).sizes(), (std::vector<int64_t>{1}));
}

TEST(CyclicNetTest, KinematicTermsAreZeroOnTheContentAndGrowWithErrors) {
  const ClipChannels s = MakeClipChannels(0);
  KinematicLoss loss(s.clip.skeleton, s.roles, s.norm, s.clip.frame_time);
  const KinematicLoss::Terms same = loss.Compute(s.x, s.x);
  EXPECT_NEAR(same.smooth.item<double>(), 0, 1e-9);
  EXPECT_NEAR(same.traj.item<double>(), 0, 1e-9);
  EXPECT_NEAR(same.foot.item<double>(), 0, 1e-9);
  EXPECT_LT(same.bone.item<double>(), 1e-6);  // Real positions keep their bones.
  EXPECT_LT(loss.BoneError(s.x).item<double>(), 1e-3);
  torch::manual_seed(1);
  const torch::Tensor noisy = s.x + 0.3 * torch::randn_like(s.x);
  const KinematicLoss::Terms t = loss.Compute(noisy, s.x);
  EXPECT_GT(t.smooth.item<double>(), 1e-3);
  EXPECT_GT(t.bone.item<double>(), 1e-4);
  EXPECT_GT(t.traj.item<double>(), 1e-2);
  EXPECT_GT(t.foot.item<double>(), 1e-3);
  EXPECT_GT(loss.BoneError(noisy).item<double>(), 1e-2);
  // Switches: a zero weight drops its term.
  CyclicConfig only_bone;
  only_bone.smooth_weight = only_bone.traj_weight = only_bone.foot_weight = 0;
  EXPECT_NEAR(loss.Weighted(t, only_bone).item<double>(), t.bone.item<double>(), 1e-9);
}

TEST(CyclicNetTest, KinematicOptimizationReducesBoneErrorOfAPerturbedClip) {
  // Only the bone-length term, as a test of what the optimization does; the
  // full weighted loss is checked to fall too.
  CyclicConfig c = Tiny();
  c.kc_iters = 200;
  c.kc_lr = 0.05;
  c.smooth_weight = c.traj_weight = c.foot_weight = 0;
  const ClipChannels s = MakeClipChannels(1);
  torch::manual_seed(2);
  CyclicNet net(c, static_cast<int>(s.x.size(1)));
  net->eval();
  for (torch::Tensor& p : net->parameters()) p.requires_grad_(false);
  KinematicLoss loss(s.clip.skeleton, s.roles, s.norm, s.clip.frame_time);
  torch::Tensor h;
  {
    torch::NoGradGuard no_grad;
    h = net->encode(s.x) + 0.5 * torch::randn({1, c.hidden, s.x.size(2) / 2});
  }
  const double before = loss.BoneError(net->decode(h)).item<double>();
  const torch::Tensor no_offset = torch::zeros_like(s.x);
  const KinematicFit fit = OptimizeHidden(net, loss, c, s.x, no_offset, &h);
  const double after = loss.BoneError(net->decode(h)).item<double>();
  std::printf("bone error %.4f -> %.4f, loss %.4f -> %.4f in %d steps\n", before, after,
              fit.loss_before, fit.loss_after, fit.steps);
  EXPECT_LT(fit.loss_after, 0.5 * fit.loss_before);
  EXPECT_LT(after, 0.7 * before);
  EXPECT_GT(fit.steps, 0);
  const CyclicConfig all = Tiny();
  const KinematicFit fit_all = OptimizeHidden(net, loss, all, s.x, no_offset, &h);
  EXPECT_LT(fit_all.loss_after, 0.5 * fit_all.loss_before);
}

TEST(CyclicModelTest, CycleLossFallsAndThePackageServesTransfers) {
  // The paper's decoder-only output: its cycle loss starts at the
  // autoencoder's error and must fall.
  CyclicTrainOptions o = TinyOptions(Dir("train"));
  o.config.residual = false;
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  const auto& names = CyclicLossNames();
  const size_t cycle = std::find(names.begin(), names.end(), "cycle") - names.begin();
  const size_t rec = std::find(names.begin(), names.end(), "rec") - names.begin();
  // Rows after the autoencoder stage (iteration > 60) carry the cycle loss.
  std::vector<double> cyc;
  for (const LossRow& r : rows) {
    if (r.iteration > o.config.ae_iterations + 10) cyc.push_back(r.values[cycle]);
  }
  ASSERT_GE(cyc.size(), 10u);
  std::printf("cycle %.4f -> %.4f; rec %.4f -> %.4f\n", cyc.front(), cyc.back(),
              rows.front().values[rec], rows.back().values[rec]);
  EXPECT_LT(cyc.back(), 0.7 * cyc.front());
  EXPECT_LT(rows.back().values[rec], 0.5 * rows.front().values[rec]);
  for (const char* f : {"config.txt", "norm.txt", "skeleton.bvh", "weights.pt", "loss.csv"})
    EXPECT_TRUE(fs::exists(o.out + "/" + f)) << f;

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ((*m)->summary().family, "cyclic");
  const motion::Motion content = Clip(0), a = Clip(1), b = Clip(2);
  const StyleCode sa = *(*m)->EncodeStyle(a), sb = *(*m)->EncodeStyle(b);
  EXPECT_EQ(sa.values.size(), 2u * o.config.hidden);
  absl::StatusOr<motion::Motion> out = (*m)->Transfer(content, sa);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  EXPECT_TRUE(out->skeleton.SameTopology(content.skeleton));
  EXPECT_LT(motion::BoneLengthError(*out, *motion::FindHumanoidRoles(content.skeleton)), 1e-4);
  // Any length, odd included.
  motion::Motion odd = content;
  odd.num_frames = 37;
  odd.values.resize(static_cast<size_t>(37) * content.skeleton.num_channels());
  absl::StatusOr<motion::Motion> out_odd = (*m)->Transfer(odd, sa);
  ASSERT_TRUE(out_odd.ok()) << out_odd.status();
  EXPECT_EQ(out_odd->num_frames, 37);
  // Interpolation at w = 0 and w = 1 equals transfer with B and A; loading
  // again gives the same outputs.
  auto same = [](const motion::Motion& x, const motion::Motion& y) {
    double worst = 0;
    for (size_t i = 0; i < x.values.size(); ++i)
      worst = std::max(worst, std::fabs(x.values[i] - y.values[i]));
    return worst;
  };
  const motion::Motion ta = *(*m)->Transfer(content, sa, motion::PostProcessMode::kNone);
  const motion::Motion tb = *(*m)->Transfer(content, sb, motion::PostProcessMode::kNone);
  EXPECT_LT(same(*(*m)->Interpolate(content, {sa, sb}, {{1, 0}, {}}, motion::PostProcessMode::kNone),
                 ta),
            1e-3);
  EXPECT_LT(same(*(*m)->Interpolate(content, {sa, sb}, {{0, 1}, {}}, motion::PostProcessMode::kNone),
                 tb),
            1e-3);
  auto again = CyclicModel::Load(o.out);
  ASSERT_TRUE(again.ok());
  EXPECT_LT(same(*(*again)->Transfer(content, sa, motion::PostProcessMode::kNone), ta), 1e-4);
  // Without the inference-time optimization the output differs.
  auto no_kc = CyclicModel::Load(o.out, CyclicOptions{0});
  ASSERT_TRUE(no_kc.ok());
  const motion::Motion ta0 = *(*no_kc)->Transfer(content, sa, motion::PostProcessMode::kNone);
  EXPECT_GT(same(ta0, ta), 1e-3);
  // A per-frame schedule of constant weights is the fixed blend (compared
  // without the optimization, whose Adam steps amplify rounding
  // differences).
  std::vector<std::vector<double>> schedule(content.num_frames, {1, 0});
  EXPECT_LT(same(*(*no_kc)->Interpolate(content, {sa, sb}, {{}, schedule},
                                        motion::PostProcessMode::kNone),
                 ta0),
            1e-2);  // Degrees and units: float rounding of a per-step vs one code.

  // keep_path: the output walks the content's path. The pelvis path
  // (TrajectoryError) then differs from the content's only by the generated
  // pelvis offset from the root; the generated trajectory drifts far more.
  {
    const std::string kept = Dir("keep_path");
    for (const char* f : {"config.txt", "norm.txt", "skeleton.bvh", "weights.pt"})
      fs::copy_file(o.out + "/" + f, kept + "/" + f, fs::copy_options::overwrite_existing);
    std::ofstream(kept + "/config.txt", std::ios::app) << "keep_path = 1\n";
    auto keep = CyclicModel::Load(kept, CyclicOptions{0});
    ASSERT_TRUE(keep.ok()) << keep.status();
    const motion::HumanoidRoles roles = *motion::FindHumanoidRoles(content.skeleton);
    const motion::Motion on_path =
        *(*keep)->Transfer(content, sa, motion::PostProcessMode::kNone);
    const double kept_error = motion::TrajectoryError(on_path, content, roles);
    const double own_error = motion::TrajectoryError(ta0, content, roles);
    std::printf("trajectory error: generated %.4f, keep_path %.6f\n", own_error, kept_error);
    EXPECT_LT(kept_error, 0.2);
    EXPECT_GT(own_error, 20 * kept_error);
  }

  // The AdaIN probe: another style changes the output.
  auto probe = CyclicModel::Load(o.out, CyclicOptions{0, true});
  ASSERT_TRUE(probe.ok());
  const motion::Motion own = *(*probe)->Transfer(content, *(*probe)->EncodeStyle(content),
                                                 motion::PostProcessMode::kNone);
  EXPECT_GT(same((*probe)->Transfer(content, sa, motion::PostProcessMode::kNone).value(), own),
            1e-2);

  // Bad input: a clip on another skeleton, a wrong-size style code.
  motion::Motion other = content;
  std::vector<motion::Joint> joints = other.skeleton.joints();
  joints[3].name = "Renamed";
  other.skeleton = *motion::Skeleton::Create(joints);
  EXPECT_EQ((*m)->Transfer(other, sa).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ((*m)->Transfer(content, StyleCode{{1, 2, 3}}).status().code(),
            absl::StatusCode::kInvalidArgument);

  // Resume continues from the checkpoint to a longer run.
  CyclicTrainOptions more = o;
  more.config.iterations = 220;
  more.resume = true;
  std::vector<std::string> lines;
  more.log = [&](const std::string& l) { lines.push_back(l); };
  more.on_record = nullptr;
  ASSERT_TRUE(TrainCyclic(more).ok());
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines[1].find("resumed from"), std::string::npos) << lines[1];
  // A checkpoint of another configuration is refused.
  CyclicTrainOptions changed = more;
  changed.config.hidden = 32;
  EXPECT_EQ(TrainCyclic(changed).code(), absl::StatusCode::kFailedPrecondition);

  // Corrupt weights: a clear error naming the file.
  const std::string broken = Dir("broken");
  for (const char* f : {"config.txt", "norm.txt", "skeleton.bvh"})
    fs::copy_file(o.out + "/" + f, broken + "/" + f);
  std::ofstream(broken + "/weights.pt") << "not a torch archive";
  absl::StatusOr<std::unique_ptr<StyleModel>> bad = LoadStyleModel(broken);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("weights.pt"), absl::string_view::npos);
}

TEST(CyclicModelTest, GuidedGeneratorStageLearnsFromTheLabelCritic) {
  // --guided: the label critic learns real windows' labels and the
  // generator's classification loss on transfers falls.
  // Two critics (--critics 2): both learn and both are checkpointed.
  CyclicTrainOptions o = TinyOptions(Dir("guided"));
  o.data = testing::LabelledClips();
  o.config.guided = true;
  o.config.critics = 2;
  o.config.content_balance = 1;  // Every action drawn alike (logged).
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  const auto& names = CyclicLossNames();
  const size_t cls = std::find(names.begin(), names.end(), "cls") - names.begin();
  const size_t labels = std::find(names.begin(), names.end(), "labels") - names.begin();
  std::vector<LossRow> generator;
  for (const LossRow& r : rows)
    if (r.iteration > o.config.ae_iterations + 10) generator.push_back(r);
  ASSERT_GE(generator.size(), 5u);
  std::printf("labels %.4f -> %.4f; cls %.4f -> %.4f\n", generator.front().values[labels],
              generator.back().values[labels], generator.front().values[cls],
              generator.back().values[cls]);
  EXPECT_LT(generator.back().values[labels], 0.5 * generator.front().values[labels]);
  EXPECT_LT(generator.back().values[cls], 0.8 * generator.front().values[cls]);
  EXPECT_TRUE(std::any_of(log.begin(), log.end(), [](const std::string& l) {
    return l.rfind("content balance 1:", 0) == 0;
  }));
  for (const char* f : {"label_critic.pt", "opt_l.pt", "label_critic2.pt", "opt_l2.pt"}) {
    EXPECT_TRUE(std::filesystem::exists(o.out + "/checkpoint/" + f)) << f;
  }
  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  // Unlabelled names are refused, naming the file.
  CyclicTrainOptions unguided = TinyOptions(Dir("balance_unguided"));
  unguided.config.content_balance = 1;
  EXPECT_EQ(TrainCyclic(unguided).code(), absl::StatusCode::kInvalidArgument);
  o.data = testing::FourClips();
  o.out = Dir("guided_unlabelled");
  const absl::Status s = TrainCyclic(o);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("normal.bvh"), std::string::npos) << s;
}

TEST(CyclicNetTest, StyleNetworkShapesAndStartsNearTheIdentity) {
  CyclicConfig c = Tiny();
  c.style_dim = 8, c.blocks = 3;
  const ClipChannels s = MakeClipChannels(0);
  CyclicNet net(c, static_cast<int>(s.x.size(1)));
  const torch::Tensor style = MakeClipChannels(1).x;
  EXPECT_EQ(net->code(style).sizes(), (std::vector<int64_t>{1, 8, 1}));
  EXPECT_EQ(c.code_size(), 8);
  const torch::Tensor h = net->encode(s.x);
  const torch::Tensor restyled = net->transform(h, net->code(style));
  EXPECT_EQ(restyled.sizes(), h.sizes());
  // Each block starts at a tenth of its output: near, not at, the identity.
  const double change = (restyled - h).abs().mean().item<double>();
  EXPECT_GT(change, 0);
  EXPECT_LT(change, 0.2 * h.abs().mean().item<double>() + 1e-3);
  // A code per hidden step works too.
  EXPECT_EQ(net->transform(h, net->code(style).expand({1, 8, h.size(2)})).sizes(), h.sizes());
}

// Trains the autoencoder stage alone on the labelled clips (into
// Dir(name + "_ae"); its loss rows into `ae_rows` when given) and returns the
// options of a guided style-network run (8 values, 2 blocks) of
// `iterations` that starts from it, into Dir(name).
CyclicTrainOptions StyleNetworkAfterAutoencoder(const std::string& name, int iterations,
                                                std::vector<LossRow>* ae_rows = nullptr) {
  CyclicTrainOptions ae = TinyOptions(Dir(name + "_ae"));
  ae.data = testing::LabelledClips();
  ae.config.iterations = ae.config.ae_iterations;  // The autoencoder stage only.
  if (ae_rows != nullptr) ae.on_record = [ae_rows](const LossRow& r) { ae_rows->push_back(r); };
  const absl::Status trained = TrainCyclic(ae);
  EXPECT_TRUE(trained.ok()) << trained;
  CyclicTrainOptions o = TinyOptions(Dir(name));
  o.data = testing::LabelledClips();
  o.config.guided = true;
  o.config.style_dim = 8, o.config.blocks = 2;
  o.config.ae_iterations = 0, o.config.iterations = iterations;
  o.init_from = ae.out;
  return o;
}

// --adain-skip: the content's own channel statistics never reach the
// restyled features; the style clip's take their place.
TEST(CyclicNetTest, AdaInSkipGivesTheContentTheStyleClipsChannelStatistics) {
  CyclicConfig c = Tiny();
  c.style_dim = 8, c.blocks = 2;
  const ClipChannels s = MakeClipChannels(0);
  const int width = static_cast<int>(s.x.size(1));
  torch::manual_seed(3);
  CyclicNet plain(c, width);
  c.adain_skip = true;
  torch::manual_seed(3);
  CyclicNet skip(c, width);
  EXPECT_EQ(c.code_size(), 8 + 2 * c.hidden);
  torch::NoGradGuard no_grad;
  const torch::Tensor style = MakeClipChannels(1).x;
  const torch::Tensor code = skip->code(style);
  ASSERT_EQ(code.sizes(), (std::vector<int64_t>{1, 8 + 2 * c.hidden, 1}));
  // The style encoder's values, then the style clip's hidden statistics.
  EXPECT_TRUE(torch::allclose(code.slice(1, 0, 8), plain->code(style)));
  const torch::Tensor hs = skip->encode(style);
  EXPECT_TRUE(torch::allclose(code.slice(1, 8, code.size(1)), CyclicNetImpl::SkipStats(hs)));

  const torch::Tensor h = skip->encode(s.x);
  // A clip's own statistics give its features back.
  EXPECT_LT((CyclicNetImpl::AdaInSkip(h, CyclicNetImpl::SkipStats(h)) - h).abs().max().item<double>(),
            1e-4);
  // Others give those statistics' means.
  const torch::Tensor moved = CyclicNetImpl::AdaInSkip(h, CyclicNetImpl::SkipStats(hs));
  EXPECT_LT((moved.mean(2) - hs.mean(2)).abs().max().item<double>(), 1e-4);
  EXPECT_GT((moved - h).abs().mean().item<double>(), 1e-3);

  // Shift every hidden channel of the content by its own constant: with the
  // normalized skip the restyled features do not change; without, they do.
  const torch::Tensor shift = torch::rand({1, h.size(1), 1});
  const double with_skip =
      (skip->transform(h + shift, code) - skip->transform(h, code)).abs().max().item<double>();
  const torch::Tensor plain_code = plain->code(style);
  const double without =
      (plain->transform(h + shift, plain_code) - plain->transform(h, plain_code))
          .abs()
          .max()
          .item<double>();
  std::printf("content shift reaches the output: %.2e (normalized skip), %.2e (plain)\n", with_skip,
              without);
  EXPECT_LT(with_skip, 1e-4);
  EXPECT_GT(without, 0.1);
  // A code per hidden step works too.
  EXPECT_EQ(skip->transform(h, code.expand({1, code.size(1), h.size(2)})).sizes(), h.sizes());
}

// A package with the normalized skip trains from an autoencoder, loads and
// transfers (its style codes hold the statistics too); without a style
// network the option is refused.
TEST(CyclicModelTest, AdaInSkipPackageTrainsLoadsAndTransfers) {
  std::vector<LossRow> ae_rows;
  CyclicTrainOptions o = StyleNetworkAfterAutoencoder("adain_skip", 60, &ae_rows);
  ASSERT_FALSE(ae_rows.empty());
  o.config.adain_skip = true;
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  ASSERT_GE(rows.size(), 2u);
  // G(C, C) reconstructs the content from the first iteration on (the skip
  // is the identity for a clip's own style): the rec loss stays near the
  // autoencoder's instead of starting from scratch.
  std::printf("rec: autoencoder %.4f, then %.4f -> %.4f\n", ae_rows.back().values[0],
              rows.front().values[0], rows.back().values[0]);
  EXPECT_LT(rows.front().values[0], 2.0 * ae_rows.back().values[0]);
  EXPECT_LT(rows.back().values[0], 2.0 * ae_rows.back().values[0]);

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  const motion::Motion content = motion::ReadBvhFile(o.data[0]).value();
  const motion::Motion a = motion::ReadBvhFile(o.data[3]).value();
  const motion::Motion b = motion::ReadBvhFile(o.data[1]).value();
  absl::StatusOr<StyleCode> ca = (*m)->EncodeStyle(a), cb = (*m)->EncodeStyle(b);
  ASSERT_TRUE(ca.ok() && cb.ok());
  EXPECT_EQ(ca->values.size(), static_cast<size_t>(8 + 2 * o.config.hidden));
  absl::StatusOr<motion::Motion> out = (*m)->Transfer(content, *ca, motion::PostProcessMode::kNone);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  StyleWeights half;
  half.fixed = {0.5, 0.5};
  absl::StatusOr<motion::Motion> mixed =
      (*m)->Interpolate(content, {*ca, *cb}, half, motion::PostProcessMode::kNone);
  ASSERT_TRUE(mixed.ok()) << mixed.status();
  EXPECT_EQ(mixed->num_frames, content.num_frames);

  CyclicTrainOptions no_style_net = TinyOptions(Dir("adain_skip_plain"));
  no_style_net.config.adain_skip = true;
  EXPECT_EQ(TrainCyclic(no_style_net).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nadain_skip = 1\n", "cfg.txt").status().code(),
            absl::StatusCode::kInvalidArgument);
}

// With `rotations`, the joints' rotations are network channels: the output's
// twists and the orientation of joints without a child joint (head, hands,
// toes) are generated. Without it they are the content clip's, exactly.
TEST(CyclicModelTest, RotationsPackageGeneratesWhatPositionsLeaveOpen) {
  const motion::Motion content = Clip(0), style = Clip(2);
  const motion::HumanoidRoles roles = *motion::FindHumanoidRoles(content.skeleton);
  const int joints = content.skeleton.num_joints();
  const motion::FeatureLayout layout(joints);
  std::vector<int> leaves;
  for (int j = 0; j < joints; ++j)
    if (content.skeleton.children(j).empty()) leaves.push_back(j);
  ASSERT_FALSE(leaves.empty());
  // The largest change of a leaf's rotation from the content's, over frames.
  auto leaf_change = [&](const motion::Motion& out) {
    const motion::FeatureClip a = *motion::ExtractFeatures(content, roles);
    const motion::FeatureClip b = *motion::ExtractFeatures(out, roles);
    double worst = 0;
    for (int f = 0; f < a.frames; ++f)
      for (int j : leaves) {
        const float* p = a.row(f) + layout.rotation(j);
        const float* q = b.row(f) + layout.rotation(j);
        worst = std::max(worst, motion::AngleBetween(motion::Quat{p[0], p[1], p[2], p[3]},
                                                     motion::Quat{q[0], q[1], q[2], q[3]}));
      }
    return worst;
  };
  std::map<bool, double> change;
  for (bool rotations : {false, true}) {
    CyclicTrainOptions o = TinyOptions(Dir(rotations ? "rotations" : "rotations_off"));
    o.config.rotations = rotations;
    o.config.iterations = 120;
    ASSERT_TRUE(TrainCyclic(o).ok());
    absl::StatusOr<std::unique_ptr<CyclicModel>> m = CyclicModel::Load(o.out, {0});
    ASSERT_TRUE(m.ok()) << m.status();
    EXPECT_EQ((*m)->config().rotations, rotations);
    EXPECT_EQ((*m)->config().net_channels(joints), rotations ? 7 * joints + 8 : 3 * joints + 8);
    absl::StatusOr<motion::Motion> out =
        (*m)->Transfer(content, *(*m)->EncodeStyle(style), motion::PostProcessMode::kNone);
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_LT(motion::BoneLengthError(*out, roles), 1e-4);
    change[rotations] = leaf_change(*out);
  }
  std::printf("largest leaf rotation change from the content: %.2g rad without, %.2g with\n",
              change[false], change[true]);
  EXPECT_LT(change[false], 1e-3);
  EXPECT_GT(change[true], 1e-2);
  const std::vector<int64_t> channels = CyclicChannels(joints, true);
  ASSERT_EQ(channels.size(), static_cast<size_t>(7 * joints + 8));
  EXPECT_EQ(channels[3 * joints], layout.trajectory());  // The path stays where it was.
  EXPECT_EQ(channels[3 * joints + 8], layout.rotation(0));
  EXPECT_EQ(channels.back(), layout.rotation(joints - 1) + 3);
}

// The content guard works for this family too: a weaker form restyles the
// hidden features part of the way, and strength 0 gives the content back.
TEST(CyclicModelTest, ContentGuardBacksOffTheRestyledFeatures) {
  CyclicTrainOptions o = TinyOptions(Dir("guarded"));
  o.data = testing::LabelledClips();
  o.config.iterations = 100;
  ASSERT_TRUE(TrainCyclic(o).ok());
  ContentGuardTrainOptions g;
  g.model = o.out;
  g.data = testing::LabelledClips();
  g.iterations = 1;  // Untrained: near-even probabilities, none reaches 0.99.
  g.guards = 2;
  g.log = [](const std::string&) {};
  ASSERT_TRUE(TrainContentGuard(g).ok());
  const motion::Motion content = Clip(0);
  const double leg = motion::FindHumanoidRoles(content.skeleton)->leg_length;
  auto transfer = [&](const std::string& keys, TransferNote* note, int kc_iters = 0) {
    const std::string dir =
        testing::CopyPackage(o.out, absl::StrCat("guarded_", keys.size(), "_", kc_iters), {}, keys);
    absl::StatusOr<std::unique_ptr<CyclicModel>> m = CyclicModel::Load(dir, {kc_iters});
    EXPECT_TRUE(m.ok()) << m.status();
    return (*m)->TransferNoted(content, *(*m)->EncodeStyle(Clip(2)), motion::PostProcessMode::kNone,
                               note);
  };
  // No form can pass (probability 0.99): the last form, strength 0, is returned.
  TransferNote note;
  absl::StatusOr<motion::Motion> out =
      transfer("content_guard = 1\nguard_strengths = 0.5,0\nguard_min_probability = 0.99\n", &note);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_TRUE(note.guarded && note.backed_off && note.last_form);
  EXPECT_EQ(note.residual_strength, 0);
  EXPECT_LT(motion::MaxPositionDifference(*out, content), 0.01 * leg);
  // Any probability: one of the forms, as the note says.
  TransferNote any;
  ASSERT_TRUE(transfer("content_guard = 1\nguard_strengths = 0.5,0\n", &any).ok());
  EXPECT_TRUE(any.guarded);
  EXPECT_EQ(any.residual_strength, any.backed_off ? (any.last_form ? 0 : 0.5) : 1);
  // The guard reads the forms before the kinematic optimization, and the
  // form it returns is then optimized: with every form at full strength,
  // the guarded transfer is the unguarded one, optimization included.
  TransferNote full;
  absl::StatusOr<motion::Motion> guarded =
      transfer("content_guard = 1\nguard_strengths = 1\n", &full, 20);
  absl::StatusOr<motion::Motion> plain = transfer("", nullptr, 20);
  absl::StatusOr<motion::Motion> unoptimized = transfer("", nullptr, 0);
  ASSERT_TRUE(guarded.ok() && plain.ok() && unoptimized.ok());
  EXPECT_TRUE(full.guarded);
  EXPECT_GT(motion::MaxPositionDifference(*plain, *unoptimized), 1e-4);  // The optimization acts.
  EXPECT_LT(motion::MaxPositionDifference(*guarded, *plain), 1e-5);
}

TEST(CyclicModelTest, StyleNetworkStartsFromAnAutoencoderAndLearnsFromTheLabelCritic) {
  CyclicTrainOptions o = StyleNetworkAfterAutoencoder("style_net", 150);
  o.config.pair_gan = true;
  const std::string ae_out = o.init_from;
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  // The encoder and decoder come from the autoencoder; the style network is new.
  bool partial = false;
  for (const std::string& line : log)
    partial = partial || (line.find("initialized 4 of ") == 0 && line.find(ae_out) != std::string::npos);
  EXPECT_TRUE(partial);
  const auto& names = CyclicLossNames();
  const size_t cls = std::find(names.begin(), names.end(), "cls") - names.begin();
  ASSERT_GE(rows.size(), 10u);
  // Once the critic knows the real windows' labels, the transfers' verdict
  // improves: the critic's gradient reaches the new style network.
  const size_t labels = std::find(names.begin(), names.end(), "labels") - names.begin();
  const auto trained = std::find_if(rows.begin(), rows.end(),
                                    [&](const LossRow& r) { return r.values[labels] < 0.01; });
  ASSERT_NE(trained, rows.end());
  std::printf("cls %.4f (iteration %d) -> %.4f\n", trained->values[cls], trained->iteration,
              rows.back().values[cls]);
  EXPECT_LT(rows.back().values[cls], 0.8 * trained->values[cls]);

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  const motion::Motion content = motion::ReadBvhFile(o.data[0]).value();
  const motion::Motion style_clip = motion::ReadBvhFile(o.data[3]).value();
  absl::StatusOr<StyleCode> code = (*m)->EncodeStyle(style_clip);
  ASSERT_TRUE(code.ok()) << code.status();
  EXPECT_EQ(code->values.size(), 8u);
  absl::StatusOr<motion::Motion> out = (*m)->Transfer(content, *code, motion::PostProcessMode::kNone);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);

  // The AdaIN probe needs v1's statistics code.
  EXPECT_EQ(CyclicModel::Load(o.out, CyclicOptions{0, true}).status().code(),
            absl::StatusCode::kInvalidArgument);

  // The label-conditional discriminator is checkpointed with the run.
  EXPECT_TRUE(std::filesystem::exists(o.out + "/checkpoint/pair_disc.pt"));
  CyclicTrainOptions unguided = TinyOptions(Dir("pair_gan_unguided"));
  unguided.config.pair_gan = true;
  EXPECT_EQ(TrainCyclic(unguided).code(), absl::StatusCode::kInvalidArgument);

  // A package whose shared tensors have other shapes is refused.
  CyclicTrainOptions wrong = o;
  wrong.out = Dir("style_net_wrong");
  wrong.config.hidden = 40;
  wrong.log = [](const std::string&) {};
  const absl::Status s = TrainCyclic(wrong);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("--init-from"), std::string::npos) << s;
  EXPECT_NE(s.message().find("'enc_conv.weight' has another shape"), std::string::npos) << s;
}

// --keep-weight: the same guided style-network run with a heavy
// content-keeping term moves the legs less.
TEST(CyclicModelTest, KeepWeightHoldsTheLegsToTheContent) {
  const auto leg_change = [](double keep) {
    CyclicTrainOptions o = TinyOptions(Dir(keep > 0 ? "keep_on" : "keep_off"));
    o.data = testing::LabelledClips();
    o.config.guided = true;
    o.config.style_dim = 8, o.config.blocks = 2, o.config.keep_weight = keep;
    o.config.class_weight = 3;
    EXPECT_TRUE(TrainCyclic(o).ok());
    absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
    EXPECT_TRUE(m.ok()) << m.status();
    const motion::Motion content = motion::ReadBvhFile(o.data[0]).value();
    const motion::Motion style = motion::ReadBvhFile(o.data[3]).value();
    const motion::Motion out =
        (*m)->Transfer(content, *(*m)->EncodeStyle(style), motion::PostProcessMode::kNone).value();
    const motion::HumanoidRoles roles = *motion::FindHumanoidRoles(content.skeleton);
    const auto a = motion::GlobalPositions(content), b = motion::GlobalPositions(out);
    double sum = 0;
    for (int f = 0; f < content.num_frames; ++f)
      for (int j : {roles.left_ankle, roles.right_ankle})
        sum += motion::Norm(a[f][j] - a[f][roles.pelvis] - (b[f][j] - b[f][roles.pelvis]));
    return sum / (2 * content.num_frames);
  };
  const double off = leg_change(0), on = leg_change(100);
  std::printf("ankle change: keep 0 %.3f, keep 100 %.3f\n", off, on);
  EXPECT_LT(on, 0.7 * off);
}

TEST(CyclicModelTest, ResidualOutputKeepsTheContentTheAutoencoderLoses) {
  // Restyled with its own style, a clip should come back as itself: the
  // residual output does so far more closely than the decoder-only one.
  std::map<bool, double> gap;
  const motion::Motion content = Clip(3);
  for (bool residual : {false, true}) {
    CyclicTrainOptions o = TinyOptions(Dir(residual ? "res" : "plain"));
    o.config.residual = residual;
    o.config.iterations = 100;
    ASSERT_TRUE(TrainCyclic(o).ok());
    auto m = CyclicModel::Load(o.out, CyclicOptions{0});
    ASSERT_TRUE(m.ok()) << m.status();
    const motion::Motion out = *(*m)->Transfer(content, *(*m)->EncodeStyle(content),
                                               motion::PostProcessMode::kNone);
    gap[residual] = motion::MaxPositionDifference(out, content);
    if (residual) {
      // The AdaIN probe with the clip's own code leaves the hidden features
      // as they are: the residual output is the clip itself.
      auto probe = CyclicModel::Load(o.out, CyclicOptions{0, true});
      ASSERT_TRUE(probe.ok());
      const motion::Motion same = *(*probe)->Transfer(content, *(*probe)->EncodeStyle(content),
                                                      motion::PostProcessMode::kNone);
      EXPECT_LT(motion::MaxPositionDifference(same, content), 0.05);
    }
  }
  std::printf("self-transfer max joint gap: decoder-only %.2f, residual %.2f\n", gap[false],
              gap[true]);
  EXPECT_LT(gap[true], 0.5 * gap[false]);
}

TEST(ChunkedStreamTest, StreamsEveryFrameInOrderWithAContinuousRoot) {
  CyclicTrainOptions o = TinyOptions(Dir("stream"));
  o.config.iterations = 80;
  ASSERT_TRUE(TrainCyclic(o).ok());
  auto loaded = LoadStyleModel(o.out);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const StyleModel> m = std::move(*loaded);
  const motion::Motion content = Clip(3), style = Clip(1);  // A turning walk.
  const StyleCode code = *m->EncodeStyle(style);
  auto bad = ChunkedStreamTransfer::Create(m, StyleCode{{1, 2}}, content.skeleton,
                                           content.frame_time, motion::PostProcessMode::kFull);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  auto st = ChunkedStreamTransfer::Create(m, code, content.skeleton, content.frame_time,
                                          motion::PostProcessMode::kFull, /*chunk=*/16,
                                          /*context=*/24);
  ASSERT_TRUE(st.ok()) << st.status();
  EXPECT_EQ((*st)->Finish().status().code(), absl::StatusCode::kFailedPrecondition);
  motion::Motion out = motion::RestMotion(content.skeleton, 0, content.frame_time);
  for (int f = 0; f < content.num_frames; f += 5) {  // Arrives 5 frames at a time.
    absl::StatusOr<motion::Motion> part =
        (*st)->Push(testing::Frames(content, f, std::min(f + 5, content.num_frames)));
    ASSERT_TRUE(part.ok()) << part.status();
    EXPECT_EQ((*st)->emitted() % 16, 0);
    out.values.insert(out.values.end(), part->values.begin(), part->values.end());
    out.num_frames += part->num_frames;
  }
  EXPECT_EQ(out.num_frames, 64);  // 4 full chunks; nothing left for Finish.
  absl::StatusOr<motion::Motion> rest = (*st)->Finish();
  ASSERT_TRUE(rest.ok());
  EXPECT_EQ(rest->num_frames, 0);
  EXPECT_EQ((*st)->received(), 64);
  // The root path has no jump at the chunk seams: no step is more than twice
  // the largest step of the whole-clip transfer.
  const motion::Motion whole = *m->Transfer(content, code);
  const size_t c = content.skeleton.num_channels();
  auto largest_step = [&](const motion::Motion& x) {
    double worst = 0;
    for (int f = 1; f < x.num_frames; ++f)
      worst = std::max(worst, std::hypot(x.values[f * c] - x.values[(f - 1) * c],
                                         x.values[f * c + 2] - x.values[(f - 1) * c + 2]));
    return worst;
  };
  EXPECT_LT(largest_step(out), 2 * largest_step(whole) + 1e-3);
  EXPECT_LT(motion::MaxPositionDifference(out, whole), 0.25 * motion::FindHumanoidRoles(
                                                                  content.skeleton)->leg_length);
}

TEST(CyclicConfigTest, RoundTripAndErrors) {
  CyclicConfig c = Tiny();
  c.dim = 155;
  c.use_cycle = false;
  c.style_dim = 32, c.blocks = 3, c.guided = true, c.pair_gan = true, c.content_class_weight = 3;
  c.keep_weight = 2, c.average_from = 100, c.average_every = 25;
  c.random_starts = true, c.keep_path = true, c.critics = 2, c.content_balance = 0.5;
  c.adain_skip = true, c.mirror = true, c.rotations = true;
  absl::StatusOr<CyclicConfig> back = CyclicConfig::Parse(c.Serialize(), "x");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Serialize(), c.Serialize());
  EXPECT_TRUE(back->random_starts);
  EXPECT_TRUE(back->keep_path);
  EXPECT_EQ(back->critics, 2);
  EXPECT_DOUBLE_EQ(back->content_balance, 0.5);
  EXPECT_TRUE(back->adain_skip);
  EXPECT_TRUE(back->mirror);
  EXPECT_TRUE(back->rotations);
  EXPECT_FALSE(CyclicConfig::Parse("dim = 5\n", "cfg.txt")->rotations);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\ncritics = 0\n", "cfg.txt").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nkernel = 4\n", "cfg.txt").status().message(),
            "cfg.txt:2: kernel must be odd");
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nfamily = contrastive\n", "cfg.txt").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nbogus = 1\n", "cfg.txt").status().message(),
            "cfg.txt:2: unknown key 'bogus'");
}

}  // namespace
}  // namespace stylus::model

namespace stylus::model {
namespace {

// --average-from for this family: the package holds the mean of the weights
// at iterations 100, 150 and 200 (a plain run stopped and resumed at each).
TEST(CyclicModelTest, WeightAveragingPackagesTheMeanOfTheSampledWeights) {
  const int width = Tiny().net_channels(Clip(0).skeleton.num_joints());
  const auto weights_of = [&](const std::string& dir, const CyclicConfig& config) {
    CyclicNet net(config, width);
    EXPECT_TRUE(LoadWeights(net, dir + "/weights.pt").ok()) << dir;
    return net;
  };
  CyclicTrainOptions plain = TinyOptions(Dir("average_plain"));
  std::vector<CyclicNet> sampled;
  for (int iterations : {100, 150, 200}) {
    CyclicTrainOptions o = plain;
    o.config.iterations = iterations;
    o.resume = iterations > 100;
    ASSERT_TRUE(TrainCyclic(o).ok());
    sampled.push_back(weights_of(plain.out, o.config));
  }
  CyclicTrainOptions averaged = TinyOptions(Dir("average_run"));
  averaged.config.average_from = 100, averaged.config.average_every = 50;
  ASSERT_TRUE(TrainCyclic(averaged).ok());
  const CyclicNet mean = weights_of(averaged.out, averaged.config);
  double moved = 0;
  const auto params = [](const CyclicNet& n) { return n->parameters(); };
  for (size_t i = 0; i < params(mean).size(); ++i) {
    const torch::Tensor expected =
        (params(sampled[0])[i] + params(sampled[1])[i] + params(sampled[2])[i]) / 3;
    EXPECT_TRUE(torch::allclose(params(mean)[i], expected, 1e-3, 1e-5)) << i;
    moved = std::max(moved, (params(sampled[2])[i] - expected).abs().max().item<double>());
  }
  EXPECT_GT(moved, 1e-3);  // The mean is not simply the last weights.
  CyclicTrainOptions late = TinyOptions(Dir("average_late"));
  late.config.average_from = 500;
  EXPECT_EQ(TrainCyclic(late).code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace stylus::model
