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
  EXPECT_LT((t.windows[0] - window[0]).abs().max().item<float>(), 1e-6);
}

// A cost matrix whose cheap cells lie on a known path: the warp follows it.
torch::Tensor CostAlong(const std::vector<int>& path, int columns) {
  torch::Tensor cost = torch::full({static_cast<int64_t>(path.size()), columns}, 5.0);
  for (size_t j = 0; j < path.size(); ++j) cost[j][path[j]] = 0.0;
  return cost;
}

TEST(PairedTargetTest, WarpPathFollowsTheCheapCellsWithHoldsAndSkips) {
  // Starts mid-sequence, advances by one, holds, skips: all allowed.
  const std::vector<int> path = {3, 4, 5, 5, 7, 8, 10, 11};
  EXPECT_EQ(WarpPath(CostAlong(path, 14), 0.5), path);
  // A jump of three is not a step the warp may take: it pays for a cell
  // off the cheap path instead (one of the two between).
  const std::vector<int> jump = WarpPath(CostAlong({0, 1, 2, 5, 6, 7}, 8), 0.5);
  for (size_t j = 1; j < jump.size(); ++j) {
    EXPECT_GE(jump[j] - jump[j - 1], 0) << j;
    EXPECT_LE(jump[j] - jump[j - 1], 2) << j;
  }
  EXPECT_EQ(jump.front(), 0);
  EXPECT_EQ(jump.back(), 7);
}

TEST(PairedTargetTest, WarpPathPrefersAdvancingByOneWhenCostsTie) {
  // Every cell costs the same: any path sums to the same cost, and the
  // penalty on holds and skips makes the steady advance the cheapest.
  const std::vector<int> path = WarpPath(torch::ones({6, 10}), 0.1);
  for (size_t j = 1; j < path.size(); ++j) EXPECT_EQ(path[j] - path[j - 1], 1) << j;
}

TEST(PairedTargetTest, ReadAtTimesInterpolatesBetweenRowsAndClampsAtTheEnds) {
  // Three rows of two channels: row r holds (r, 10 r).
  const std::vector<float> rows = {0, 0, 1, 10, 2, 20};
  const torch::Tensor read = ReadAtTimes(rows.data(), 3, 2, {-1.0, 0.0, 0.25, 1.5, 2.0, 7.0});
  ASSERT_EQ(read.sizes(), (std::vector<int64_t>{2, 6}));
  const std::vector<float> want = {0, 0, 0.25, 1.5, 2, 2};
  for (int t = 0; t < 6; ++t) {
    EXPECT_FLOAT_EQ(read[0][t].item<float>(), want[t]) << t;
    EXPECT_FLOAT_EQ(read[1][t].item<float>(), 10 * want[t]) << t;
  }
}

TEST(PairedTargetTest, WarpedTimesMapEachFrameThroughThePath) {
  // Codes at half the frame rate on both sides: a path advancing one step
  // per step reads the example frame for frame from its start...
  std::vector<double> times = WarpedTimes({5, 6, 7, 8}, 8, 40, 20);
  for (int t = 0; t < 8; ++t) EXPECT_DOUBLE_EQ(times[t], 10 + t) << t;
  // ...one advancing two steps per step reads it twice as fast, and a held
  // path stays on one frame.
  times = WarpedTimes({2, 4, 6, 8}, 8, 40, 20);
  for (int t = 1; t < 8; ++t) EXPECT_DOUBLE_EQ(times[t] - times[t - 1], 2) << t;
  times = WarpedTimes({3, 3, 3, 3}, 8, 40, 20);
  for (int t = 0; t < 8; ++t) EXPECT_DOUBLE_EQ(times[t], 6.5) << t;
  // A hold in the middle is spread over its neighbours: the times still
  // rise, never fall.
  times = WarpedTimes({0, 1, 1, 2, 3, 4}, 12, 40, 20);
  for (int t = 1; t < 12; ++t) EXPECT_GE(times[t], times[t - 1]) << t;
}

TEST(PairedTargetTest, WarpedTargetIsReadFromTheExample) {
  Fixture f;
  // An example that holds one pose: whatever the warp, every frame of the
  // target is that pose, channels first like the windows.
  motion::FeatureClip still;
  still.frames = 2 * kWindow;
  still.dim = kDim;
  for (int r = 0; r < still.frames; ++r)
    for (int c = 0; c < kDim; ++c) still.values.push_back(0.5f * c - 1);
  f.data.clips.push_back(still);
  const torch::Tensor content = torch::cat({f.Window(2, 3), f.Window(2, 9), f.Window(0, 0)});
  const PairedTargets t = FindPairedTargets(f.net, f.data, {3, -1, 1},
                                            f.net->content(content), kWindow, /*warp=*/true);
  EXPECT_EQ(t.found[0].item<float>(), 1);
  EXPECT_EQ(t.found[1].item<float>(), 0);
  EXPECT_EQ(t.found[2].item<float>(), 0);  // a frame short of a window
  for (int c = 0; c < kDim; ++c)
    for (int frame = 0; frame < kWindow; ++frame)
      EXPECT_FLOAT_EQ(t.windows[0][c][frame].item<float>(), 0.5f * c - 1) << c << " " << frame;
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
