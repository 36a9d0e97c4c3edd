// Judges and evaluation plumbing on a tiny synthesized, labelled dataset, and
// the held-out pair rule on the Bandai data.
#include "eval/evaluation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <set>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "motion/bvh.h"
#include "motion/cadence.h"
#include "motion/dataset.h"
#include "motion/metrics.h"
#include "motion/synth.h"
#include "tests/eval/tiny_dataset.h"
#include "tests/test_support.h"
#include "train/contrastive_trainer.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;

std::string TinyDataset() { return testing::TinyLabelledDataset("eval_tiny"); }

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

  ContrastiveTrainOptions to;
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
  absl::StatusOr<DaeTrainResult> dae = TrainFeatureJudge({data}, jo.out, 150, 1, {});
  ASSERT_TRUE(dae.ok()) << dae.status();
  EXPECT_LT(dae->denoised_mse, dae->noisy_mse);  // It learned to denoise.
  absl::StatusOr<std::unique_ptr<FeatureJudge>> features = FeatureJudge::Load(jo.out);
  ASSERT_TRUE(features.ok()) << features.status();
  std::vector<motion::Motion> reference;
  for (const auto& e : fs::directory_iterator(data))
    reference.push_back(*motion::ReadBvhFile(e.path().string()));
  absl::StatusOr<EvalReport> report =
      Evaluate({{"model", model->get(), true}, {"again", model->get(), false}}, **judges,
               features->get(), reference, *pairs);
  ASSERT_TRUE(report.ok()) << report.status();
  ASSERT_EQ(report->rows.size(), 5u);
  EXPECT_EQ(report->identity_row, 3);
  EXPECT_EQ(report->rows[2].name, "again, no post-processing");
  // The same model twice gives the same row.
  EXPECT_DOUBLE_EQ(report->rows[2].fmd, report->rows[0].fmd);
  // Identity's content distance is 0; the untrained model's output is far
  // from real motion in FMD compared with the real clips themselves.
  EXPECT_DOUBLE_EQ(report->rows[3].content_distance, 0.0);
  EXPECT_GT(report->rows[0].fmd, report->rows[3].fmd);
  EXPECT_GT(report->real_diversity, 0);
  for (const EvalRow& r : report->rows) EXPECT_EQ(r.pairs, static_cast<int>(pairs->size()));
  // Post-processing plants the feet of the model's output.
  EXPECT_LT(report->rows[1].foot_skating, report->rows[0].foot_skating);
  // Real capture: bones exactly as the offsets say.
  EXPECT_LT(report->rows[3].bone_length_error, 1e-4);
  // By construction the identity output never has the style clip's style label
  // and copy-style never the content clip's content, so a judge that is right
  // about real clips scores them low there.
  EXPECT_NE(report->Markdown().find("| model, post-processing full |"), std::string::npos);
  EXPECT_NE(report->Markdown().find("foot skating"), std::string::npos);
  // Gait: clips too short to take two steps are left out of it.
  EXPECT_EQ(report->rows[3].gait_pairs[1], 0);
  EXPECT_EQ(report->Markdown().find("| output | step period | stride |"), std::string::npos);
  // Longer walks and runs step, and old and proud differ in stride and arm
  // swing: the baselines sit at either end of each gap.
  const std::string stepping = testing::TinyLabelledDataset("eval_tiny_steps", 120);
  absl::StatusOr<std::vector<EvalPair>> stepping_pairs = MakeEvalPairs({stepping}, 2);
  ASSERT_TRUE(stepping_pairs.ok()) << stepping_pairs.status();
  absl::StatusOr<EvalReport> gait =
      Evaluate({{"model", model->get(), true}}, **judges, nullptr, {}, *stepping_pairs);
  ASSERT_TRUE(gait.ok()) << gait.status();
  const EvalRow &identity_gait = gait->rows[gait->identity_row],
                &copy_style = gait->rows[gait->identity_row + 1];
  EXPECT_GT(identity_gait.gait_pairs[1] + identity_gait.gait_pairs[3], 0);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(copy_style.gait_pairs[k], identity_gait.gait_pairs[k]) << kGaitFigures[k];
    if (identity_gait.gait_pairs[k] == 0) continue;
    EXPECT_DOUBLE_EQ(identity_gait.gait_toward_style[k], 0.0) << kGaitFigures[k];
    EXPECT_DOUBLE_EQ(copy_style.gait_toward_style[k], 1.0) << kGaitFigures[k];
  }
  EXPECT_NE(gait->Markdown().find("| output | step period | stride |"), std::string::npos);
  // Verdicts: one per pair and row; the identity row's judged labels are the
  // judges' verdicts on the content clips themselves, and its accuracy counts
  // exactly the verdicts that match.
  ASSERT_EQ(report->verdicts.size(), pairs->size() * report->rows.size());
  int identity_right = 0;
  for (const EvalVerdict& v : report->verdicts) {
    if (v.row != report->identity_row) continue;
    const auto label = motion::ParseClipName((*pairs)[v.pair].content_path);
    ASSERT_TRUE(label.has_value());
    identity_right += v.content == label->content;
  }
  EXPECT_EQ(identity_right,
            static_cast<int>(std::lround(report->rows[3].content_accuracy * pairs->size())));
  const std::string csv = report->VerdictsCsv(*pairs);
  EXPECT_EQ(
      csv.rfind("content_bvh,style_bvh,output,style,judged_style,content,judged_content,movement\n",
                0),
      0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'),
            static_cast<long>(report->verdicts.size() + 1));
  EXPECT_NE(csv.find(",identity (output = content),"), std::string::npos);
  EXPECT_NE(csv.find(",\"model, post-processing full\","), std::string::npos);  // Quoted.

  // Second judges: the same judges a second time agree with themselves on
  // every pair, so both, either and each accuracy are the first's.
  EXPECT_FALSE(report->second_judges);
  EXPECT_EQ(report->Markdown().find("Second judges"), std::string::npos);
  absl::StatusOr<EvalReport> twice =
      Evaluate({{"model", model->get(), true}}, **judges, nullptr, {}, *pairs, {}, judges->get());
  ASSERT_TRUE(twice.ok()) << twice.status();
  ASSERT_TRUE(twice->second_judges);
  for (size_t r = 0; r < twice->rows.size(); ++r) {
    const EvalRow& row = twice->rows[r];
    EXPECT_DOUBLE_EQ(row.content_accuracy,
                     report->rows[r == 0 || r == 1 ? r : r + 1].content_accuracy);
    EXPECT_DOUBLE_EQ(row.second_style_accuracy, row.style_accuracy) << row.name;
    EXPECT_DOUBLE_EQ(row.second_content_accuracy, row.content_accuracy) << row.name;
    EXPECT_DOUBLE_EQ(row.content_by_both, row.content_accuracy) << row.name;
    EXPECT_DOUBLE_EQ(row.ContentByEither(), row.content_accuracy) << row.name;
  }
  EXPECT_NE(twice->Markdown().find("Second judges"), std::string::npos);

  // own_style: the row restyles each content clip with its own style code;
  // its verdicts are the judges' on exactly those transfers.
  absl::StatusOr<EvalReport> own =
      Evaluate({{"model", model->get(), false}, {"own", model->get(), false, /*own_style=*/true}},
               **judges, nullptr, {}, *pairs);
  ASSERT_TRUE(own.ok()) << own.status();
  ASSERT_EQ(own->rows[1].name, "own, no post-processing");
  // Its foot skating is the mean over exactly those transfers, and differs
  // from the transfers' row (the verdicts alone could agree by chance).
  int checked = 0;
  double skating = 0;
  for (const EvalVerdict& v : own->verdicts) {
    if (v.row != 1) continue;
    const motion::Motion content = *motion::ReadBvhFile((*pairs)[v.pair].content_path);
    const motion::Motion back =
        (*model)
            ->Transfer(content, *(*model)->EncodeStyle(content), motion::PostProcessMode::kNone)
            ->motion;
    EXPECT_EQ(v.content, (*judges)->contents()[*(*judges)->ClassifyContent(back)]);
    EXPECT_EQ(v.style, (*judges)->styles()[*(*judges)->ClassifyStyle(back)]);
    skating += motion::FootSkating(back, content, (*model)->data().roles);
    ++checked;
  }
  ASSERT_EQ(checked, static_cast<int>(pairs->size()));
  EXPECT_NEAR(own->rows[1].foot_skating, skating / checked, 1e-6 * skating / checked);
  EXPECT_NE(own->rows[1].foot_skating, own->rows[0].foot_skating);

  // style_timing: transfers with the style's cadence, post-processed against
  // the content warped alike, and the warped content as a row of its own;
  // each verdict is the judges' on exactly that output.
  // Walks long enough to have a cadence, the style's at another step rate
  // (speed / stride).
  const std::string gaits = ::testing::TempDir() + "/eval_gaits";
  fs::create_directories(gaits);
  std::vector<EvalPair> timed_pairs = *pairs;
  for (const auto& [content, style] :
       std::vector<std::pair<std::string, std::string>>{{"old,frames=150,speed=100,stride=120",
                                                         "proud,frames=150,speed=150,stride=120"},
                                                        {"proud,frames=150,speed=130",
                                                         "old,frames=150,speed=80,stride=100"}}) {
    const std::string c = gaits + "/dataset-9_walk_" + content.substr(0, content.find(',')) +
                          "_00" + std::to_string(timed_pairs.size()) + ".bvh";
    const std::string st = gaits + "/dataset-9_run_" + style.substr(0, style.find(',')) + "_00" +
                           std::to_string(timed_pairs.size()) + ".bvh";
    ASSERT_TRUE(
        motion::WriteBvhFile(*motion::Synthesize(*motion::ParseSynthStyle(content)), c).ok());
    ASSERT_TRUE(
        motion::WriteBvhFile(*motion::Synthesize(*motion::ParseSynthStyle(style)), st).ok());
    timed_pairs.push_back({c, st});
  }
  absl::StatusOr<EvalReport> timed =
      Evaluate({{"model", model->get(), false},
                {"timed", model->get(), true, /*own_style=*/false, /*style_timing=*/true}},
               **judges, nullptr, {}, timed_pairs);
  ASSERT_TRUE(timed.ok()) << timed.status();
  ASSERT_EQ(timed->rows.size(), 6u);
  EXPECT_EQ(timed->rows[1].name, "timed, no post-processing");
  EXPECT_EQ(timed->rows[2].name, "timed, post-processing full");
  EXPECT_EQ(timed->rows[3].name, "content at the style's cadence (no model)");
  EXPECT_EQ(timed->identity_row, 4);
  int warped = 0;
  double ratio_sum = 0;
  for (const EvalVerdict& v : timed->verdicts) {
    if (v.row != 1 && v.row != 3) continue;
    const motion::Motion content = *motion::ReadBvhFile(timed_pairs[v.pair].content_path);
    const motion::Motion style = *motion::ReadBvhFile(timed_pairs[v.pair].style_path);
    TransferOptions options(motion::PostProcessMode::kNone);
    options.timing = Timing::kStyle;
    absl::StatusOr<TransferResult> t =
        (*model)->Transfer(content, *(*model)->EncodeStyle(style), options);
    ASSERT_TRUE(t.ok()) << t.status();
    const motion::Motion expected =
        v.row == 1 ? t->motion
                   : (t->warp.applied ? motion::TimeWarp(content, t->warp.ratio) : content);
    EXPECT_EQ(v.content, (*judges)->contents()[*(*judges)->ClassifyContent(expected)]);
    EXPECT_EQ(v.style, (*judges)->styles()[*(*judges)->ClassifyStyle(expected)]);
    if (v.row == 1 && t->warp.applied) {
      ++warped;
      ratio_sum += t->warp.ratio;
    }
  }
  ASSERT_GT(warped, 0) << "no pair was time-warped: the rows test nothing";
  EXPECT_EQ(timed->rows[1].time_warped, warped);
  EXPECT_NEAR(timed->rows[1].time_warp_ratio, ratio_sum / warped, 1e-9);
  EXPECT_EQ(timed->rows[0].time_warped, 0);
  // The timing rows differ from the content-timed transfers' where a warp
  // was applied (their jitter is measured over other frames).
  EXPECT_NE(timed->rows[1].jitter, timed->rows[0].jitter);
  EXPECT_NE(timed->Markdown().find("Style timing (timed, no post-processing): "),
            std::string::npos);

  // The motion-only judge beside the pose judges: its verdict on every
  // output, counted against the style clip's style and the content clip's.
  ASSERT_TRUE(TrainMotionJudge(jo).ok());
  absl::StatusOr<std::unique_ptr<MotionJudge>> motion_judge = MotionJudge::Load(jo.out);
  ASSERT_TRUE(motion_judge.ok()) << motion_judge.status();
  absl::StatusOr<EvalReport> with_motion =
      Evaluate({{"model", model->get(), false}}, **judges, nullptr, {}, *pairs, {}, nullptr,
               motion_judge->get());
  ASSERT_TRUE(with_motion.ok()) << with_motion.status();
  ASSERT_TRUE(with_motion->motion_judge);
  const int identity = with_motion->identity_row;
  int motion_right = 0, motion_source = 0;
  for (const EvalVerdict& v : with_motion->verdicts) {
    if (v.row != identity) continue;
    const motion::Motion content = *motion::ReadBvhFile((*pairs)[v.pair].content_path);
    const auto& styles = (*motion_judge)->styles();
    EXPECT_EQ(v.motion_style, styles[*(*motion_judge)->ClassifyStyle(content)]);
    motion_right += v.motion_style == motion::ParseClipName((*pairs)[v.pair].style_path)->style;
    motion_source += v.motion_style == motion::ParseClipName((*pairs)[v.pair].content_path)->style;
  }
  const EvalRow& id_row = with_motion->rows[identity];
  EXPECT_NEAR(id_row.motion_style_accuracy, double(motion_right) / pairs->size(), 1e-12);
  EXPECT_NEAR(id_row.motion_source_style, double(motion_source) / pairs->size(), 1e-12);
  EXPECT_NE(with_motion->Markdown().find("| motion judge: style |"), std::string::npos);
  EXPECT_EQ(report->Markdown().find("motion judge"), std::string::npos);
  const std::string by_style = with_motion->ByStyleMarkdown(*pairs);
  EXPECT_EQ(by_style.rfind("| output | old | proud |\n", 0), 0u) << by_style;
  EXPECT_NE(by_style.find(" / "), std::string::npos);
}

