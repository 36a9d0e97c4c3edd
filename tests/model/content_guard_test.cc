// model/content_guard: an ensemble of action classifiers trained for a tiny
// contrastive package (train/guard_trainer.h), its files checked on load, and
// the guarded transfer it drives (StyleModel::Interpolate).
#include "model/content_guard.h"

#include <filesystem>
#include <fstream>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
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

using namespace contrastive_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;
using testing::FourClips;

using ContentGuardTest = TrainedModelTest;

TEST_F(ContentGuardTest, LearnsTheLabelledClipsAndGuardsTransfers) {
  const std::string dir = Dir("guarded");
  fs::copy(*dir_, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  ContentGuardTrainOptions o;
  o.model = dir;
  o.data = testing::LabelledClips();
  o.iterations = 150;
  o.guards = 2;
  o.log = [](const std::string&) {};
  absl::StatusOr<ContentGuardAccuracy> acc = TrainContentGuard(o);
  ASSERT_TRUE(acc.ok()) << acc.status();
  EXPECT_EQ(acc->clips, 0);  // Single files: no held-out split.
  for (const char* f : {"guard.txt", "guard_1.pt", "guard_2.pt"}) {
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  }
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> plain = ContrastiveModel::Load(dir);
  ASSERT_TRUE(plain.ok()) << plain.status();
  const ContrastiveConfig& config = (*plain)->config();
  absl::StatusOr<std::unique_ptr<ContentGuard>> guard =
      ContentGuard::Load(dir, config.dim, config.window, config.hop);
  ASSERT_TRUE(guard.ok()) << guard.status();
  ASSERT_EQ((*guard)->contents(), (std::vector<std::string>{"run", "turn", "walk"}));
  // The guards learned the four clips' actions (walk, walk, run, turn).
  const int want[] = {2, 2, 0, 1};
  for (int i = 0; i < 4; ++i) {
    absl::StatusOr<motion::FeatureClip> f = (*plain)->NormalizedFeatures(Clip(i), "clip");
    ASSERT_TRUE(f.ok()) << f.status();
    const std::vector<double> p = (*guard)->Probabilities(*f);
    ASSERT_EQ(p.size(), 3u);
    EXPECT_NEAR(p[0] + p[1] + p[2], 1.0, 1e-6);
    EXPECT_EQ((*guard)->Classify(*f), want[i]) << testing::LabelledClips()[i];
  }
  // Turned on, every transfer ends at one of the forms.
  AppendConfig(dir, "content_guard = 1\nguard_strengths = 0.5,0\n");
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> guarded = ContrastiveModel::Load(dir);
  ASSERT_TRUE(guarded.ok()) << guarded.status();
  const StyleCode code = *(*guarded)->EncodeStyle(Clip(1));
  for (int i : {0, 2, 3}) {
    absl::StatusOr<TransferResult> result =
        (*guarded)->Transfer(Clip(i), code, motion::PostProcessMode::kFull);
    ASSERT_TRUE(result.ok()) << result.status();
    const TransferNote& note = result->note;
    EXPECT_TRUE(note.guarded);
    EXPECT_EQ(note.residual_strength, note.backed_off ? (note.last_form ? 0 : 0.5) : 1) << i;
    EXPECT_TRUE(!note.last_form || note.backed_off) << i;
  }
  // Off until config.txt turns it on.
  absl::StatusOr<TransferResult> plain_result =
      (*plain)->Transfer(Clip(0), code, motion::PostProcessMode::kFull);
  ASSERT_TRUE(plain_result.ok()) << plain_result.status();
  EXPECT_FALSE(plain_result->note.guarded);
}

TEST_F(ContentGuardTest, FilesAreCheckedOnLoad) {
  const std::string dir = Dir("guard_files");
  fs::copy(*dir_, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  AppendConfig(dir, "content_guard = 1\n");
  auto error = [&](absl::StatusCode code, const std::string& text) {
    const absl::Status s = ContrastiveModel::Load(dir).status();
    EXPECT_EQ(s.code(), code) << s;
    EXPECT_NE(s.message().find(text), std::string::npos) << s;
  };
  error(absl::StatusCode::kNotFound, "guard.txt: missing (train it with stylus-tool train-guard)");
  std::ofstream(dir + "/guard.txt") << "styles = a,b\ncontents = c,d\nguards = 0\n";
  error(absl::StatusCode::kInvalidArgument, "guard.txt:3: ");
  std::ofstream(dir + "/guard.txt", std::ios::trunc) << "styles = a,b\nguards = 1\n";
  error(absl::StatusCode::kInvalidArgument, "guard.txt: missing 'styles' or 'contents'");
  std::ofstream(dir + "/guard.txt", std::ios::trunc) << "styles = a,b\ncontents = c,d\n";
  error(absl::StatusCode::kNotFound, "guard_1.pt: missing");
  std::ofstream(dir + "/guard_1.pt") << "not a torch archive";
  error(absl::StatusCode::kInvalidArgument, "guard_1.pt: cannot load weights");
  ContentGuardTrainOptions o;
  o.model = dir;
  o.data = testing::LabelledClips();
  o.guards = 0;
  EXPECT_EQ(TrainContentGuard(o).status().code(), absl::StatusCode::kInvalidArgument);
  o.guards = 1;
  o.data = FourClips();  // Not labelled.
  EXPECT_EQ(TrainContentGuard(o).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace stylus::model
