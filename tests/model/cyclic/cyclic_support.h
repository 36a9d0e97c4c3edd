// Shared by the cyclic family's tests: a tiny configuration, its training
// options on four synthesized walks (no dataset needed), and a clip's
// normalized network channels.
#ifndef STYLUS_TESTS_MODEL_CYCLIC_CYCLIC_SUPPORT_H_
#define STYLUS_TESTS_MODEL_CYCLIC_CYCLIC_SUPPORT_H_

#include <string>
#include <vector>

#include "model/cyclic/cyclic_config.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/normalization.h"
#include "tests/model/synth_clips.h"
#include "train/cyclic_trainer.h"

namespace stylus::model::cyclic_testing {

inline std::string Dir(const std::string& name) { return testing::FreshDir("cyclic_" + name); }

inline motion::Motion Clip(int i) { return *motion::ReadBvhFile(testing::FourClips()[i]); }

inline CyclicConfig Tiny() {
  CyclicConfig c;
  c.window = 16;
  c.hop = 8;
  c.hidden = 24;
  c.kernel = 5;
  c.dropout = 0;
  c.batch = 8;
  c.lr = 2e-3;
  c.ae_iterations = 60;
  c.iterations = 200;
  c.seed = 3;
  return c;
}

inline CyclicTrainOptions TinyOptions(const std::string& out) {
  CyclicTrainOptions o;
  o.data = testing::FourClips();
  o.out = out;
  o.config = Tiny();
  o.log_every = 10;
  o.checkpoint_every = 50;
  o.threads = 1;
  o.log = [](const std::string&) {};
  return o;
}


// Trains the autoencoder stage alone on the labelled clips (into
// Dir(name + "_ae"); its loss rows into `ae_rows` when given) and returns the
// options of a guided style-network run (8 values, 2 blocks) of
// `iterations` that starts from it, into Dir(name).
inline CyclicTrainOptions StyleNetworkAfterAutoencoder(const std::string& name, int iterations,
                                                       std::vector<LossRow>* ae_rows = nullptr) {
  CyclicTrainOptions ae = TinyOptions(Dir(name + "_ae"));
  ae.data = testing::LabelledClips();
  ae.config.iterations = ae.config.ae_iterations;  // The autoencoder stage only.
  if (ae_rows != nullptr) ae.on_record = [ae_rows](const LossRow& r) { ae_rows->push_back(r); };
  const absl::Status trained = TrainCyclic(ae);
  EXPECT_TRUE(trained.ok()) << trained;
  CyclicTrainOptions o = TinyOptions(Dir(name));
  o.data = testing::LabelledClips();
  o.config.guided = true;
  o.config.style_dim = 8, o.config.blocks = 2;
  o.config.ae_iterations = 0, o.config.iterations = iterations;
  o.init_from = ae.out;
  return o;
}

}  // namespace stylus::model::cyclic_testing

#endif  // STYLUS_TESTS_MODEL_CYCLIC_CYCLIC_SUPPORT_H_