// --random-starts: the same seed draws other windows (so other weights),
// the judges still learn the tiny set's labels, and labels.txt says how
// they were trained.
// --random-starts and --swap-parts: each draws other windows (so other
// weights from the same seed), learns, and is recorded in labels.txt.
TEST(EvaluationTest, JudgesTrainedOnRandomStartsOrSwappedPartsRecordIt) {
  const std::string data = TinyDataset();
  struct Variant {
    std::string name;
    bool random_starts;
    double swap_parts;
    std::vector<std::string> recorded;
  };
  const std::vector<Variant> variants = {
      {"grid", false, 0, {"random_starts = 0", "swap_parts = 0\n"}},
      {"random", true, 0, {"random_starts = 1", "swap_parts = 0\n"}},
      {"swap", false, 0.5, {"random_starts = 0", "swap_parts = 0.5\n"}}};
  std::map<std::string, std::string> weights;
  for (const Variant& v : variants) {
    JudgeTrainOptions jo;
    jo.data = {data};
    jo.out = ::testing::TempDir() + "/judges_" + v.name;
    jo.iterations = 400;
    jo.batch = 8;
    jo.random_starts = v.random_starts;
    jo.swap_parts = v.swap_parts;
    jo.log = [](const std::string&) {};
    absl::StatusOr<JudgeAccuracy> acc = TrainJudges(jo);
    ASSERT_TRUE(acc.ok()) << acc.status();
    std::printf("%s: held-out style %.2f content %.2f\n", v.name.c_str(), acc->style, acc->content);
    EXPECT_GE(acc->content, 0.75) << v.name;
    std::ifstream labels(jo.out + "/labels.txt");
    const std::string text((std::istreambuf_iterator<char>(labels)), {});
    for (const std::string& line : v.recorded) {
      EXPECT_NE(text.find(line), std::string::npos) << v.name << ": " << line << " in " << text;
    }
    std::ifstream w(jo.out + "/content.pt", std::ios::binary);
    weights[v.name] = std::string((std::istreambuf_iterator<char>(w)), {});
    ASSERT_TRUE(Judges::Load(jo.out).ok());
  }
  EXPECT_NE(weights["grid"], weights["random"]);
  EXPECT_NE(weights["grid"], weights["swap"]);
}

