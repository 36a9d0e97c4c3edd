// Training, packaging and inference of a tiny contrastive model on synthesized
// clips (no dataset needed; runs in seconds).
#include "model/contrastive/contrastive_model.h"

#include <filesystem>
#include <fstream>
#include <thread>

#include "gtest/gtest.h"
#include "model/content_guard.h"
#include "model/pass_batcher.h"
#include "model/window_tensor.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/synth.h"
#include "tests/model/contrastive/contrastive_support.h"
#include "tests/model/synth_clips.h"
#include "tests/model/transfer_support.h"
#include "train/contrastive_trainer.h"
#include "train/guard_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;
using testing::FourClips;

TEST(ContrastiveModelTest, TinyModelOverfitsFourClips) {
  // Without the adversarial term (whose game need not settle in 300 steps),
  // the reconstruction of four clips must fall well below where it starts.
  ContrastiveTrainOptions o = TinyOptions(Dir("overfit"), 300);
  o.config.alpha = 0;
  std::vector<LossRecord> curve;
  o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
  ASSERT_TRUE(TrainContrastive(o).ok());
  ASSERT_EQ(curve.size(), 30u);
  for (const auto& r : curve)
    std::printf("%d rec %.4f gan %.4f nce %.4f tri %.4f\n", r.iteration, r.rec, r.gan, r.nce,
                r.tri);
  EXPECT_LT(curve.back().rec, 0.5 * curve.front().rec)
      << curve.front().rec << " -> " << curve.back().rec;
  for (const char* f : {"config.txt", "norm.txt", "skeleton.bvh", "weights.pt", "loss.csv"}) {
    EXPECT_TRUE(fs::exists(o.out + "/" + f)) << f;
  }
}

TEST(ContrastiveModelTest, TrainingIsDeterministicAndResumable) {
  // Two runs with one seed agree; a run killed at its checkpoint and resumed
  // ends where an uninterrupted run ends.
  std::vector<LossRecord> a, b, c;
  ContrastiveTrainOptions oa = TinyOptions(Dir("det_a"), 80);
  oa.on_record = [&](const LossRecord& r) { a.push_back(r); };
  ASSERT_TRUE(TrainContrastive(oa).ok());
  ContrastiveTrainOptions ob = TinyOptions(Dir("det_b"), 40);
  ob.on_record = [&](const LossRecord& r) { b.push_back(r); };
  ASSERT_TRUE(TrainContrastive(ob).ok());
  for (size_t i = 0; i < b.size(); ++i) EXPECT_DOUBLE_EQ(a[i].total, b[i].total) << i;
  ContrastiveTrainOptions oc = TinyOptions(ob.out, 80);
  oc.resume = true;
  oc.on_record = [&](const LossRecord& r) { c.push_back(r); };
  ASSERT_TRUE(TrainContrastive(oc).ok());
  ASSERT_EQ(c.size(), 4u);
  EXPECT_NEAR(c.back().total, a.back().total, 1e-4 * std::fabs(a.back().total));
  // Resuming with another configuration is refused.
  ContrastiveTrainOptions od = TinyOptions(ob.out, 120);
  od.config.channels = 8;
  od.resume = true;
  EXPECT_EQ(TrainContrastive(od).code(), absl::StatusCode::kFailedPrecondition);
}

TEST_F(TrainedModelTest, TransferKeepsLayoutAndLengthForAnyLength) {
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(*dir_);
  ASSERT_TRUE(m.ok()) << m.status();
  const StyleCode style = *(*m)->EncodeStyle(Clip(1));
  EXPECT_EQ(style.values.size(), 16u);
  for (int frames : {5, 16, 17, 64, 101}) {
    const motion::Motion content =
        *motion::Synthesize(*motion::ParseSynthStyle("normal,frames=" + std::to_string(frames)));
    absl::StatusOr<motion::Motion> out = MotionOf((*m)->Transfer(content, style));
    ASSERT_TRUE(out.ok()) << out.status();
    EXPECT_EQ(out->num_frames, frames);
    EXPECT_TRUE(out->skeleton.SameTopology(content.skeleton));
    EXPECT_TRUE(motion::ParseBvh(motion::FormatBvh(*out), "out").ok());
  }
}

