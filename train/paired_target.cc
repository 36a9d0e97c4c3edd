#include "train/paired_target.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace stylus::model {

std::vector<int> WarpPath(const torch::Tensor& cost, double step_penalty) {
  const torch::Tensor c = cost.to(torch::kFloat64).contiguous();
  const int64_t n = c.size(0), m = c.size(1);
  const double* d = c.data_ptr<double>();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> total(n * m, inf);
  std::vector<int8_t> step(n * m, 1);
  for (int64_t k = 0; k < m; ++k) total[k] = d[k];
  for (int64_t j = 1; j < n; ++j) {
    for (int64_t k = 0; k < m; ++k) {
      double best = inf;
      int8_t how = 1;
      for (int8_t s = 0; s <= 2; ++s) {
        if (k - s < 0) break;
        const double v = total[(j - 1) * m + k - s] + (s == 1 ? 0.0 : step_penalty);
        if (v < best) best = v, how = s;
      }
      total[j * m + k] = best + d[j * m + k];
      step[j * m + k] = how;
    }
  }
  int64_t k = 0;
  for (int64_t q = 1; q < m; ++q)
    if (total[(n - 1) * m + q] < total[(n - 1) * m + k]) k = q;
  std::vector<int> path(n);
  for (int64_t j = n - 1; j >= 0; --j) {
    path[j] = static_cast<int>(k);
    if (j > 0) k -= step[j * m + k];
  }
  return path;
}

std::vector<double> WarpedTimes(const std::vector<int>& path, int window, int example_frames,
                                int example_steps) {
  const int n = static_cast<int>(path.size());
  std::vector<double> smooth(n);
  for (int j = 0; j < n; ++j) {
    // Past either end the path goes on at its last slope.
    const double a = j > 0 ? path[j - 1] : (n > 1 ? 2.0 * path[0] - path[1] : path[0]);
    const double b =
        j + 1 < n ? path[j + 1] : (n > 1 ? 2.0 * path[n - 1] - path[n - 2] : path[n - 1]);
    smooth[j] = (a + 2.0 * path[j] + b) / 4.0;
  }
  const double content_rate = static_cast<double>(window) / n;  // frames per code step
  const double example_rate = static_cast<double>(example_frames) / example_steps;
  std::vector<double> times(window);
  for (int t = 0; t < window; ++t) {
    // The code step whose centre is frame t, fractional, and the warp there
    // (linear between steps, extended with the last slope past the ends).
    const double j = (t + 0.5) / content_rate - 0.5;
    const int j0 = std::clamp(static_cast<int>(std::floor(j)), 0, std::max(n - 2, 0));
    const int j1 = std::min(j0 + 1, n - 1);
    const double k = smooth[j0] + (j - j0) * (smooth[j1] - smooth[j0]);
    times[t] = (k + 0.5) * example_rate - 0.5;
  }
  return times;
}

torch::Tensor ReadAtTimes(const float* frames, int rows, int dim, const std::vector<double>& times) {
  torch::Tensor out = torch::empty({dim, static_cast<int64_t>(times.size())});
  float* o = out.data_ptr<float>();
  const int64_t columns = static_cast<int64_t>(times.size());
  for (int64_t t = 0; t < columns; ++t) {
    const double at = std::clamp(times[t], 0.0, static_cast<double>(rows - 1));
    const int a = std::min(static_cast<int>(at), rows - 1), b = std::min(a + 1, rows - 1);
    const float w = static_cast<float>(at - a);
    for (int c = 0; c < dim; ++c)
      o[c * columns + t] = (1 - w) * frames[a * dim + c] + w * frames[b * dim + c];
  }
  return out;
}

PairedTargets FindPairedTargets(ContrastiveNet& net, const TrainingSet& data,
                                const std::vector<int>& examples, const torch::Tensor& codes,
                                int window, bool warp) {
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
    const torch::Tensor mine = codes[i].detach();  // (C, Tc)
    if (warp) {
      // (Tc, steps): squared distance of every content step to every example step.
      const torch::Tensor cost = torch::cdist(mine.t().unsqueeze(0), code[0].t().unsqueeze(0))
                                     .squeeze(0)
                                     .pow(2);
      const std::vector<int> path = WarpPath(cost, 0.1 * cost.mean().item<double>());
      const std::vector<double> times =
          WarpedTimes(path, window, clip.frames, static_cast<int>(code.size(2)));
      out.windows[i].copy_(ReadAtTimes(clip.values.data(), clip.frames, dim, times));
      out.found[i].fill_(1);
      continue;
    }
    // Every placement of the content window's code along the example's.
    const torch::Tensor placed = code.unfold(2, code_frames, 1);  // (1, C, n, Tc)
    const torch::Tensor distance =
        (placed - mine.unsqueeze(1).unsqueeze(0)).pow(2).sum({1, 3});  // (1, n)
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
