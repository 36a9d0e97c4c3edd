// Training of the `contrastive` family: self-supervised (no labels), or
// label-guided (ContrastiveConfig::guided, docs/notes/contrastive.md); with
// periodic checkpoints, resumable, deterministic for a seed.
#ifndef STYLUS_TRAIN_CONTRASTIVE_TRAINER_H_
#define STYLUS_TRAIN_CONTRASTIVE_TRAINER_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "model/contrastive/contrastive_config.h"
#include "train/clip_sources.h"

namespace stylus::model {

struct LossRecord {
  int iteration = 0;
  double rec = 0, gan = 0, nce = 0, tri = 0, disc = 0, total = 0;
  // Label-guided training only: the transfers' classification loss, the
  // cycle loss and the critic's own loss on real windows.
  double cls = 0, cyc = 0, critic = 0;
  // With dynamics_weight: the dynamics style term.
  double dyn = 0;
  // With teacher_weight: the distance to the teacher's transfer.
  double teach = 0;
  // With motion_gan_weight: the generator's and the motion discriminator's
  // losses; with motion_class_weight: the transfers' loss against the motion
  // critic and the critic's own loss on real windows.
  double mgan = 0, mdisc = 0, mcls = 0, mcritic = 0;
  // With paired_weight: the distance to the paired targets.
  double pair = 0;
  // With motion_rec_weight / own_rec_weight: those terms.
  double mrec = 0, own = 0;
};

struct ContrastiveTrainOptions {
  std::vector<std::string> data;     // Directories (training split) or .bvh files.
  TrainingDataOptions data_options;  // Labels CSV, the package's skeleton.
  std::string out;                   // Package directory, e.g. models/contrastive/v10.
  ContrastiveConfig config;          // dim is filled from the data.
  bool resume = false;               // Continue from out/checkpoint if present.
  // A package whose weights.pt starts the networks (fine-tuning); its shapes
  // must fit `config`. Ignored when resuming (the checkpoint has them).
  std::string init_from;
  int checkpoint_every = 500;  // Iterations; also rewrites the package.
  int log_every = 50;
  int threads = 0;     // LibTorch intra-op threads; 0 = all cores.
  std::string commit;  // Recorded in config.txt.
  // Progress lines (default: stderr).
  std::function<void(const std::string&)> log;
  // Called with each logged average (tests read the curve through it).
  std::function<void(const LossRecord&)> on_record;
};

// Trains to options.config.iterations, writing the package (config.txt,
// norm.txt, skeleton.bvh, weights.pt, loss.csv) at every checkpoint and at
// the end. FAILED_PRECONDITION when `resume` is set but the checkpoint was
// made with another configuration; INVALID_ARGUMENT for bad data.
absl::Status TrainContrastive(const ContrastiveTrainOptions& options);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_CONTRASTIVE_TRAINER_H_
