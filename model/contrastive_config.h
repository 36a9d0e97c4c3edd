// Hyper-parameters of the `contrastive` family (paper 000, docs/contrastive.md),
// stored in a model package as `config.txt` (key = value lines).
#ifndef STYLUS_MODEL_CONTRASTIVE_CONFIG_H_
#define STYLUS_MODEL_CONTRASTIVE_CONFIG_H_

#include <cstdint>
#include <map>
#include <string>

#include "absl/status/statusor.h"

namespace stylus::model {

struct ContrastiveConfig {
  // Data and architecture.
  int window = 32;     // T frames per window.
  int hop = 24;        // Window stride (overlap T/4).
  int dim = 0;         // Feature channels d (set from the data).
  int channels = 144;  // Width of codes and hidden layers.
  int res_kernel = 3;  // Kernel of the residual blocks' convolutions.
  // Loss weights: L = L_rec + a L_gan + b L_nce + c L_tri.
  double alpha = 1.0, beta = 0.3, gamma = 0.3;
  double margin = 1.0;       // Triplet margin.
  double temperature = 0.1;  // InfoNCE temperature on unit-length codes.
  bool use_nce = true, use_tri = true;
  // Optimization.
  int batch = 16;
  double lr = 1e-4;
  int iterations = 20000;
  uint64_t seed = 1;
  // Provenance (filled by training).
  std::string family = "contrastive";
  std::string data;    // Data directories trained on.
  std::string commit;  // Source commit of the trainer.
  int trained_iterations = 0;

  std::string Serialize() const;
  // INVALID_ARGUMENT naming `source` and the line of a malformed or
  // out-of-range entry; unknown keys are errors too.
  static absl::StatusOr<ContrastiveConfig> Parse(const std::string& text,
                                                 const std::string& source);
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_CONFIG_H_
