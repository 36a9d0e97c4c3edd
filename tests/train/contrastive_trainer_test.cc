// train/contrastive_trainer: label-guided training of the contrastive family
// (the critic, residual training, resume, fine-tuning, weight averaging, the
// error for clips without labelled names). Synthesized clips; runs in seconds.
#include "train/contrastive_trainer.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "model/contrastive/contrastive_net.h"
#include "model/guard_net.h"
#include "model/weights_io.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/normalization.h"
#include "motion/windowing.h"
#include "tests/model/synth_clips.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "tests/train/contrastive_training_support.h"
#include "train/clip_classes.h"
#include "train/label_critic.h"
#include "train/pair_discriminator.h"
#include "train/training_set.h"
#include "train/weight_average.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;
using testing::LabelledClips;

// `o` with its labels turned off: training is refused, naming --guided.
void ExpectRefusedWithoutGuided(ContrastiveTrainOptions o) {
  o.config.guided = false;
  const absl::Status s = TrainContrastive(o);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--guided"), std::string::npos) << s;
}

TEST(ContrastiveTrainerTest, CriticLearnsTheLabelsAndTransfersFollowIt) {
  ContrastiveTrainOptions o = GuidedOptions(testing::FreshDir("guided_learn"), 200);
  o.config.alpha = 0;
  std::vector<LossRecord> curve;
  o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
  ASSERT_TRUE(TrainContrastive(o).ok());
  ASSERT_EQ(curve.size(), 20u);
  for (const LossRecord& r : curve)
    std::printf("%d rec %.4f cls %.4f cyc %.4f critic %.4f\n", r.iteration, r.rec, r.cls, r.cyc,
                r.critic);
  // The critic separates real windows' labels; transfers are pushed towards
  // the target style and the content input's content; the reconstruction
  // from another clip's style code and the cycle are learnt. The run's last
  // rows are averaged: 200 iterations on four clips still jump from row to
  // row (seeds 1-5: cls 0.25-0.60 of its first row, rec and cyc 0.70-0.79).
  EXPECT_LT(curve.back().critic, 0.3 * curve.front().critic);
  EXPECT_LT(MeanOfLastRows(curve, &LossRecord::cls), 0.7 * curve.front().cls);
  EXPECT_LT(MeanOfLastRows(curve, &LossRecord::rec), 0.85 * curve.front().rec);
  EXPECT_LT(MeanOfLastRows(curve, &LossRecord::cyc), 0.85 * curve.front().cyc);
  // The package is an ordinary contrastive package: it loads and transfers.
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_TRUE((*m)->config().guided);
  const motion::Motion content = *motion::ReadBvhFile(LabelledClips()[0]);
  const motion::Motion style = *motion::ReadBvhFile(LabelledClips()[3]);
  absl::StatusOr<motion::Motion> out = MotionOf((*m)->Transfer(content, *(*m)->EncodeStyle(style)));
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);

  // keep_path: the transfer walks the content's root path (pelvis on the
  // floor), which the generated trajectory of a briefly trained model does not.
  const std::string kept = testing::FreshDir("guided_keep_path");
  fs::copy(o.out, kept, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::ofstream(kept + "/config.txt", std::ios::app) << "keep_path = 1\n";
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> k = ContrastiveModel::Load(kept);
  ASSERT_TRUE(k.ok()) << k.status();
  ASSERT_TRUE((*k)->config().keep_path);
  absl::StatusOr<motion::Motion> on_path =
      MotionOf((*k)->Transfer(content, *(*k)->EncodeStyle(style)));
  ASSERT_TRUE(on_path.ok()) << on_path.status();
  auto path_error = [&](const motion::Motion& m) {
    return motion::TrajectoryError(m, content, (*k)->data().roles);
  };
  std::printf("root path error: free %.3f, kept %.3f\n", path_error(*out), path_error(*on_path));
  // What remains of the error is the generated body's facing, which turns
  // the kept velocities a little; how much depends on the weights' last
  // digits (under 0.5 units where this test was written, 0.65 on another
  // machine), so the bound is loose and the comparison with the free path is the check.
  EXPECT_LT(path_error(*on_path), 2.0);
  EXPECT_GT(path_error(*out), 20 * path_error(*on_path));

  // smooth_sigma: the same transfer without the generator's frame-to-frame
  // shake (the mean jerk falls), the same length and path.
  std::ofstream(kept + "/config.txt", std::ios::app) << "smooth_sigma = 2\n";
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> sm = ContrastiveModel::Load(kept);
  ASSERT_TRUE(sm.ok()) << sm.status();
  absl::StatusOr<motion::Motion> smooth =
      MotionOf((*sm)->Transfer(content, *(*sm)->EncodeStyle(style)));
  ASSERT_TRUE(smooth.ok()) << smooth.status();
  EXPECT_EQ(smooth->num_frames, content.num_frames);
  std::printf("jitter: raw %.1f, smoothed %.1f\n", motion::Jitter(*on_path),
              motion::Jitter(*smooth));
  EXPECT_LT(motion::Jitter(*smooth), 0.7 * motion::Jitter(*on_path));
  EXPECT_LT(path_error(*smooth), 2.0);
}

