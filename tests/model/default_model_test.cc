// The shipped default model and judges (models/) load and work on real input.
#include <string>

#include "gtest/gtest.h"
#include "model/contrastive_model.h"
#include "model/judges.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/kinematics.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

const std::string kModel = std::string(STYLUS_SOURCE_DIR) + "/models/contrastive/v3";
const std::string kJudges = std::string(STYLUS_SOURCE_DIR) + "/models/judges/v1";

TEST(DefaultModelTest, TransfersTheShippedSamples) {
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ((*m)->package().config.dim, 162);
  EXPECT_GT((*m)->package().config.trained_iterations, 0);
  const motion::Motion content =
      *motion::ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const motion::Motion style = *motion::ReadBvhFile(testing::SourceDir() + "/samples/walk_old.bvh");
  absl::StatusOr<StyleCode> code = (*m)->EncodeStyle(style);
  ASSERT_TRUE(code.ok()) << code.status();
  absl::StatusOr<motion::Motion> out = (*m)->Transfer(content, *code);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  EXPECT_GT(motion::MaxPositionDifference(*out, content), 1.0);  // It changed something.
}

TEST(DefaultModelTest, JudgesRecognizeRealHeldOutClips) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<std::unique_ptr<Judges>> judges = Judges::Load(kJudges);
  ASSERT_TRUE(judges.ok()) << judges.status();
  absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset({dir});
  ASSERT_TRUE(index.ok());
  int right = 0, total = 0;
  for (const motion::ClipEntry* c : index->Split(true)) {
    const motion::Motion clip = *motion::ReadBvhFile(c->path);
    const auto& styles = (*judges)->styles();
    right += styles[*(*judges)->ClassifyStyle(clip)] == c->label.style;
    ++total;
  }
  EXPECT_GT(static_cast<double>(right) / total, 0.8);
}

}  // namespace
}  // namespace stylus::model
