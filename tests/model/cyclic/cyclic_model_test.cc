// model/cyclic/cyclic_model: packages of tiny trained networks load and serve
// transfers (rotations, the normalized skip, the residual output, the content
// guard).
#include "model/cyclic/cyclic_model.h"

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
#include "train/cyclic_trainer.h"
#include "train/guard_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace cyclic_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;

TEST(CyclicModelTest, CycleLossFallsAndThePackageServesTransfers) {
  // The paper's decoder-only output: its cycle loss starts at the
  // autoencoder's error and must fall.
  CyclicTrainOptions o = TinyOptions(Dir("train"));
  o.config.residual = false;
  std::vector<LossRow> rows;
  o.on_record = [&](const LossRow& r) { rows.push_back(r); };
  ASSERT_TRUE(TrainCyclic(o).ok());
  // Rows after the autoencoder stage (iteration > 60) carry the cycle loss.
  std::vector<double> cyc;
  for (const LossRow& r : rows) {
    if (r.iteration > o.config.ae_iterations + 10) cyc.push_back(r.Get("cycle"));
  }
  ASSERT_GE(cyc.size(), 10u);
  std::printf("cycle %.4f -> %.4f; rec %.4f -> %.4f\n", cyc.front(), cyc.back(),
              rows.front().Get("rec"), rows.back().Get("rec"));
  EXPECT_LT(cyc.back(), 0.7 * cyc.front());
  EXPECT_LT(rows.back().Get("rec"), 0.5 * rows.front().Get("rec"));
  for (const char* f : {"config.txt", "norm.txt", "skeleton.bvh", "weights.pt", "loss.csv"})
    EXPECT_TRUE(fs::exists(o.out + "/" + f)) << f;

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ((*m)->summary().family, "cyclic");
  const motion::Motion content = Clip(0), a = Clip(1), b = Clip(2);
  const StyleCode sa = *(*m)->EncodeStyle(a), sb = *(*m)->EncodeStyle(b);
  EXPECT_EQ(sa.values.size(), 2u * o.config.hidden);
  absl::StatusOr<motion::Motion> out = MotionOf((*m)->Transfer(content, sa));
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  EXPECT_TRUE(out->skeleton.SameTopology(content.skeleton));
  EXPECT_LT(motion::BoneLengthError(*out, *motion::FindHumanoidRoles(content.skeleton)), 1e-4);
  // Any length, odd included.
  motion::Motion odd = content;
  odd.num_frames = 37;
  odd.values.resize(static_cast<size_t>(37) * content.skeleton.num_channels());
  absl::StatusOr<motion::Motion> out_odd = MotionOf((*m)->Transfer(odd, sa));
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
  const motion::Motion ta = (*m)->Transfer(content, sa, motion::PostProcessMode::kNone)->motion;
  const motion::Motion tb = (*m)->Transfer(content, sb, motion::PostProcessMode::kNone)->motion;
  EXPECT_LT(same((*m)->Interpolate(content, {sa, sb}, {{1, 0}, {}}, motion::PostProcessMode::kNone)
                     ->motion,
                 ta),
            1e-3);
  EXPECT_LT(same((*m)->Interpolate(content, {sa, sb}, {{0, 1}, {}}, motion::PostProcessMode::kNone)
                     ->motion,
                 tb),
            1e-3);
  auto again = CyclicModel::Load(o.out);
  ASSERT_TRUE(again.ok());
  EXPECT_LT(same((*again)->Transfer(content, sa, motion::PostProcessMode::kNone)->motion, ta),
            1e-4);
  // Without the inference-time optimization the output differs.
  auto no_kc = CyclicModel::Load(o.out, "kc_iters = 0\n");
  ASSERT_TRUE(no_kc.ok());
  const motion::Motion ta0 =
      (*no_kc)->Transfer(content, sa, motion::PostProcessMode::kNone)->motion;
  EXPECT_GT(same(ta0, ta), 1e-3);
  // A per-frame schedule of constant weights is the fixed blend (compared
  // without the optimization, whose Adam steps amplify rounding
  // differences).
  std::vector<std::vector<double>> schedule(content.num_frames, {1, 0});
  EXPECT_LT(
      same((*no_kc)
               ->Interpolate(content, {sa, sb}, {{}, schedule}, motion::PostProcessMode::kNone)
               ->motion,
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
    auto keep = CyclicModel::Load(kept, "kc_iters = 0\n");
    ASSERT_TRUE(keep.ok()) << keep.status();
    const motion::HumanoidRoles roles = *motion::FindHumanoidRoles(content.skeleton);
    const motion::Motion on_path =
        (*keep)->Transfer(content, sa, motion::PostProcessMode::kNone)->motion;
    const double kept_error = motion::TrajectoryError(on_path, content, roles);
    const double own_error = motion::TrajectoryError(ta0, content, roles);
    std::printf("trajectory error: generated %.4f, keep_path %.6f\n", own_error, kept_error);
    EXPECT_LT(kept_error, 0.2);
    EXPECT_GT(own_error, 20 * kept_error);
  }

  // Bad input: a clip on a rig that is no humanoid, a wrong-size style code.
  const motion::Motion other = *motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) +
                                                    "/tests/fixtures/bvh/good/three_joint.bvh");
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
  // What was read, what was loaded, then the resume.
  ASSERT_GE(lines.size(), 3u);
  EXPECT_NE(lines[0].find("read 4 clips"), std::string::npos) << lines[0];
  EXPECT_NE(lines[2].find("resumed from"), std::string::npos) << lines[2];
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
  std::printf("rec: autoencoder %.4f, then %.4f -> %.4f\n", ae_rows.back().Get("rec"),
              rows.front().Get("rec"), rows.back().Get("rec"));
  EXPECT_LT(rows.front().Get("rec"), 2.0 * ae_rows.back().Get("rec"));
  EXPECT_LT(rows.back().Get("rec"), 2.0 * ae_rows.back().Get("rec"));

  absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(o.out);
  ASSERT_TRUE(m.ok()) << m.status();
  const motion::Motion content = motion::ReadBvhFile(o.data[0]).value();
  const motion::Motion a = motion::ReadBvhFile(o.data[3]).value();
  const motion::Motion b = motion::ReadBvhFile(o.data[1]).value();
  absl::StatusOr<StyleCode> ca = (*m)->EncodeStyle(a), cb = (*m)->EncodeStyle(b);
  ASSERT_TRUE(ca.ok() && cb.ok());
  EXPECT_EQ(ca->values.size(), static_cast<size_t>(8 + 2 * o.config.hidden));
  absl::StatusOr<motion::Motion> out =
      MotionOf((*m)->Transfer(content, *ca, motion::PostProcessMode::kNone));
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  StyleWeights half;
  half.fixed = {0.5, 0.5};
  absl::StatusOr<motion::Motion> mixed =
      MotionOf((*m)->Interpolate(content, {*ca, *cb}, half, motion::PostProcessMode::kNone));
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
    absl::StatusOr<std::unique_ptr<CyclicModel>> m = CyclicModel::Load(o.out, "kc_iters = 0\n");
    ASSERT_TRUE(m.ok()) << m.status();
    EXPECT_EQ((*m)->config().rotations, rotations);
    EXPECT_EQ((*m)->config().net_channels(joints), rotations ? 7 * joints + 8 : 3 * joints + 8);
    absl::StatusOr<motion::Motion> out = MotionOf(
        (*m)->Transfer(content, *(*m)->EncodeStyle(style), motion::PostProcessMode::kNone));
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
    absl::StatusOr<std::unique_ptr<CyclicModel>> m =
        CyclicModel::Load(dir, absl::StrCat("kc_iters = ", kc_iters, "\n"));
    EXPECT_TRUE(m.ok()) << m.status();
    absl::StatusOr<TransferResult> result =
        (*m)->Transfer(content, *(*m)->EncodeStyle(Clip(2)), motion::PostProcessMode::kNone);
    if (result.ok() && note != nullptr) *note = result->note;
    return MotionOf(std::move(result));
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
    auto m = CyclicModel::Load(o.out, "kc_iters = 0\n");
    ASSERT_TRUE(m.ok()) << m.status();
    const motion::Motion out =
        (*m)->Transfer(content, *(*m)->EncodeStyle(content), motion::PostProcessMode::kNone)
            ->motion;
    gap[residual] = motion::MaxPositionDifference(out, content);
  }
  std::printf("self-transfer max joint gap: decoder-only %.2f, residual %.2f\n", gap[false],
              gap[true]);
  EXPECT_LT(gap[true], 0.5 * gap[false]);
}

}  // namespace
}  // namespace stylus::model
