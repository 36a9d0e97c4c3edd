// Distillation from a teacher package (train/teacher.h): its transfer in any
// student's normalization, what it refuses, and a student pulled towards it.
#include "train/teacher.h"

#include <cstdio>
#include <vector>

#include "gtest/gtest.h"
#include "tests/train/contrastive_training_support.h"

namespace stylus::model {
namespace {

using contrastive_testing::GuidedOptions;

// One tiny offline teacher per test process: guided, with the inference keys
// the teacher applies (smoothing, the content's detail, the content's path).
const std::string& TeacherDir() {
  static const std::string* dir = [] {
    auto* d = new std::string(testing::FreshDir("teacher"));
    ContrastiveTrainOptions o = GuidedOptions(*d, 40);
    o.config.keep_path = true;
    o.config.smooth_sigma = 1;
    o.config.content_detail = 0.5;
    EXPECT_TRUE(TrainContrastive(o).ok());
    return d;
  }();
  return *dir;
}

TEST(TeacherTest, GivesOneTransferWhateverTheStudentsNormalization) {
  absl::StatusOr<motion::NormStats> own = motion::NormStats::Load(TeacherDir() + "/norm.txt");
  ASSERT_TRUE(own.ok()) << own.status();
  const int dim = own->dim();
  // A student whose statistics differ from the teacher's on every channel.
  motion::NormStats other = *own;
  for (int c = 0; c < dim; ++c) {
    other.mean[c] += 0.3f * own->std[c] * static_cast<float>(c % 5 - 2);
    other.std[c] *= 1.0f + 0.1f * static_cast<float>(c % 3);
  }
  absl::StatusOr<Teacher> same = Teacher::Load(TeacherDir(), dim, *own);
  absl::StatusOr<Teacher> converted = Teacher::Load(TeacherDir(), dim, other);
  ASSERT_TRUE(same.ok()) << same.status();
  ASSERT_TRUE(converted.ok()) << converted.status();

  torch::manual_seed(5);
  const torch::Tensor x = torch::randn({2, dim, 16}), style = torch::randn({2, dim, 16});
  auto tensor = [dim](const std::vector<float>& v) {
    return torch::tensor(v).reshape({1, dim, 1});
  };
  const torch::Tensor mean = tensor(own->mean), std = tensor(own->std);
  const torch::Tensor mean_o = tensor(other.mean), std_o = tensor(other.std);
  auto to_other = [&](const torch::Tensor& t) { return (t * std + mean - mean_o) / std_o; };
  const torch::Tensor y = same->Transfer(x, style) * std + mean;
  const torch::Tensor y_o = converted->Transfer(to_other(x), to_other(style)) * std_o + mean_o;
  EXPECT_LT((y - y_o).abs().max().item<float>(), 1e-3 * y.abs().max().item<float>());
  // The transfer restyles: it is not the content.
  EXPECT_GT((same->Transfer(x, style) - x).abs().mean().item<float>(), 1e-2);
  // No gradient flows into the teacher.
  EXPECT_FALSE(same->Transfer(x.requires_grad_(), style).requires_grad());
}

// At a strength below 1 the teacher gives its guard's weaker form: at 0 the
// content itself, in between a change that grows with the strength.
TEST(TeacherTest, WeakerFormsComeBetweenTheContentAndTheFullTransfer) {
  absl::StatusOr<motion::NormStats> own = motion::NormStats::Load(TeacherDir() + "/norm.txt");
  ASSERT_TRUE(own.ok()) << own.status();
  const int dim = own->dim();
  torch::manual_seed(7);
  const torch::Tensor x = torch::randn({2, dim, 16}), style = torch::randn({2, dim, 16});
  std::vector<double> change;
  for (double k : {0.0, 0.4, 0.8}) {
    absl::StatusOr<Teacher> t = Teacher::Load(TeacherDir(), dim, *own, k);
    ASSERT_TRUE(t.ok()) << t.status();
    change.push_back(Teacher::PoseL1(t->Transfer(x, style), x).item<double>());
  }
  EXPECT_LT(change[0], 1e-5);
  EXPECT_GT(change[1], 1e-3);
  EXPECT_GT(change[2], change[1]);
}

TEST(TeacherTest, RefusesLivePackagesAndOtherFeatures) {
  absl::StatusOr<motion::NormStats> own = motion::NormStats::Load(TeacherDir() + "/norm.txt");
  ASSERT_TRUE(own.ok());
  EXPECT_EQ(Teacher::Load(TeacherDir(), own->dim() + 1, *own).status().code(),
            absl::StatusCode::kFailedPrecondition);
  motion::NormStats renamed = *own;
  renamed.names[0] = "something_else";
  EXPECT_EQ(Teacher::Load(TeacherDir(), own->dim(), renamed).status().code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(Teacher::Load(testing::FreshDir("no_teacher"), own->dim(), *own).status().code(),
            absl::StatusCode::kNotFound);
  const std::string live = testing::FreshDir("live_teacher");
  ContrastiveTrainOptions o = GuidedOptions(live, 2);
  o.config.live = true;
  o.config.window = 32;
  ASSERT_TRUE(TrainContrastive(o).ok());
  absl::StatusOr<Teacher> t = Teacher::Load(live, own->dim(), *own);
  EXPECT_EQ(t.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(t.status().message().find("live package"), std::string::npos) << t.status();
}

// A live student distilled from the teacher comes closer to its transfers
// than one trained alike without the term.
TEST(TeacherTest, ALiveStudentComesCloserToTheTeacher) {
  auto run = [](const std::string& dir, double weight) {
    std::vector<LossRecord> curve;
    ContrastiveTrainOptions o = GuidedOptions(dir, 80);
    o.config.live = true;
    o.config.window = 32;
    o.config.frame_residual = true;
    o.config.teacher = TeacherDir();
    o.config.teacher_weight = weight;
    o.on_record = [&](const LossRecord& r) { curve.push_back(r); };
    EXPECT_TRUE(TrainContrastive(o).ok());
    return curve;
  };
  // The distance is recorded with any weight above 0; a tiny weight barely
  // steers the student.
  const std::string taught_dir = testing::FreshDir("student_taught");
  const std::vector<LossRecord> free = run(testing::FreshDir("student_free"), 1e-6);
  const std::vector<LossRecord> taught = run(taught_dir, 30);
  ASSERT_EQ(free.size(), taught.size());
  ASSERT_GE(free.size(), 6u);
  const double first = taught[0].teach;
  const double free_end = contrastive_testing::MeanOfLastRows(free, &LossRecord::teach, 3);
  const double taught_end = contrastive_testing::MeanOfLastRows(taught, &LossRecord::teach, 3);
  std::printf("distance to the teacher: first %.3f, end free %.3f, end taught %.3f\n", first,
              free_end, taught_end);
  EXPECT_GT(first, 0);
  EXPECT_LT(taught_end, 0.8 * free_end);
  // The package says what it was distilled from.
  absl::StatusOr<ContrastiveConfig> c = contrastive_testing::ReadPackageConfig(taught_dir);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->teacher, TeacherDir());
  EXPECT_DOUBLE_EQ(c->teacher_weight, 30);
}

}  // namespace
}  // namespace stylus::model
