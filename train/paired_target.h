// The paired term of label-guided training: Bandai has most actions in most
// styles, so a transfer of a content window to a style has a real example
// of what it should become, the same action performed in that style. The
// example is not aligned with the content (another take, another tempo):
// its window whose content code (Ec, trained to ignore style) is nearest
// the content window's is the target.
#ifndef STYLUS_TRAIN_PAIRED_TARGET_H_
#define STYLUS_TRAIN_PAIRED_TARGET_H_

#include <torch/torch.h>

#include <vector>

#include "model/contrastive/contrastive_net.h"
#include "train/training_set.h"

namespace stylus::model {

struct PairedTargets {
  torch::Tensor windows;  // (B, dim, window): the targets (zeros where none).
  torch::Tensor found;    // (B): 1 where a target was found, else 0.
};

// For each content window i (content codes `codes`, (B, C, Tc), of windows
// of `window` frames), the window of clip `examples[i]` of `data` (-1:
// none) whose content code is nearest: the example's whole-clip code is
// compared with the window's at every offset (squared distance summed over
// the code). A clip shorter than a window gives none. No gradient flows
// through the search.
PairedTargets FindPairedTargets(ContrastiveNet& net, const TrainingSet& data,
                                const std::vector<int>& examples, const torch::Tensor& codes,
                                int window);

// The mean L1 distance of `transfer` to the targets over `channels` (1, dim,
// 1) and the windows that have one (0 when none has).
torch::Tensor PairedLoss(const torch::Tensor& transfer, const PairedTargets& targets,
                         const torch::Tensor& channels);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_PAIRED_TARGET_H_