// --residual: transfers are trained as the content window plus the change
// the style makes, and the package transfers in that form. Restyled with
// its own style the clip comes back far closer than from the same run
// trained in the plain form; the critic's verdict on the transfers is
// still learnt, and another style still changes the clip.
TEST(ContrastiveTrainerTest, ResidualTrainingKeepsTheClipAndStillRestyles) {
  const motion::Motion clip = *motion::ReadBvhFile(LabelledClips()[0]);
  const motion::Motion other = *motion::ReadBvhFile(LabelledClips()[3]);
  std::map<bool, double> self_gap, other_gap;
  for (bool residual : {false, true}) {
    ContrastiveTrainOptions o =
        GuidedOptions(testing::FreshDir(residual ? "residual" : "plain"), 200);
    o.config.alpha = 0;
    o.config.residual = residual;
    std::vector<LossRecord> curve;
    o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
    ASSERT_TRUE(TrainContrastive(o).ok());
    std::printf("residual %d: cls %.4f -> %.4f\n", residual, curve.front().cls, curve.back().cls);
    EXPECT_LT(MeanOfLastRows(curve, &LossRecord::cls), 0.7 * curve.front().cls);
    absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(o.out);
    ASSERT_TRUE(m.ok()) << m.status();
    EXPECT_EQ((*m)->config().residual, residual);
    auto gap = [&](const motion::Motion& style) {
      return motion::MaxPositionDifference(
          (*m)->Transfer(clip, *(*m)->EncodeStyle(style), motion::PostProcessMode::kNone)->motion,
          clip);
    };
    self_gap[residual] = gap(clip);
    other_gap[residual] = gap(other);
  }
  std::printf(
      "max joint gap to the content: own style plain %.2f, residual %.2f; "
      "other style plain %.2f, residual %.2f\n",
      self_gap[false], self_gap[true], other_gap[false], other_gap[true]);
  EXPECT_LT(self_gap[true], 0.5 * self_gap[false]);
  EXPECT_GT(other_gap[true], 2 * self_gap[true]);
}

TEST(ContrastiveTrainerTest, ResumesWithItsCritic) {
  ResumedRuns runs;
  ASSERT_NO_FATAL_FAILURE(TrainUnbrokenAndResumed("guided", GuidedOptions, &runs));
  const LossRecord &a = runs.unbroken.back(), &c = runs.resumed.back();
  EXPECT_NEAR(c.critic, a.critic, 1e-4 * std::fabs(a.critic));
  EXPECT_NEAR(c.total, a.total, 1e-4 * std::fabs(a.total));
  // A label-free checkpoint is another configuration.
  ContrastiveTrainOptions od = GuidedOptions(runs.resumed_dir, 120);
  od.config.guided = false;
  od.resume = true;
  EXPECT_EQ(TrainContrastive(od).code(), absl::StatusCode::kFailedPrecondition);
}

TEST(ContrastiveTrainerTest, PairGanTrainsAndResumesWithItsDiscriminator) {
  auto options = [](const std::string& out, int iterations) {
    ContrastiveTrainOptions o = GuidedOptions(out, iterations);
    o.config.pair_gan = true;
    o.config.alpha = 0.5;
    return o;
  };
  ResumedRuns runs;
  ASSERT_NO_FATAL_FAILURE(TrainUnbrokenAndResumed("pair_gan", options, &runs));
  ASSERT_TRUE(fs::exists(runs.unbroken_dir + "/checkpoint/pair_disc.pt"));
  ASSERT_EQ(runs.unbroken.size(), 8u);
  for (const LossRecord& r : runs.unbroken) {
    EXPECT_TRUE(std::isfinite(r.gan) && r.gan > 0) << r.iteration;
    EXPECT_TRUE(std::isfinite(r.disc) && r.disc > 0) << r.iteration;
  }
  const LossRecord &a = runs.unbroken.back(), &c = runs.resumed.back();
  EXPECT_NEAR(c.disc, a.disc, 1e-4 * std::fabs(a.disc));
  EXPECT_NEAR(c.total, a.total, 1e-4 * std::fabs(a.total));
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(runs.unbroken_dir);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_TRUE((*m)->config().pair_gan);
}

