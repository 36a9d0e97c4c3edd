#include "model/runtime.h"

#include <torch/torch.h>

#include <algorithm>
#include <thread>

namespace stylus::model {

void SetComputeThreads(int threads) {
  at::set_num_threads(
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

int ComputeThreads() { return at::get_num_threads(); }

void InitComputeThreadsHere() { at::init_num_threads(); }

}  // namespace stylus::model