TEST(FeatureMetricsTest, DistancesAreZeroForIdenticalSetsAndGrowWithAShift) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  std::vector<std::vector<double>> a(300, std::vector<double>(8)), b = a, shifted;
  for (auto& v : a)
    for (double& x : v) x = g(rng);
  for (auto& v : b)
    for (double& x : v) x = g(rng);
  for (const auto& v : a) {
    shifted.push_back(v);
    for (double& x : shifted.back()) x += 1.0;
  }
  EXPECT_NEAR(FrechetDistance(a, a), 0, 1e-6);
  EXPECT_LT(FrechetDistance(a, b), 0.5);               // Same distribution, other samples.
  EXPECT_NEAR(FrechetDistance(a, shifted), 8.0, 0.2);  // |mean shift|^2 = 8.
  const auto same = KernelInceptionDistance(a, b, 10, 100, 1);
  const auto moved = KernelInceptionDistance(a, shifted, 10, 100, 1);
  EXPECT_LT(std::abs(same.first), 3 * same.second + 0.05);
  EXPECT_GT(moved.first, 10 * std::abs(same.first) + 0.1);
  EXPECT_NEAR(Diversity(a, 2000, 1), std::sqrt(2.0 * 8), 0.4);  // E|x-y| for N(0, I_8).
  FeatureMap f{2, 3, {1, 2, 3, 4, 5, 6}}, h = f;
  EXPECT_EQ(ContentDistance(f, h), 0);
  EXPECT_EQ(StyleDistance(f, h), 0);
  h.values[0] = 2;
  EXPECT_NEAR(ContentDistance(f, h), 1.0 / 6, 1e-12);
  EXPECT_GT(StyleDistance(f, h), 0);
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