// The critics that read only dynamics: both learn on real windows (the
// motion critic's label loss falls), both are checkpointed, and a resumed run
// ends where an unbroken one does; without labels they are refused.
TEST(ContrastiveTrainerTest, MotionCriticsTrainAndResume) {
  auto options = [](const std::string& out, int iterations) {
    ContrastiveTrainOptions o = GuidedOptions(out, iterations);
    o.config.motion_gan_weight = 1;
    o.config.motion_class_weight = 1;
    return o;
  };
  ResumedRuns runs;
  ASSERT_NO_FATAL_FAILURE(TrainUnbrokenAndResumed("motion_critics", options, &runs));
  for (const char* f : {"motion_disc.pt", "opt_md.pt", "motion_critic.pt", "opt_mc.pt"})
    EXPECT_TRUE(fs::exists(runs.unbroken_dir + "/checkpoint/" + f)) << f;
  for (const LossRecord& r : runs.unbroken) {
    std::printf("%d mgan %.4f mdisc %.4f mcls %.4f mcritic %.4f\n", r.iteration, r.mgan, r.mdisc,
                r.mcls, r.mcritic);
    EXPECT_TRUE(std::isfinite(r.mgan) && r.mgan > 0) << r.iteration;
    EXPECT_TRUE(std::isfinite(r.mdisc) && r.mdisc > 0) << r.iteration;
    EXPECT_TRUE(std::isfinite(r.mcls) && r.mcls > 0) << r.iteration;
  }
  EXPECT_LT(runs.unbroken.back().mcritic, 0.7 * runs.unbroken.front().mcritic);
  const LossRecord &a = runs.unbroken.back(), &c = runs.resumed.back();
  EXPECT_NEAR(c.mdisc, a.mdisc, 1e-4 * std::fabs(a.mdisc));
  EXPECT_NEAR(c.mcritic, a.mcritic, 1e-4 * std::fabs(a.mcritic));
  EXPECT_NEAR(c.total, a.total, 1e-4 * std::fabs(a.total));
  absl::StatusOr<ContrastiveConfig> config = ReadPackageConfig(runs.unbroken_dir);
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->motion_gan_weight, 1);
  EXPECT_EQ(config->motion_class_weight, 1);

  ExpectRefusedWithoutGuided(options(testing::FreshDir("motion_critics_unguided"), 10));
}

// --motion-content-weight: the motion classifier's verdict without its
// content half is its style half alone, smaller than both; the weight is
// stored, and a package trained without it stores nothing (its content half
// weighs content_class_weight, as before the key).
TEST(ContrastiveTrainerTest, MotionContentWeightScalesTheMotionCriticsContentHalf) {
  auto run = [](const std::string& dir, std::optional<double> weight, double* mcls) {
    ContrastiveTrainOptions o = GuidedOptions(dir, 10);
    o.config.motion_class_weight = 1;
    o.config.motion_content_weight = weight;
    o.on_record = [mcls](const LossRecord& r) { *mcls = r.mcls; };
    ASSERT_TRUE(TrainContrastive(o).ok());
  };
  const std::string default_dir = testing::FreshDir("motion_content_default"),
                    zero_dir = testing::FreshDir("motion_content_zero");
  double both = 0, style_only = 0;
  ASSERT_NO_FATAL_FAILURE(run(default_dir, std::nullopt, &both));
  ASSERT_NO_FATAL_FAILURE(run(zero_dir, 0.0, &style_only));
  std::printf("mcls: both halves %.4f, style half only %.4f\n", both, style_only);
  EXPECT_GT(style_only, 0);
  EXPECT_LT(style_only, both);
  absl::StatusOr<ContrastiveConfig> zero =
      ReadPackageConfig(zero_dir);
  ASSERT_TRUE(zero.ok()) << zero.status();
  ASSERT_TRUE(zero->motion_content_weight.has_value());
  EXPECT_EQ(*zero->motion_content_weight, 0);
  absl::StatusOr<ContrastiveConfig> unset =
      ReadPackageConfig(default_dir);
  ASSERT_TRUE(unset.ok()) << unset.status();
  EXPECT_FALSE(unset->motion_content_weight.has_value());
  EXPECT_EQ(unset->MotionContentWeight(), unset->content_class_weight);
}

