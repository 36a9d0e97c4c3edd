// train/paired_target: the real example of a transfer (the content's action
// in the target style) found by content code, and the term's distance.
#include "train/paired_target.h"

#include <random>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_config.h"

namespace stylus::model {
namespace {

constexpr int kDim = 12, kWindow = 16;

motion::FeatureClip RandomClip(int frames, std::mt19937* rng) {
  std::normal_distribution<float> normal;
  motion::FeatureClip clip;
  clip.frames = frames;
  clip.dim = kDim;
  for (int i = 0; i < frames * kDim; ++i) clip.values.push_back(normal(*rng));
  return clip;
}

struct Fixture {
  Fixture() {
    ContrastiveConfig c;
    c.dim = kDim;
    c.channels = 8;
    c.window = kWindow;
    c.hop = 8;
    net = ContrastiveNet(c);
    std::mt19937 rng(5);
    data.norm.mean.assign(kDim, 0);
    data.norm.std.assign(kDim, 1);
    data.clips = {RandomClip(kWindow, &rng), RandomClip(kWindow - 1, &rng),
                  RandomClip(3 * kWindow, &rng)};
  }
  // (1, dim, frames) of clip `c` from frame `start`.
  torch::Tensor Window(int c, int start) const {
    const motion::FeatureClip& clip = data.clips[c];
    torch::Tensor all = torch::from_blob(const_cast<float*>(clip.values.data()),
                                         {clip.frames, kDim}, torch::kFloat32)
                            .t();
    return all.slice(1, start, start + kWindow).unsqueeze(0).contiguous();
  }
  ContrastiveNet net{nullptr};
  TrainingSet data;
};

TEST(PairedTargetTest, FindsAWindowOfEachExampleLongEnough) {
  Fixture f;
  // Four content windows; their examples: a clip exactly a window long,
  // none, a clip a frame short of a window, and a long clip.
  const torch::Tensor content = torch::cat({f.Window(2, 5), f.Window(2, 20), f.Window(0, 0),
                                            f.Window(2, 32)});
  const torch::Tensor codes = f.net->content(content);
  const PairedTargets t = FindPairedTargets(f.net, f.data, {0, -1, 1, 2}, codes, kWindow);
  ASSERT_EQ(t.windows.sizes(), (std::vector<int64_t>{4, kDim, kWindow}));
  EXPECT_EQ(t.found[0].item<float>(), 1);
  EXPECT_EQ(t.found[1].item<float>(), 0);
  EXPECT_EQ(t.found[2].item<float>(), 0);
  EXPECT_EQ(t.found[3].item<float>(), 1);
  // The only window of a window-long clip is the clip.
  EXPECT_TRUE(torch::equal(t.windows[0], f.Window(0, 0)[0]));
  EXPECT_EQ(t.windows[1].abs().sum().item<float>(), 0);
  // The long clip's target is one of its windows, at a whole frame offset.
  bool is_a_window = false;
  for (int start = 0; start + kWindow <= 3 * kWindow; ++start)
    is_a_window = is_a_window || torch::equal(t.windows[3], f.Window(2, start)[0]);
  EXPECT_TRUE(is_a_window);
}

TEST(PairedTargetTest, NearestCodeWinsWhenTheExampleRepeatsTheContent) {
  Fixture f;
  // The example is the content window itself, three times over: every
  // placement on a copy of it matches, so the target is that window.
  const torch::Tensor window = f.Window(0, 0);
  motion::FeatureClip tripled;
  tripled.frames = 3 * kWindow;
  tripled.dim = kDim;
  for (int k = 0; k < 3; ++k)
    tripled.values.insert(tripled.values.end(), f.data.clips[0].values.begin(),
                          f.data.clips[0].values.end());
  f.data.clips.push_back(tripled);
  const PairedTargets t =
      FindPairedTargets(f.net, f.data, {3}, f.net->content(window), kWindow);
  ASSERT_EQ(t.found[0].item<float>(), 1);
  // The window itself is a placement at distance 0: the target's code is the
  // content's (the fixture's untrained network may give another placement
  // the same code to within rounding, so the code is what is compared).
  const torch::Tensor target = t.windows[0].unsqueeze(0);
  EXPECT_LT((f.net->content(target) - f.net->content(window)).abs().max().item<float>(), 1e-5);
}

TEST(PairedTargetTest, LossCountsOnlyTheChannelsAndWindowsThatHaveATarget) {
  PairedTargets t{torch::zeros({2, kDim, kWindow}), torch::tensor({1.f, 0.f})};
  torch::Tensor channels = torch::zeros({1, kDim, 1});
  channels.slice(1, 0, 4).fill_(1);
  EXPECT_EQ(PairedLoss(t.windows, t, channels).item<float>(), 0);
  // Off by 2 on the counted channels of the window with a target, by 7
  // elsewhere: the mean over what counts is 2.
  torch::Tensor transfer = torch::full({2, kDim, kWindow}, 7.f);
  transfer[0].slice(0, 0, 4).fill_(2);
  EXPECT_FLOAT_EQ(PairedLoss(transfer, t, channels).item<float>(), 2);
  const PairedTargets none{t.windows, torch::zeros({2})};
  EXPECT_EQ(PairedLoss(transfer, none, channels).item<float>(), 0);
}

}  // namespace
}  // namespace stylus::model
