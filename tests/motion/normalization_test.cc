#include "motion/normalization.h"

#include <cmath>

#include "gtest/gtest.h"

namespace stylus::motion {
namespace {

FeatureClip Clip(int frames, int dim, float scale) {
  FeatureClip c;
  c.frames = frames;
  c.dim = dim;
  for (int f = 0; f < frames; ++f)
    for (int k = 0; k < dim; ++k) c.values.push_back(k == 0 ? 5.f : scale * (f - k) + k);
  return c;
}

TEST(NormalizationTest, StandardizesEveryChannelAndInverts) {
  const FeatureClip a = Clip(50, 4, 2), b = Clip(30, 4, -1);
  absl::StatusOr<NormStats> s = NormStats::Compute({&a, &b}, {"c", "x", "y", "z"});
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->std[0], 1.f);  // Constant channel passes through.
  FeatureClip n = a;
  s->Normalize(&n);
  FeatureClip both = n;
  FeatureClip nb = b;
  s->Normalize(&nb);
  both.values.insert(both.values.end(), nb.values.begin(), nb.values.end());
  both.frames += nb.frames;
  for (int k = 1; k < 4; ++k) {
    double mean = 0, sq = 0;
    for (int f = 0; f < both.frames; ++f) mean += both.row(f)[k];
    mean /= both.frames;
    for (int f = 0; f < both.frames; ++f) sq += (both.row(f)[k] - mean) * (both.row(f)[k] - mean);
    EXPECT_NEAR(mean, 0, 1e-5);
    EXPECT_NEAR(std::sqrt(sq / both.frames), 1, 1e-4);
  }
  s->Denormalize(&n);
  for (size_t i = 0; i < n.values.size(); ++i) EXPECT_NEAR(n.values[i], a.values[i], 1e-4);
}

TEST(NormalizationTest, SerializationRoundTripsExactly) {
  const FeatureClip a = Clip(20, 6, 0.37f);
  NormStats s = *NormStats::Compute({&a});
  const std::string path = ::testing::TempDir() + "/norm_test.txt";
  ASSERT_TRUE(s.Save(path).ok());
  absl::StatusOr<NormStats> back = NormStats::Load(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->mean, s.mean);
  EXPECT_EQ(back->std, s.std);
  EXPECT_EQ(back->names, s.names);
}

TEST(NormalizationTest, MalformedFilesAreErrorsWithLines) {
  EXPECT_FALSE(NormStats::Parse("", "f").ok());
  EXPECT_FALSE(NormStats::Parse("stylus-norm 1 2\na 0 1\n", "f").ok());
  const absl::Status s = NormStats::Parse("stylus-norm 1 2\na 0 1\nb 0 0\n", "f").status();
  EXPECT_NE(s.message().find("f:3:"), std::string::npos) << s;
  EXPECT_FALSE(NormStats::Parse("stylus-norm 1 1\na nan 1\n", "f").ok());
  EXPECT_EQ(NormStats::Load("/no/such/file").status().code(), absl::StatusCode::kNotFound);
  FeatureClip wide = Clip(3, 5, 1), narrow = Clip(3, 4, 1);
  EXPECT_FALSE(NormStats::Compute({&wide, &narrow}).ok());
  EXPECT_FALSE(NormStats::Compute({}).ok());
}

}  // namespace
}  // namespace stylus::motion
