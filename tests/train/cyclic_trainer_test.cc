// train/cyclic_trainer: the label-guided stage, starting from an autoencoder,
// the content-keeping term and weight averaging, on synthesized walks.
#include "train/cyclic_trainer.h"

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
#include "model/cyclic/cyclic_net.h"
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

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace cyclic_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;

TEST(CyclicTrainerTest, GuidedGeneratorStageLearnsFromTheLabelCritic) {
  // --guided: the label critic learns real windows' labels and the
  // generator's classification loss on transfers falls.
  CyclicTrainOptions o = TinyOptions(Dir("guided"));
  o.data = testing::LabelledClips();
  o.config.guided = true;
  o.config.content_balance = 1;  // Every action drawn alike (logged).
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  std::vector<LossRow> generator;
  for (const LossRow& r : rows)
    if (r.iteration > o.config.ae_iterations + 10) generator.push_back(r);
  ASSERT_GE(generator.size(), 5u);
  std::printf("labels %.4f -> %.4f; cls %.4f -> %.4f\n", generator.front().Get("labels"),
              generator.back().Get("labels"), generator.front().Get("cls"),
              generator.back().Get("cls"));
  EXPECT_LT(generator.back().Get("labels"), 0.5 * generator.front().Get("labels"));
  EXPECT_LT(generator.back().Get("cls"), 0.8 * generator.front().Get("cls"));
  EXPECT_TRUE(std::any_of(log.begin(), log.end(), [](const std::string& l) {
    return l.rfind("content balance 1:", 0) == 0;
  }));
  for (const char* f : {"label_critic.pt", "opt_l.pt"}) {
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

TEST(CyclicTrainerTest, StyleNetworkStartsFromAnAutoencoderAndLearnsFromTheLabelCritic) {
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
    partial =
        partial || (line.find("initialized 4 of ") == 0 && line.find(ae_out) != std::string::npos);
  EXPECT_TRUE(partial);
  ASSERT_GE(rows.size(), 10u);
  // Once the critic knows the real windows' labels, the transfers' verdict
  // improves: the critic's gradient reaches the new style network.
  const auto trained = std::find_if(rows.begin(), rows.end(),
                                    [&](const LossRow& r) { return r.Get("labels") < 0.01; });
  ASSERT_NE(trained, rows.end());
  std::printf("cls %.4f (iteration %d) -> %.4f\n", trained->Get("cls"), trained->iteration,
              rows.back().Get("cls"));
  EXPECT_LT(rows.back().Get("cls"), 0.8 * trained->Get("cls"));

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  const motion::Motion content = motion::ReadBvhFile(o.data[0]).value();
  const motion::Motion style_clip = motion::ReadBvhFile(o.data[3]).value();
  absl::StatusOr<StyleCode> code = (*m)->EncodeStyle(style_clip);
  ASSERT_TRUE(code.ok()) << code.status();
  EXPECT_EQ(code->values.size(), 8u);
  absl::StatusOr<motion::Motion> out =
      MotionOf((*m)->Transfer(content, *code, motion::PostProcessMode::kNone));
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);

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
TEST(CyclicTrainerTest, KeepWeightHoldsTheLegsToTheContent) {
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
        (*m)->Transfer(content, *(*m)->EncodeStyle(style), motion::PostProcessMode::kNone)
            .value()
            .motion;
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

// --average-from for this family: the package holds the mean of the weights
// at iterations 100, 150 and 200 (a plain run stopped and resumed at each).
TEST(CyclicTrainerTest, WeightAveragingPackagesTheMeanOfTheSampledWeights) {
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
