#include "model/contrastive/contrastive_config.h"

#include "gtest/gtest.h"

namespace stylus::model {
namespace {

TEST(ContrastiveConfigTest, EveryFieldSurvivesSerializeAndParse) {
  ContrastiveConfig c;
  c.window = 48, c.hop = 36, c.dim = 162, c.channels = 64, c.res_kernel = 5;
  c.alpha = 0.1, c.beta = 0.6, c.gamma = 0.2, c.margin = 0.5, c.temperature = 0.2;
  c.use_nce = false, c.use_tri = false, c.cross_view = false;
  c.content_weight = 0.5, c.guided = true, c.class_weight = 2, c.cycle_weight = 3;
  c.content_class_weight = 2.5, c.content_balance = 0.5;
  c.motion_class_weight = 1, c.motion_content_weight = 0.25, c.paired_weight = 2;
  c.motion_rec_weight = 0.5, c.own_rec_weight = 1.5;
  c.pair_gan = true, c.keep_path = true, c.smooth_sigma = 1.5, c.style_strength = 0.7;
  c.residual = true, c.random_starts = true, c.mirror = true, c.style_from_motion = true;
  c.bottleneck_channels = 12, c.bottleneck_pool = 2;
  c.batch = 8, c.lr = 3e-4, c.iterations = 123, c.seed = 99, c.trained_iterations = 77;
  c.data = "../shared/data/bandai", c.commit = "abc123";
  absl::StatusOr<ContrastiveConfig> back = ContrastiveConfig::Parse(c.Serialize(), "config.txt");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Serialize(), c.Serialize());
  EXPECT_FALSE(back->cross_view);
  EXPECT_TRUE(back->pair_gan);
  EXPECT_TRUE(back->keep_path);
  EXPECT_DOUBLE_EQ(back->smooth_sigma, 1.5);
  EXPECT_DOUBLE_EQ(back->style_strength, 0.7);
  EXPECT_TRUE(back->residual);
  EXPECT_TRUE(back->random_starts);
  EXPECT_TRUE(back->mirror);
  EXPECT_TRUE(back->style_from_motion);
  EXPECT_EQ(back->bottleneck_channels, 12);
  EXPECT_EQ(back->bottleneck_pool, 2);
  EXPECT_DOUBLE_EQ(back->content_class_weight, 2.5);
  EXPECT_DOUBLE_EQ(back->content_balance, 0.5);
  EXPECT_DOUBLE_EQ(back->motion_class_weight, 1);
  EXPECT_DOUBLE_EQ(back->MotionContentWeight(), 0.25);
  EXPECT_DOUBLE_EQ(back->paired_weight, 2);
  EXPECT_DOUBLE_EQ(back->motion_rec_weight, 0.5);
  EXPECT_DOUBLE_EQ(back->own_rec_weight, 1.5);
}

TEST(ContrastiveConfigTest, TheBottleneckIsOfflineAndItsPoolNeedsChannels) {
  ContrastiveConfig c;
  c.dim = 162;
  EXPECT_EQ(c.Serialize().find("bottleneck"), std::string::npos);  // Off: not written.
  const std::string base = c.Serialize();
  absl::StatusOr<ContrastiveConfig> live =
      ContrastiveConfig::Parse(base + "live = 1\nbottleneck_channels = 8\n", "config.txt");
  ASSERT_FALSE(live.ok());
  EXPECT_NE(live.status().message().find("'bottleneck_channels' is for offline packages"),
            std::string::npos)
      << live.status();
  absl::StatusOr<ContrastiveConfig> pool_alone =
      ContrastiveConfig::Parse(base + "bottleneck_pool = 2\n", "config.txt");
  ASSERT_FALSE(pool_alone.ok());
  EXPECT_NE(pool_alone.status().message().find("needs 'bottleneck_channels'"), std::string::npos)
      << pool_alone.status();
  absl::StatusOr<ContrastiveConfig> zero_pool =
      ContrastiveConfig::Parse(base + "bottleneck_channels = 8\nbottleneck_pool = 0\n", "c.txt");
  ASSERT_FALSE(zero_pool.ok());
  EXPECT_NE(zero_pool.status().message().find("c.txt:"), std::string::npos) << zero_pool.status();
}

TEST(ContrastiveConfigTest, TheStyleFilterIsOfflineOddAndRoundTrips) {
  ContrastiveConfig c;
  c.dim = 162;
  EXPECT_EQ(c.Serialize().find("style_filter"), std::string::npos);  // Off: not written.
  const std::string base = c.Serialize();
  c.style_filter_taps = 9;
  absl::StatusOr<ContrastiveConfig> back = ContrastiveConfig::Parse(c.Serialize(), "config.txt");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->style_filter_taps, 9);
  absl::StatusOr<ContrastiveConfig> even =
      ContrastiveConfig::Parse(base + "style_filter_taps = 4\n", "c.txt");
  ASSERT_FALSE(even.ok());
  EXPECT_NE(even.status().message().find("must be odd"), std::string::npos) << even.status();
  absl::StatusOr<ContrastiveConfig> live =
      ContrastiveConfig::Parse(base + "live = 1\nstyle_filter_taps = 9\n", "config.txt");
  ASSERT_FALSE(live.ok());
  EXPECT_NE(live.status().message().find("'style_filter_taps' is for offline packages"),
            std::string::npos)
      << live.status();
}

