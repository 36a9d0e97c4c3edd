// Shapes and losses of the contrastive networks on a tiny configuration.
#include "model/contrastive/contrastive_net.h"

#include "gtest/gtest.h"
#include "model/window_tensor.h"

namespace stylus::model {
namespace {

ContrastiveConfig Tiny() {
  ContrastiveConfig c;
  c.dim = 10;
  c.channels = 8;
  c.window = 16;
  return c;
}

TEST(ContrastiveNetTest, Shapes) {
  torch::manual_seed(0);
  const ContrastiveConfig c = Tiny();
  ContrastiveNet net(c);
  Discriminator disc(c);
  const torch::Tensor x = torch::randn({3, c.dim, c.window});
  const torch::Tensor content = net->content(x), style = net->style(x);
  EXPECT_EQ(content.sizes(), (std::vector<int64_t>{3, c.channels, c.window / 2}));
  EXPECT_EQ(style.sizes(), (std::vector<int64_t>{3, c.channels}));
  EXPECT_EQ(net->decode(content, style).sizes(), x.sizes());
  EXPECT_EQ(disc->forward(x).sizes(), (std::vector<int64_t>{3}));
}

TEST(ContrastiveNetTest, StyleChangesTheOutputContentCodeIgnoresScale) {
  torch::manual_seed(1);
  ContrastiveNet net(Tiny());
  const torch::Tensor x = torch::randn({2, 10, 16});
  const torch::Tensor c = net->content(x);
  const torch::Tensor a = net->decode(c, torch::zeros({2, 8})),
                      b = net->decode(c, torch::ones({2, 8}));
  EXPECT_GT((a - b).abs().max().item<float>(), 1e-3);
}

TEST(ContrastiveNetTest, ReconstructionLossIsMeanAbsoluteError) {
  const torch::Tensor a = torch::zeros({1, 2, 2}),
                      b = torch::tensor({1.f, -1.f, 2.f, 0.f}).reshape({1, 2, 2});
  EXPECT_FLOAT_EQ(ReconstructionLoss(a, b).item<float>(), 1.0f);
  EXPECT_FLOAT_EQ(ReconstructionLoss(b, b).item<float>(), 0.0f);
}

TEST(ContrastiveNetTest, NceLossRewardsMatchingTimeSteps) {
  torch::manual_seed(2);
  const torch::Tensor target = torch::randn({4, 8, 6});
  const torch::Tensor w = torch::eye(8);
  const double aligned = NceLoss(target, target, w, 0.1).item<double>();
  const double shuffled = NceLoss(target.roll(1, 2), target, w, 0.1).item<double>();
  EXPECT_LT(aligned, 0.5);
  EXPECT_GT(shuffled, aligned + 1.0);
  // Uniform logits give log(L).
  EXPECT_NEAR(NceLoss(target, target, torch::zeros({8, 8}), 0.1).item<double>(), std::log(6.0),
              1e-5);
}

TEST(ContrastiveNetTest, TripletLossHingesOnTheMargin) {
  const torch::Tensor a = torch::tensor({{1.f, 0.f}}), p = torch::tensor({{1.f, 0.f}});
  const torch::Tensor n = torch::tensor({{-1.f, 0.f}}), n_close = torch::tensor({{0.f, 1.f}});
  EXPECT_FLOAT_EQ(TripletLoss(a, p, n, 1.0).item<float>(), 0.f);  // d_ap 0, d_an 2.
  EXPECT_NEAR(TripletLoss(a, p, n_close, 1.5).item<float>(), 1.5 - std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(TripletLoss(a, n, p, 1.0).item<float>(), 3.f, 1e-6);  // Swapped: 2 - 0 + 1.
}

TEST(ContrastiveNetTest, GanLossesAreNonSaturating) {
  const torch::Tensor confident_real = torch::full({4}, 10.f),
                      confident_fake = torch::full({4}, -10.f);
  EXPECT_LT(DiscriminatorGanLoss(confident_real, confident_fake).item<float>(), 1e-3);
  EXPECT_GT(GeneratorGanLoss(confident_fake).item<float>(), 9.f);  // Strong gradient when D wins.
  EXPECT_NEAR(GeneratorGanLoss(torch::zeros({4})).item<float>(), std::log(2.0), 1e-6);
}

TEST(SmoothOverTimeTest, KeepsSlowMotionAndRemovesShake) {
  const torch::Tensor t = torch::arange(32, torch::kFloat32);
  const torch::Tensor ramp = (t * 0.1).view({1, 1, 32});
  const torch::Tensor shake =
      torch::where(t.remainder(2) == 0, torch::ones({32}), -torch::ones({32}));
  const torch::Tensor x =
      torch::cat({ramp, shake.view({1, 1, 32}), torch::full({1, 1, 32}, 3.0)}, 1);
  const torch::Tensor y = SmoothOverTime(x, 1.5);
  ASSERT_EQ(y.sizes(), x.sizes());
  // A ramp is kept away from the edges, a constant everywhere; the
  // frame-to-frame alternation all but vanishes.
  EXPECT_LT((y[0][0].slice(0, 5, 27) - x[0][0].slice(0, 5, 27)).abs().max().item<float>(), 1e-4);
  EXPECT_LT((y[0][2] - 3).abs().max().item<float>(), 1e-5);
  EXPECT_LT(y[0][1].slice(0, 5, 27).abs().max().item<float>(), 0.02);
  EXPECT_TRUE(SmoothOverTime(x, 0).equal(x));
}

TEST(FrameChangesTest, GivesEachChannelsChangeFromTheFrameBefore) {
  const torch::Tensor x = torch::arange(0, 12, torch::kFloat).pow(2).reshape({1, 2, 6});
  const torch::Tensor d = FrameChanges(x);
  ASSERT_EQ(d.sizes(), x.sizes());
  for (int c = 0; c < 2; ++c) {
    for (int t = 1; t < 6; ++t) {
      EXPECT_FLOAT_EQ(d[0][c][t].item<float>(),
                      kFrameChangeScale * (x[0][c][t] - x[0][c][t - 1]).item<float>());
    }
    EXPECT_FLOAT_EQ(d[0][c][0].item<float>(), d[0][c][1].item<float>());
  }
}

TEST(ContrastiveNetTest, StyleFromMotionGivesAStillClipOneCodeWhateverItsPose) {
  torch::manual_seed(2);
  ContrastiveConfig c = Tiny();
  c.style_from_motion = true;
  ContrastiveNet net(c);
  // Two clips frozen in different poses, and one that moves.
  const torch::Tensor pose_a = torch::randn({1, 10, 1}), pose_b = torch::randn({1, 10, 1});
  const torch::Tensor still_a = pose_a.expand({1, 10, 16}).contiguous();
  const torch::Tensor still_b = pose_b.expand({1, 10, 16}).contiguous();
  const torch::Tensor moving = still_a + 0.3 * torch::randn({1, 10, 16});
  const torch::Tensor a = net->style(still_a), b = net->style(still_b), m = net->style(moving);
  EXPECT_LT((a - b).abs().max().item<float>(), 1e-6);
  EXPECT_GT((a - m).abs().max().item<float>(), 1e-3);
  // Without the option the frozen poses differ.
  c.style_from_motion = false;
  torch::manual_seed(2);
  ContrastiveNet pose_net(c);
  EXPECT_GT((pose_net->style(still_a) - pose_net->style(still_b)).abs().max().item<float>(), 1e-3);
}

TEST(ContrastiveNetTest, TheBottleneckKeepsTheCodesShapeAndSaysLessOfTheClip) {
  torch::manual_seed(3);
  ContrastiveConfig c = Tiny();
  c.channels = 16, c.bottleneck_channels = 2, c.bottleneck_pool = 4;
  ContrastiveNet net(c);
  ASSERT_TRUE(net->bottleneck);
  const torch::Tensor x = torch::randn({3, c.dim, c.window});
  const torch::Tensor code = net->content(x);
  ASSERT_EQ(code.sizes(), (std::vector<int64_t>{3, c.channels, c.window / 2}));
  EXPECT_EQ(net->decode(code, net->style(x)).sizes(), x.sizes());
  // Every step of the widened code is the same linear map of k numbers: a
  // code of 16 channels spans only k = 2 dimensions.
  const torch::Tensor steps = code.permute({0, 2, 1}).reshape({-1, c.channels});
  const torch::Tensor centred = steps - steps.mean(0, true);
  const torch::Tensor sv = torch::linalg_svdvals(centred);
  EXPECT_GT(sv[1].item<float>(), 1e-3);
  EXPECT_LT(sv[2].item<float>(), 1e-4 * sv[0].item<float>());
  // Pooled over 4 of the 8 steps, the code varies slowly: one window's
  // largest step-to-step change is well under that of the unpooled code.
  c.bottleneck_pool = 1;
  torch::manual_seed(3);
  ContrastiveNet unpooled(c);
  const auto jump = [](const torch::Tensor& t) {
    return (t.slice(2, 1, t.size(2)) - t.slice(2, 0, t.size(2) - 1)).abs().mean().item<float>();
  };
  EXPECT_LT(jump(code), 0.7 * jump(unpooled->content(x)));
  // Without the key there is no bottleneck module (older packages load as before).
  EXPECT_FALSE(ContrastiveNet(Tiny())->bottleneck);
}

TEST(ContrastiveNetTest, AFreshStyleFilterPassesTheGeneratorThroughThenFiltersByStyle) {
  ContrastiveConfig c = Tiny();
  c.style_filter_taps = 5;
  torch::manual_seed(4);
  ContrastiveNet plain(Tiny());
  ContrastiveNet filtered(c);
  ASSERT_TRUE(filtered->generator->filter);
  EXPECT_FALSE(plain->generator->filter);  // Off without the key.
  // The same weights but the filter's: a fresh filter changes nothing.
  {
    torch::NoGradGuard no_grad;
    auto mine = filtered->named_parameters();
    for (const auto& p : plain->named_parameters()) mine[p.key()].copy_(p.value());
  }
  const torch::Tensor x = torch::randn({2, c.dim, c.window});
  const torch::Tensor code = plain->content(x), style = plain->style(x);
  EXPECT_TRUE(torch::allclose(plain->decode(code, style), filtered->decode(code, style)));
  // A kernel that the style code chooses: two codes now filter the same
  // content differently over time.
  {
    torch::NoGradGuard no_grad;
    filtered->generator->filter->kernels->weight.normal_(0, 0.3);
  }
  const torch::Tensor a = filtered->decode(code, torch::zeros_like(style)),
                      b = filtered->decode(code, style);
  const torch::Tensor a_plain = plain->decode(code, torch::zeros_like(style)),
                      b_plain = plain->decode(code, style);
  EXPECT_GT(((a - b) - (a_plain - b_plain)).abs().max().item<float>(), 1e-3);
  EXPECT_EQ(a.sizes(), x.sizes());
}

}  // namespace
}  // namespace stylus::model
