// Training of the `cyclic` family (paper 004, docs/notes/cyclic.md): the
// autoencoder alone first, then the generator with the style, content,
// adversarial, cycle and kinematic losses, the encoder frozen so the hidden
// space the style is measured in stays fixed. No labels. Periodic
// checkpoints, resumable, deterministic for a seed.
#ifndef STYLUS_TRAIN_CYCLIC_TRAINER_H_
#define STYLUS_TRAIN_CYCLIC_TRAINER_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "model/cyclic/cyclic_config.h"
#include "train/clip_sources.h"
#include "train/training_run.h"

namespace stylus::model {

struct CyclicTrainOptions {
  std::vector<std::string> data;     // Directories (training split) or .bvh files.
  TrainingDataOptions data_options;  // Labels CSV, the package's skeleton.
  std::string out;                   // Package directory, e.g. models/cyclic/v1.
  CyclicConfig config;               // dim is filled from the data.
  bool resume = false;
  // Start from this package's weights (same architecture), e.g. to train the
  // generator stage again on an autoencoder already trained (set
  // config.ae_iterations to 0). Ignored when resuming from a checkpoint.
  std::string init_from;
  int checkpoint_every = 500;
  int log_every = 50;
  int threads = 0;
  std::string commit;
  std::function<void(const std::string&)> log;
  // Each logged row (its values named as in CyclicLossNames()).
  std::function<void(const LossRow&)> on_record;
};

// rec, style, content, gan, cycle, smooth, bone, traj, foot, disc, cls (the
// transfers' classification loss), labels (the label critic's own loss on
// real windows; both 0 unless guided), total.
const std::vector<std::string>& CyclicLossNames();

// Trains to options.config.iterations, writing the package (config.txt,
// norm.txt, skeleton.bvh, weights.pt, loss.csv) at every checkpoint and at
// the end. FAILED_PRECONDITION when resuming a checkpoint of another
// configuration; INVALID_ARGUMENT for bad data or options.
absl::Status TrainCyclic(const CyclicTrainOptions& options);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_CYCLIC_TRAINER_H_