// Same-action pairs: the style clip does the content's action (its label, in
// its dataset) in another style; the validation and test halves split the
// content clips between them, every clip in one.
TEST(EvaluationTest, PairKindsAndTheValidationAndTestHalves) {
  STYLUS_REQUIRE_BANDAI(dir);
  const std::vector<std::string> dirs = {dir + "/dataset-1", dir + "/dataset-2"};
  absl::StatusOr<std::vector<EvalPair>> same = MakeEvalPairs(dirs, 3, PairKind::kSameAction);
  ASSERT_TRUE(same.ok()) << same.status();
  EXPECT_GT(same->size(), 150u);
  for (const EvalPair& p : *same) {
    const auto c = *motion::ParseClipName(p.content_path), s = *motion::ParseClipName(p.style_path);
    EXPECT_EQ(c.content, s.content);
    EXPECT_EQ(c.dataset, s.dataset);
    EXPECT_NE(c.style, s.style);
  }
  std::set<std::string> all, halves;
  const absl::StatusOr<std::vector<EvalPair>> every = MakeEvalPairs(dirs, 3);
  ASSERT_TRUE(every.ok()) << every.status();
  for (const EvalPair& p : *every) all.insert(p.content_path);
  size_t in_validation = 0;
  for (EvalSplit split : {EvalSplit::kValidation, EvalSplit::kTest}) {
    const absl::StatusOr<std::vector<EvalPair>> half =
        MakeEvalPairs(dirs, 3, PairKind::kCrossAction, split);
    ASSERT_TRUE(half.ok()) << half.status();
    for (const EvalPair& p : *half) {
      EXPECT_TRUE(InEvalSplit(p.content_path, split));
      EXPECT_FALSE(InEvalSplit(
          p.content_path, split == EvalSplit::kTest ? EvalSplit::kValidation : EvalSplit::kTest));
      halves.insert(p.content_path);
      in_validation += split == EvalSplit::kValidation;
    }
  }
  EXPECT_EQ(halves, all);
  EXPECT_GT(in_validation, all.size());  // About half of 3 pairs per clip.
  EXPECT_EQ(ParseEvalSplit("holdout").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ParsePairKind("same").status().code(), absl::StatusCode::kInvalidArgument);
}