TEST_F(TrainedModelTest, SaveLoadGivesIdenticalOutputs) {
  auto a = *ContrastiveModel::Load(*dir_);
  auto b = *ContrastiveModel::Load(*dir_);
  const motion::Motion out_a = a->Transfer(Clip(0), *a->EncodeStyle(Clip(2)))->motion;
  const motion::Motion out_b = b->Transfer(Clip(0), *b->EncodeStyle(Clip(2)))->motion;
  EXPECT_EQ(out_a.values, out_b.values);
}

TEST_F(TrainedModelTest, ConcurrentTransfersBatchedEqualTransfersRunAlone) {
  auto m = *ContrastiveModel::Load(*dir_);
  const StyleCode style = *m->EncodeStyle(Clip(1));
  const std::vector<motion::Motion> contents = {Clip(0), Clip(2), Clip(3)};
  std::vector<motion::Motion> alone;
  for (const motion::Motion& c : contents) alone.push_back(m->Transfer(c, style)->motion);
  // A long delay: each pass waits for the other calls' (the limit is far).
  PassBatcher batcher(/*max_rows=*/1000, std::chrono::milliseconds(500));
  std::vector<motion::Motion> batched(contents.size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < contents.size(); ++i) {
    threads.emplace_back([&, i] {
      TransferOptions options;
      options.batcher = &batcher;
      absl::StatusOr<TransferResult> r = m->Transfer(contents[i], style, options);
      ASSERT_TRUE(r.ok()) << r.status();
      batched[i] = r->motion;
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_GT(batcher.calls(), batcher.batches()) << "passes held several calls";
  for (size_t i = 0; i < contents.size(); ++i) {
    ASSERT_EQ(batched[i].num_frames, alone[i].num_frames);
    EXPECT_LT(motion::MaxPositionDifference(batched[i], alone[i]), 1e-3) << "clip " << i;
  }
}

TEST_F(TrainedModelTest, InterpolationEndpointsEqualTransfer) {
  auto m = *ContrastiveModel::Load(*dir_);
  const StyleCode a = *m->EncodeStyle(Clip(1)), b = *m->EncodeStyle(Clip(2));
  const motion::Motion content = Clip(0);
  const motion::Motion ta = m->Transfer(content, a)->motion, tb = m->Transfer(content, b)->motion;
  const motion::Motion w0 = m->Interpolate(content, {a, b}, {{1.0, 0.0}, {}})->motion;
  const motion::Motion w1 = m->Interpolate(content, {a, b}, {{0.0, 1.0}, {}})->motion;
  EXPECT_LT(motion::MaxPositionDifference(w0, ta), 1e-4);
  EXPECT_LT(motion::MaxPositionDifference(w1, tb), 1e-4);
  EXPECT_GT(motion::MaxPositionDifference(ta, tb), 1e-3);  // The styles differ.
  // A per-frame schedule that holds style A matches transfer with A.
  StyleWeights hold_a;
  hold_a.per_frame.assign(content.num_frames, {1.0, 0.0});
  EXPECT_LT(motion::MaxPositionDifference(m->Interpolate(content, {a, b}, hold_a)->motion, ta),
            1e-4);
  // Bad schedules are errors.
  StyleWeights short_schedule;
  short_schedule.per_frame.assign(3, {1.0, 0.0});
  EXPECT_EQ(m->Interpolate(content, {a, b}, short_schedule).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(m->Interpolate(content, {a, b}, {{1.0}, {}}).ok());
}

// style_strength (config.txt): 0 restyles the content with its own windows'
// style whatever is asked; 0.5 lies between that and the full transfer.
TEST_F(TrainedModelTest, StyleStrengthMovesFromTheContentsOwnStyle) {
  auto full = *ContrastiveModel::Load(*dir_);
  const std::string weak = Dir("weak_style");
  fs::copy(*dir_, weak, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  auto with_strength = [&](double k) {
    std::ofstream(weak + "/config.txt", std::ios::app) << "style_strength = " << k << "\n";
    return *ContrastiveModel::Load(weak);
  };
  const auto none = with_strength(0);
  const StyleCode a = *full->EncodeStyle(Clip(1)), b = *full->EncodeStyle(Clip(2));
  const motion::Motion content = Clip(0);
  EXPECT_LT(motion::MaxPositionDifference(none->Transfer(content, a)->motion,
                                          none->Transfer(content, b)->motion),
            1e-4);
  const auto half = with_strength(0.5);  // The later key wins.
  const motion::Motion target = full->Transfer(content, a)->motion,
                       own = none->Transfer(content, a)->motion,
                       mid = half->Transfer(content, a)->motion;
  EXPECT_GT(motion::MaxPositionDifference(target, own), 1e-3);
  EXPECT_LT(motion::MaxPositionDifference(mid, target), motion::MaxPositionDifference(own, target));
  EXPECT_LT(motion::MaxPositionDifference(mid, own), motion::MaxPositionDifference(target, own));
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\nstyle_strength = 1.5\n", "c.txt").ok());
}

// residual (config.txt): the content window plus the change the style makes
// in the generator's output. With style_strength 0 that change is nothing, so
// the content comes back as it was, which the plain generator cannot do.
TEST_F(TrainedModelTest, ResidualTransferKeepsWhatTheGeneratorLoses) {
  auto plain = *ContrastiveModel::Load(*dir_);
  const std::string dir = Dir("residual");
  fs::copy(*dir_, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::ofstream(dir + "/config.txt", std::ios::app) << "residual = 1\n";
  const auto residual = *ContrastiveModel::Load(dir);
  std::ofstream(dir + "/config.txt", std::ios::app) << "style_strength = 0\n";
  const auto own = *ContrastiveModel::Load(dir);
  const motion::Motion content = Clip(0);
  const StyleCode a = *plain->EncodeStyle(Clip(1));
  auto off = [&](const ContrastiveModel& m) {
    return motion::MaxPositionDifference(
        m.Transfer(content, a, motion::PostProcessMode::kNone)->motion, content);
  };
  EXPECT_LT(off(*own), 1e-3);
  EXPECT_GT(off(*plain), 100 * off(*own));
  EXPECT_GT(off(*residual), 1e-3);  // A real style change remains.
}

// content_detail (config.txt): each generated window's pose channels gain k
// times the content window's detail, what the Gaussian of detail_sigma
// frames takes out of it; the root path and contacts are left alone.
TEST_F(TrainedModelTest, ContentDetailAddsTheContentsQuickMotion) {
  const std::string dir = Dir("detail");
  fs::copy(*dir_, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::ofstream(dir + "/config.txt", std::ios::app) << "smooth_sigma = 2\n";
  const auto plain = *ContrastiveModel::Load(dir);
  std::ofstream(dir + "/config.txt", std::ios::app) << "content_detail = 0.5\ndetail_sigma = 3\n";
  const auto detailed = *ContrastiveModel::Load(dir);
  EXPECT_DOUBLE_EQ(detailed->config().content_detail, 0.5);

  // A walk with a quick 5-frame shake on every channel.
  motion::FeatureClip f = *plain->NormalizedFeatures(Clip(0), "content");
  for (int t = 0; t < f.frames; ++t) {
    for (int c = 0; c < f.dim; ++c) f.row(t)[c] += (t % 5 == 0 ? 0.8f : -0.2f);
  }
  const int window = plain->config().window;
  const std::vector<int> starts = {0, 10};
  const StyleCode a = *plain->EncodeStyle(Clip(1));
  const std::vector<float> y0 = *plain->GenerateWindows(f, starts, {a, a});
  const std::vector<float> y1 = *detailed->GenerateWindows(f, starts, {a, a});
  const torch::Tensor x = WindowTensor(f, starts, window);
  const torch::Tensor want = 0.5 * (x - SmoothOverTime(x, 3));
  const torch::Tensor got =
      torch::from_blob(const_cast<float*>(y1.data()), x.sizes(), torch::kFloat32) -
      torch::from_blob(const_cast<float*>(y0.data()), x.sizes(), torch::kFloat32);
  const int64_t path = f.dim - motion::FeatureLayout::kPathChannels;
  EXPECT_LT((got.slice(1, 0, path) - want.slice(1, 0, path)).abs().max().item<double>(), 1e-4);
  EXPECT_GT(want.slice(1, 0, path).abs().max().item<double>(), 0.3);  // The shake is there.
  EXPECT_LT(got.slice(1, path).abs().max().item<double>(), 1e-6);

  // The smoothing takes the shake out of the transfer; the detail puts it back.
  auto shake = [&](const std::vector<float>& y) {
    const torch::Tensor t =
        torch::from_blob(const_cast<float*>(y.data()), x.sizes(), torch::kFloat32)
            .slice(1, 0, path);
    return (t - SmoothOverTime(t, 3)).abs().mean().item<double>();
  };
  EXPECT_GT(shake(y1), 3 * shake(y0)) << shake(y0) << " vs " << shake(y1);

  // Whole clips transfer, and the options that cannot go together are refused.
  EXPECT_TRUE(detailed->Transfer(Clip(0), a).ok());
  for (const char* bad :
       {"dim = 10\ncontent_detail = 1.5\nsmooth_sigma = 3\n", "dim = 10\ncontent_detail = 0.5\n",
        "dim = 10\ncontent_detail = 0.5\nsmooth_sigma = 3\nresidual = 1\n"}) {
    EXPECT_FALSE(ContrastiveConfig::Parse(bad, "c.txt").ok()) << bad;
  }
  EXPECT_TRUE(
      ContrastiveConfig::Parse("dim = 10\ncontent_detail = 0.5\ndetail_sigma = 2\n", "c.txt").ok());
}

TEST_F(TrainedModelTest, RejectsClipsTheModelCannotTake) {
  auto m = *ContrastiveModel::Load(*dir_);
  motion::Motion fast = Clip(0);
  fast.frame_time = 1.0 / 300;  // Rates from 24 to 240 Hz are resampled; this one is not.
  const absl::Status s = m->EncodeStyle(fast).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("300 fps"), std::string::npos) << s;
  fast.frame_time = 1.0 / 120;
  EXPECT_TRUE(m->EncodeStyle(fast).ok());
  motion::Motion nan = Clip(0);
  nan.values[40] = std::nan("");
  EXPECT_NE(m->EncodeStyle(nan).status().message().find("not a finite number"), std::string::npos);
  const motion::Motion other = *motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) +
                                                    "/tests/fixtures/bvh/good/three_joint.bvh");
  EXPECT_NE(m->EncodeStyle(other).status().message().find(
                "style clip is on another rig than the model's: not a humanoid rig"),
            std::string::npos);
}

TEST_F(TrainedModelTest, CorruptOrMissingFilesAreClearErrors) {
  const std::string copy = Dir("corrupt");
  fs::copy(*dir_, copy, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  {  // Truncate the weights.
    std::ofstream w(copy + "/weights.pt", std::ios::trunc | std::ios::binary);
    w << "not a torch archive";
  }
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(copy);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(m.status().message().find("weights.pt: cannot load weights"), std::string::npos)
      << m.status();
  fs::remove(copy + "/norm.txt");
  EXPECT_EQ(ContrastiveModel::Load(copy).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(ContrastiveModel::Load("/no/such/model").status().code(), absl::StatusCode::kNotFound);
  // Weights of another width.
  const std::string other = Dir("other");
  fs::copy(*dir_, other, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::ifstream in(other + "/config.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text.replace(text.find("channels = 16"), 13, "channels = 12");
  std::ofstream(other + "/config.txt", std::ios::trunc) << text;
  EXPECT_EQ(ContrastiveModel::Load(other).status().code(), absl::StatusCode::kInvalidArgument);
}

// Appends `text` to the package's config.txt.
}  // namespace
}  // namespace stylus::model
