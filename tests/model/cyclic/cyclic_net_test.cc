// model/cyclic/cyclic_net: shapes, the kinematic terms and the inference-time
// optimization, the style network, on a tiny configuration.
#include "model/cyclic/cyclic_net.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "model/chunked_streamer.h"
#include "model/content_guard.h"
#include "model/cyclic/cyclic_model.h"
#include "model/family_registry.h"
#include "model/package.h"
#include "model/weights_io.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/model/cyclic/cyclic_support.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "train/cyclic_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace cyclic_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;

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
  EXPECT_LT(
      (CyclicNetImpl::AdaInSkip(h, CyclicNetImpl::SkipStats(h)) - h).abs().max().item<double>(),
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
  const double without = (plain->transform(h + shift, plain_code) - plain->transform(h, plain_code))
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

}  // namespace
}  // namespace stylus::model