// The paired term: each transfer's distance to the content's action in the
// target style (the labelled walks have a walk in both styles, so every
// batch has some), logged and stored; without labels it is refused.
TEST(ContrastiveTrainerTest, PairedTermTrainsOnExamplesOfTheActionInTheTargetStyle) {
  ContrastiveTrainOptions o = GuidedOptions(testing::FreshDir("paired"), 40);
  o.config.paired_weight = 1;
  std::vector<LossRecord> curve;
  o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
  ASSERT_TRUE(TrainContrastive(o).ok());
  ASSERT_EQ(curve.size(), 4u);
  for (const LossRecord& r : curve) {
    std::printf("%d pair %.4f\n", r.iteration, r.pair);
    EXPECT_TRUE(std::isfinite(r.pair) && r.pair > 0) << r.iteration;
  }
  absl::StatusOr<ContrastiveConfig> config = ReadPackageConfig(o.out);
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->paired_weight, 1);

  ContrastiveTrainOptions unguided = GuidedOptions(testing::FreshDir("paired_unguided"), 10);
  unguided.config.paired_weight = 1;
  ExpectRefusedWithoutGuided(unguided);
}

// The fidelity terms: the reconstruction's and the cycle's motion against
// the content window's, and the window rendered with its own style code.
// Each is computed (an untrained generator's output is far from its input),
// logged and stored; without labels they are refused.
TEST(ContrastiveTrainerTest, MotionAndOwnCodeReconstructionTermsAreTrainedAndStored) {
  ContrastiveTrainOptions o = GuidedOptions(testing::FreshDir("fidelity_terms"), 40);
  o.config.motion_rec_weight = 1;
  o.config.own_rec_weight = 1;
  std::vector<LossRecord> curve;
  o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
  ASSERT_TRUE(TrainContrastive(o).ok());
  ASSERT_EQ(curve.size(), 4u);
  for (const LossRecord& r : curve) {
    std::printf("%d rec %.4f mrec %.4f own %.4f\n", r.iteration, r.rec, r.mrec, r.own);
    EXPECT_TRUE(std::isfinite(r.mrec) && r.mrec > 0) << r.iteration;
    EXPECT_TRUE(std::isfinite(r.own) && r.own > 0) << r.iteration;
  }
  absl::StatusOr<ContrastiveConfig> config = ReadPackageConfig(o.out);
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->motion_rec_weight, 1);
  EXPECT_EQ(config->own_rec_weight, 1);
  std::ifstream csv(o.out + "/loss.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",mrec,own,"), std::string::npos) << header;

  ContrastiveTrainOptions motion_only = GuidedOptions(testing::FreshDir("motion_rec_unguided"), 10);
  motion_only.config.motion_rec_weight = 1;
  ExpectRefusedWithoutGuided(motion_only);
  ContrastiveTrainOptions own_only = GuidedOptions(testing::FreshDir("own_rec_unguided"), 10);
  own_only.config.own_rec_weight = 1;
  ExpectRefusedWithoutGuided(own_only);
}

TEST(ContrastiveTrainerTest, NeedsLabelledClipNames) {
  ContrastiveTrainOptions o = GuidedOptions(testing::FreshDir("guided_unlabelled"), 10);
  o.data = testing::FourClips();  // normal.bvh, old.bvh, ...
  const absl::Status s = TrainContrastive(o);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("normal.bvh"), std::string::npos) << s;
}