// The by-dataset table counts each verdict in its content clip's dataset and
// in "one dataset" or "two datasets".
TEST(EvaluationTest, AccuracyByDatasetSplitsThePairs) {
  const std::vector<EvalPair> pairs = {
      {"d/dataset-1_bow_old_001.bvh", "d/dataset-1_run_proud_001.bvh"},
      {"d/dataset-1_bow_old_001.bvh", "d/dataset-2_walk_elderly_001.bvh"},
      {"d/dataset-2_walk_active_001.bvh", "d/dataset-2_run_elderly_002.bvh"},
      {"d/dataset-2_run_normal_003.bvh", "d/dataset-1_bow_proud_002.bvh"}};
  EvalReport report;
  report.rows.resize(2);
  report.rows[0].name = "model", report.rows[1].name = "identity";
  // The model: style right on pairs 0, 1 and 3; content right on 1 and 2.
  const std::vector<std::pair<std::string, std::string>> model = {
      {"proud", "guide"}, {"elderly", "bow"}, {"normal", "walk"}, {"proud", "walk"}};
  for (int p = 0; p < 4; ++p) {
    report.verdicts.push_back({p, 0, model[p].first, model[p].second});
    const auto content = motion::ParseClipName(pairs[p].content_path);
    report.verdicts.push_back({p, 1, content->style, content->content});
  }
  const std::string table = report.ByDatasetMarkdown(pairs);
  EXPECT_EQ(table,
            "| output | content from dataset-1 (2 pairs) | content from dataset-2 (2 pairs) | both "
            "clips from one dataset (2 pairs) | from two datasets (2 pairs) |\n"
            "| --- | --- | --- | --- | --- |\n"
            "| model | 1.000 / 0.500 | 0.500 / 0.500 | 0.500 / 0.500 | 1.000 / 0.500 |\n"
            "| identity | 0.000 / 1.000 | 0.000 / 1.000 | 0.000 / 1.000 | 0.000 / 1.000 |\n")
      << table;
}

}  // namespace
}  // namespace stylus::model
