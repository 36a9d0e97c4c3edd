// How a family's network passes go through a PassBatcher (model/pass_batcher.h;
// internal to model/: includes LibTorch).
#ifndef STYLUS_MODEL_PASS_BATCHING_H_
#define STYLUS_MODEL_PASS_BATCHING_H_

#include <torch/torch.h>

#include <functional>
#include <vector>

#include "model/pass_batcher.h"

namespace stylus::model {

using Pass = std::function<torch::Tensor(const std::vector<torch::Tensor>&)>;

// `pass` on `inputs` (each with this call's rows in dim 0), batched with
// concurrent calls of the same `owner` and `pass_id` whose inputs have the
// same shapes but dim 0; this call's rows of the output. Without a batcher,
// `pass` on `inputs` alone. Rethrows what the pass threw.
torch::Tensor RunPass(PassBatcher* batcher, const void* owner, int pass_id,
                      const std::vector<torch::Tensor>& inputs, const Pass& pass);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_PASS_BATCHING_H_