TEST(ContrastiveConfigTest, ContentDetailRoundTrips) {
  ContrastiveConfig c;
  c.dim = 162, c.smooth_sigma = 3, c.content_detail = 0.5, c.detail_sigma = 2;
  absl::StatusOr<ContrastiveConfig> back = ContrastiveConfig::Parse(c.Serialize(), "config.txt");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Serialize(), c.Serialize());
  EXPECT_DOUBLE_EQ(back->content_detail, 0.5);
  EXPECT_DOUBLE_EQ(back->DetailSigma(), 2);
  c.detail_sigma = 0;  // Falls back to the output smoothing's sigma.
  EXPECT_DOUBLE_EQ(ContrastiveConfig::Parse(c.Serialize(), "c")->DetailSigma(), 3);
}

TEST(ContrastiveConfigTest, ContentGuardRoundTripsAndChecksItsStrengths) {
  ContrastiveConfig c;
  c.dim = 162, c.content_guard = true, c.guard_strengths = {0.9, 0.5, 0},
  c.guard_min_probability = 0.4;
  absl::StatusOr<ContrastiveConfig> back = ContrastiveConfig::Parse(c.Serialize(), "config.txt");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Serialize(), c.Serialize());
  EXPECT_TRUE(back->content_guard);
  EXPECT_EQ(back->guard_strengths, (std::vector<double>{0.9, 0.5, 0}));
  EXPECT_DOUBLE_EQ(back->guard_min_probability, 0.4);
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\n", "c")->content_guard);  // Off by default.
  for (const char* bad :
       {"1,1", "0.4,0.7", "1,x", "1.5", "", "1,0.9,0.8,0.7,0.6,0.5,0.4,0.3,0.2"}) {
    const absl::Status s =
        ContrastiveConfig::Parse(std::string("dim = 10\nguard_strengths = ") + bad + "\n", "c.txt")
            .status();
    EXPECT_NE(s.message().find("c.txt:2: "), std::string::npos) << bad << ": " << s;
  }
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\nguard_min_probability = 2\n", "c").ok());
}

TEST(ContrastiveConfigTest, ErrorsNameTheLine) {
  const absl::Status unknown = ContrastiveConfig::Parse("dim = 10\nwings = 2\n", "c.txt").status();
  EXPECT_NE(unknown.message().find("c.txt:2: unknown key 'wings'"), std::string::npos) << unknown;
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\nwindow = 31\n", "c.txt").ok());  // Odd window.
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\nuse_nce = yes\n", "c.txt").ok());
  EXPECT_FALSE(ContrastiveConfig::Parse("family = cyclic\ndim = 10\n", "c.txt").ok());
  EXPECT_FALSE(ContrastiveConfig::Parse("window = 32\n", "c.txt").ok());  // No dim.
  EXPECT_FALSE(ContrastiveConfig::Parse("dim = 10\nsmooth_sigma = -1\n", "c.txt").ok());
}

// Keys of experiments that were taken out: an old package that sets one
// fails to load with a message naming the key and its line.
TEST(ContrastiveConfigTest, RemovedExperimentKeysAreNamed) {
  for (const char* key :
       {"local_style", "keep_amplitude", "replicate_pad", "full_rate_content", "centred_style",
        "self_rec_weight", "pair_offset_weight", "content_body"}) {
    const absl::Status s =
        ContrastiveConfig::Parse(std::string("dim = 10\n") + key + " = 0\n", "c.txt").status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << key;
    EXPECT_NE(s.message().find(std::string("c.txt:2: '") + key + "' was an experiment"),
              std::string::npos)
        << s;
  }
}

}  // namespace
}  // namespace stylus::model
