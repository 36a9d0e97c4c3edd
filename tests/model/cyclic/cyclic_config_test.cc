// model/cyclic/cyclic_config: config.txt round trip and errors.
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
#include "model/family_registry.h"
#include "model/package.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/model/cyclic/cyclic_support.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "train/cyclic_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace cyclic_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;

TEST(CyclicConfigTest, RoundTripAndErrors) {
  CyclicConfig c = Tiny();
  c.dim = 155;
  c.use_cycle = false;
  c.style_dim = 32, c.blocks = 3, c.guided = true, c.pair_gan = true, c.content_class_weight = 3;
  c.keep_weight = 2, c.average_from = 100, c.average_every = 25;
  c.random_starts = true, c.keep_path = true, c.content_balance = 0.5;
  c.adain_skip = true, c.mirror = true, c.rotations = true;
  absl::StatusOr<CyclicConfig> back = CyclicConfig::Parse(c.Serialize(), "x");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->Serialize(), c.Serialize());
  EXPECT_TRUE(back->random_starts);
  EXPECT_TRUE(back->keep_path);
  EXPECT_DOUBLE_EQ(back->content_balance, 0.5);
  EXPECT_TRUE(back->adain_skip);
  EXPECT_TRUE(back->mirror);
  EXPECT_TRUE(back->rotations);
  EXPECT_FALSE(CyclicConfig::Parse("dim = 5\n", "cfg.txt")->rotations);
  EXPECT_NE(CyclicConfig::Parse("dim = 5\ncritics = 2\n", "cfg.txt")
                .status()
                .message()
                .find("cfg.txt:2: 'critics' was an experiment"),
            std::string::npos);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\ncritics = 0\n", "cfg.txt").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nkernel = 4\n", "cfg.txt").status().message(),
            "cfg.txt:2: kernel must be odd");
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nfamily = contrastive\n", "cfg.txt").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(CyclicConfig::Parse("dim = 5\nbogus = 1\n", "cfg.txt").status().message(),
            "cfg.txt:2: unknown key 'bogus'");
}

}  // namespace
}  // namespace stylus::model
