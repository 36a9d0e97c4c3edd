// The paired term of label-guided training: Bandai has most actions in most
// styles, so a transfer of a content window to a style has a real example
// of what it should become, the same action performed in that style. The
// example is not aligned with the content (another take, another tempo):
// its window whose content code (Ec, trained to ignore style) is nearest
// the content window's is the target, or, warped, the example time-warped
// onto the content window by dynamic time warping of the two content codes.
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
// With `warp`, the example is time-warped onto the window instead
// (WarpPath on the codes' squared distances, then each frame of the window
// read from the example at the warped time, linearly between its frames).
PairedTargets FindPairedTargets(ContrastiveNet& net, const TrainingSet& data,
                                const std::vector<int>& examples, const torch::Tensor& codes,
                                int window, bool warp = false);

// Subsequence dynamic time warping. `cost` (n, m) is the cost of matching
// step j of one sequence with step k of another. Returns, for every j, the
// k it matches: non-decreasing, advancing 0, 1 or 2 steps at a time (a hold
// or a skip costs `step_penalty` more than an advance of 1), free to start
// and end anywhere in the other, with the least summed cost.
std::vector<int> WarpPath(const torch::Tensor& cost, double step_penalty);

// The times (fractional frames of an example of `example_frames` frames
// whose content code has `example_steps` steps) at which to read the example
// for each of the `window` frames of a content window whose code has
// path.size() steps, given the warp `path` of code steps (WarpPath). The
// path is smoothed by [1 2 1] / 4 first (going on at its end slopes past
// its ends), so a hold or a skip spreads over its neighbours; between steps
// the warp is linear.
std::vector<double> WarpedTimes(const std::vector<int>& path, int window, int example_frames,
                                int example_steps);

// Reads `frames` (rows, each `dim` values) at every time of `times`
// (fractional row indices, clamped to the rows), linearly between rows:
// (dim, times.size()), channels first.
torch::Tensor ReadAtTimes(const float* frames, int rows, int dim, const std::vector<double>& times);

// The mean L1 distance of `transfer` to the targets over `channels` (1, dim,
// 1) and the windows that have one (0 when none has).
torch::Tensor PairedLoss(const torch::Tensor& transfer, const PairedTargets& targets,
                         const torch::Tensor& channels);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_PAIRED_TARGET_H_
