#include "train/paired_target.h"

#include <algorithm>
#include <cstdint>

namespace stylus::model {

PairedTargets FindPairedTargets(ContrastiveNet& net, const TrainingSet& data,
                                const std::vector<int>& examples, const torch::Tensor& codes,
                                int window) {
  torch::NoGradGuard no_grad;
  const int64_t batch = codes.size(0), code_frames = codes.size(2);
  const int dim = data.dim();
  PairedTargets out{torch::zeros({batch, dim, window}), torch::zeros({batch})};
  for (int64_t i = 0; i < batch; ++i) {
    if (examples[i] < 0) continue;
    const motion::FeatureClip& clip = data.clips[examples[i]];
    if (clip.frames < window) continue;
    // (1, dim, frames), channels first as the networks read.
    const torch::Tensor whole =
        torch::from_blob(const_cast<float*>(clip.values.data()), {clip.frames, dim},
                         torch::kFloat32)
            .t()
            .unsqueeze(0)
            .contiguous();
    const torch::Tensor code = net->content(whole);  // (1, C, frames * Tc / window)
    if (code.size(2) < code_frames) continue;
    // Every placement of the content window's code along the example's.
    const torch::Tensor placed = code.unfold(2, code_frames, 1);  // (1, C, n, Tc)
    const torch::Tensor distance =
        (placed - codes[i].detach().unsqueeze(1).unsqueeze(0)).pow(2).sum({1, 3});  // (1, n)
    const int64_t best = distance.argmin(1).item<int64_t>();
    const int64_t start = std::min<int64_t>(best * window / code_frames, clip.frames - window);
    out.windows[i].copy_(whole[0].slice(1, start, start + window));
    out.found[i].fill_(1);
  }
  return out;
}

torch::Tensor PairedLoss(const torch::Tensor& transfer, const PairedTargets& targets,
                         const torch::Tensor& channels) {
  const torch::Tensor found = targets.found.view({-1, 1, 1});
  const torch::Tensor n = targets.found.sum();
  if (n.item<double>() == 0) return torch::zeros({});
  return ((transfer - targets.windows).abs() * channels * found).sum() /
         (n * channels.sum() * transfer.size(2));
}

}  // namespace stylus::model
