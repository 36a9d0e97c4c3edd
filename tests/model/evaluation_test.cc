// Judges and evaluation plumbing on a tiny synthesized, labelled dataset, and
// the held-out pair rule on the Bandai data.
#include "model/evaluation.h"

#include <filesystem>
#include <set>

#include "gtest/gtest.h"
#include "model/contrastive_trainer.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/synth.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;

// dataset-9_{walk,run}_{old,proud}_00{1,2}.bvh, synthesized.
std::string TinyDataset() {
  const std::string dir = ::testing::TempDir() + "/eval_tiny";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* content : {"walk", "run"}) {
    for (const char* style : {"old", "proud"}) {
      for (int take = 1; take <= 2; ++take) {
        std::string spec = std::string(style) + ",frames=48,turn=" + std::to_string(take * 10);
        if (std::string(content) == "run") spec += ",gait=run,speed=300,stride=240";
        const std::string path =
            dir + "/dataset-9_" + content + "_" + style + "_00" + std::to_string(take) + ".bvh";
        EXPECT_TRUE(
            motion::WriteBvhFile(*motion::Synthesize(*motion::ParseSynthStyle(spec)), path).ok());
      }
    }
  }
  return dir;
}

TEST(EvaluationTest, JudgesAndEvaluationRunEndToEnd) {
  const std::string data = TinyDataset();
  JudgeTrainOptions jo;
  jo.data = {data};
  jo.out = ::testing::TempDir() + "/eval_judges";
  jo.iterations = 60;
  jo.batch = 8;
  jo.log = [](const std::string&) {};
  absl::StatusOr<JudgeAccuracy> acc = TrainJudges(jo);
  ASSERT_TRUE(acc.ok()) << acc.status();
  EXPECT_GT(acc->clips, 0);
  absl::StatusOr<std::unique_ptr<Judges>> judges = Judges::Load(jo.out);
  ASSERT_TRUE(judges.ok()) << judges.status();
  EXPECT_EQ((*judges)->styles(), (std::vector<std::string>{"old", "proud"}));
  EXPECT_EQ((*judges)->contents(), (std::vector<std::string>{"run", "walk"}));

  TrainOptions to;
  to.data = {data};
  to.out = ::testing::TempDir() + "/eval_model";
  to.config.channels = 16;
  to.config.window = 16;
  to.config.hop = 12;
  to.config.batch = 4;
  to.config.iterations = 10;
  to.log = [](const std::string&) {};
  ASSERT_TRUE(TrainContrastive(to).ok());
  auto model = ContrastiveModel::Load(to.out);
  ASSERT_TRUE(model.ok()) << model.status();

  absl::StatusOr<std::vector<EvalPair>> pairs = MakeEvalPairs({data}, 2);
  ASSERT_TRUE(pairs.ok()) << pairs.status();
  absl::StatusOr<EvalReport> report = Evaluate(**model, **judges, *pairs);
  ASSERT_TRUE(report.ok()) << report.status();
  ASSERT_EQ(report->rows.size(), 4u);
  for (const EvalRow& r : report->rows) EXPECT_EQ(r.pairs, static_cast<int>(pairs->size()));
  // Post-processing plants the feet of the model's output.
  EXPECT_LT(report->rows[1].foot_skating, report->rows[0].foot_skating);
  // Real capture: bones exactly as the offsets say.
  EXPECT_LT(report->rows[2].bone_length_error, 1e-4);
  // By construction the identity output never has the style clip's style label
  // and copy-style never the content clip's content, so a judge that is right
  // about real clips scores them low there.
  EXPECT_NE(report->Markdown().find("| model, post-processing full |"), std::string::npos);
  EXPECT_NE(report->Markdown().find("foot skating"), std::string::npos);
}

TEST(EvaluationTest, BandaiPairsDifferInContentAndStyleAndAreDeterministic) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<std::vector<EvalPair>> a = MakeEvalPairs({dir}, 3);
  ASSERT_TRUE(a.ok()) << a.status();
  absl::StatusOr<std::vector<EvalPair>> b =
      MakeEvalPairs({dir + "/dataset-2", dir + "/dataset-1"}, 3);
  ASSERT_TRUE(b.ok());
  EXPECT_GT(a->size(), 200u);
  std::set<std::pair<std::string, std::string>> sa, sb;
  for (const EvalPair& p : *a) {
    const auto c = *motion::ParseClipName(p.content_path), s = *motion::ParseClipName(p.style_path);
    EXPECT_NE(c.content, s.content);
    EXPECT_NE(c.style, s.style);
    sa.insert({fs::path(p.content_path).filename(), fs::path(p.style_path).filename()});
  }
  for (const EvalPair& p : *b)
    sb.insert({fs::path(p.content_path).filename(), fs::path(p.style_path).filename()});
  EXPECT_EQ(sa, sb);
}

}  // namespace
}  // namespace stylus::model
