// Shared by the contrastive family's tests: a tiny configuration trained on
// four synthesized walks (no dataset needed), and a fixture holding one such
// package per test process.
#ifndef STYLUS_TESTS_MODEL_CONTRASTIVE_CONTRASTIVE_SUPPORT_H_
#define STYLUS_TESTS_MODEL_CONTRASTIVE_CONTRASTIVE_SUPPORT_H_

#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "motion/bvh.h"
#include "tests/model/synth_clips.h"
#include "train/contrastive_trainer.h"

namespace stylus::model::contrastive_testing {

inline std::string Dir(const std::string& name) { return testing::FreshDir("contrastive_" + name); }

inline ContrastiveTrainOptions TinyOptions(const std::string& out, int iterations) {
  ContrastiveTrainOptions o;
  o.data = testing::FourClips();
  o.out = out;
  o.config.channels = 16;
  o.config.window = 16;
  o.config.hop = 12;
  o.config.batch = 8;
  o.config.lr = 2e-3;
  o.config.iterations = iterations;
  o.config.seed = 7;
  o.log_every = 10;
  o.checkpoint_every = 40;
  o.threads = 1;
  o.log = [](const std::string&) {};
  return o;
}

inline motion::Motion Clip(int i) { return *motion::ReadBvhFile(testing::FourClips()[i]); }

// Appends `text` to <dir>/config.txt.
inline void AppendConfig(const std::string& dir, const std::string& text) {
  std::ofstream(dir + "/config.txt", std::ios::app) << text;
}

// One tiny live package per lookahead and generator form, trained once per
// test process.
inline std::shared_ptr<const ContrastiveModel> LivePackage(int lookahead,
                                                           bool frame_residual = false,
                                                           int dilation_growth = 1) {
  static std::map<int, std::shared_ptr<const ContrastiveModel>>* packages =
      new std::map<int, std::shared_ptr<const ContrastiveModel>>();
  const int key = 100 * dilation_growth + 2 * lookahead + (frame_residual ? 1 : 0);
  auto it = packages->find(key);
  if (it != packages->end()) return it->second;
  const std::string dir = Dir("live" + std::to_string(key));
  ContrastiveTrainOptions o = TinyOptions(dir, 20);
  o.config.live = true;
  o.config.lookahead = lookahead;
  o.config.frame_residual = frame_residual;
  o.config.dilation_growth = dilation_growth;
  o.config.keep_path = true;
  EXPECT_TRUE(TrainContrastive(o).ok());
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> m = ContrastiveModel::Load(dir);
  EXPECT_TRUE(m.ok()) << m.status();
  std::shared_ptr<const ContrastiveModel> model = std::move(*m);
  (*packages)[key] = model;
  return model;
}

class TrainedModelTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(Dir("trained"));
    ASSERT_TRUE(TrainContrastive(TinyOptions(*dir_, 40)).ok());
  }
  inline static std::string* dir_ = nullptr;
};

}  // namespace stylus::model::contrastive_testing

#endif  // STYLUS_TESTS_MODEL_CONTRASTIVE_CONTRASTIVE_SUPPORT_H_