// --init-from: a run started from a trained package's weights begins where
// that package ended (its first losses are the trained ones, not a fresh
// network's); a package of another shape is refused.
TEST(ContrastiveTrainerTest, FineTuningStartsFromTheTrainedWeights) {
  std::vector<LossRecord> trained, fresh, tuned;
  ContrastiveTrainOptions base = GuidedOptions(testing::FreshDir("guided_base"), 120);
  base.on_record = [&](const LossRecord& r) { trained.push_back(r); };
  ASSERT_TRUE(TrainContrastive(base).ok());
  ContrastiveTrainOptions scratch = GuidedOptions(testing::FreshDir("guided_scratch"), 10);
  scratch.on_record = [&](const LossRecord& r) { fresh.push_back(r); };
  ASSERT_TRUE(TrainContrastive(scratch).ok());
  ContrastiveTrainOptions tune = GuidedOptions(testing::FreshDir("guided_tuned"), 10);
  tune.init_from = base.out;
  tune.config.content_class_weight = 3;
  tune.on_record = [&](const LossRecord& r) { tuned.push_back(r); };
  ASSERT_TRUE(TrainContrastive(tune).ok());
  ASSERT_FALSE(trained.empty() || fresh.empty() || tuned.empty());
  std::printf("rec: fresh %.3f, trained %.3f, tuned %.3f\n", fresh[0].rec, trained.back().rec,
              tuned[0].rec);
  ASSERT_LT(trained.back().rec, fresh[0].rec);
  EXPECT_LT(std::abs(tuned[0].rec - trained.back().rec),
            0.25 * (fresh[0].rec - trained.back().rec));
  auto tuned_model = ContrastiveModel::Load(tune.out);
  ASSERT_TRUE(tuned_model.ok()) << tuned_model.status();
  EXPECT_DOUBLE_EQ((*tuned_model)->config().content_class_weight, 3);

  ContrastiveTrainOptions other = GuidedOptions(testing::FreshDir("guided_other"), 10);
  other.config.channels = 8;
  other.init_from = base.out;
  EXPECT_FALSE(TrainContrastive(other).ok());
  // Weights trained on other data (other normalization statistics) too.
  ContrastiveTrainOptions elsewhere = GuidedOptions(testing::FreshDir("guided_elsewhere"), 10);
  elsewhere.data.pop_back();
  elsewhere.config.guided = false;
  elsewhere.init_from = base.out;
  EXPECT_EQ(TrainContrastive(elsewhere).code(), absl::StatusCode::kFailedPrecondition);
}

// --average-from: the package holds the mean of the weights at the sampled
// iterations (here 20, 30 and 40, taken from a plain run stopped and resumed
// at each), also when the averaging run itself is killed and resumed.
TEST(ContrastiveTrainerTest, WeightAveragingPackagesTheMeanOfTheSampledWeights) {
  const auto weights_of = [](const std::string& dir, const ContrastiveConfig& config) {
    ContrastiveNet net(config);
    EXPECT_TRUE(LoadWeights(net, dir + "/weights.pt").ok()) << dir;
    return net;
  };
  ContrastiveTrainOptions plain = GuidedOptions(testing::FreshDir("average_plain"), 20);
  std::vector<ContrastiveNet> sampled;
  for (int iterations : {20, 30, 40}) {
    ContrastiveTrainOptions o = GuidedOptions(plain.out, iterations);
    o.resume = iterations > 20;
    ASSERT_TRUE(TrainContrastive(o).ok());
    absl::StatusOr<ContrastiveConfig> c = ReadPackageConfig(plain.out);
    ASSERT_TRUE(c.ok()) << c.status();
    sampled.push_back(weights_of(plain.out, *c));
  }
  ContrastiveTrainOptions averaged = GuidedOptions(testing::FreshDir("average_run"), 40);
  averaged.config.average_from = 20, averaged.config.average_every = 10;
  ASSERT_TRUE(TrainContrastive(averaged).ok());
  ContrastiveTrainOptions resumed = GuidedOptions(testing::FreshDir("average_resumed"), 30);
  resumed.config.average_from = 20, resumed.config.average_every = 10;
  ASSERT_TRUE(TrainContrastive(resumed).ok());
  resumed.config.iterations = 40;
  resumed.resume = true;
  ASSERT_TRUE(TrainContrastive(resumed).ok());

  absl::StatusOr<ContrastiveConfig> c = ReadPackageConfig(averaged.out);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->average_from, 20);
  const ContrastiveNet mean = weights_of(averaged.out, *c),
                       mean_resumed = weights_of(resumed.out, *c);
  const auto params = [](const ContrastiveNet& n) { return n->parameters(); };
  double moved = 0;
  for (size_t i = 0; i < params(mean).size(); ++i) {
    const torch::Tensor expected =
        (params(sampled[0])[i] + params(sampled[1])[i] + params(sampled[2])[i]) / 3;
    EXPECT_TRUE(torch::allclose(params(mean)[i], expected, 1e-3, 1e-5)) << i;
    EXPECT_TRUE(torch::allclose(params(mean_resumed)[i], params(mean)[i], 1e-3, 1e-5)) << i;
    moved = std::max(moved, (params(sampled[2])[i] - expected).abs().max().item<double>());
  }
  EXPECT_GT(moved, 1e-3);  // The mean is not simply the last weights.

  ContrastiveTrainOptions late = GuidedOptions(testing::FreshDir("average_late"), 40);
  late.config.average_from = 50;
  EXPECT_EQ(TrainContrastive(late).code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace stylus::model
