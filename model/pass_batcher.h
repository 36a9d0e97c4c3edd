// Dynamic batching of network passes across concurrent calls (the server's
// unary transfers: docs/service.md "Batching"). Calls that run the same pass
// (same model, same network, inputs of the same shape but the batch size)
// within `max_delay` of each other run as one forward: their inputs are
// concatenated along dim 0, the pass runs once, and each call gets its own
// rows of the output. No thread of its own: the first call of a batch leads
// it, waiting until `max_rows` rows have gathered or `max_delay` has passed,
// then runs the pass on its thread while the others wait for their rows.
// A pass must treat rows independently (per-sample normalizations); then
// the results equal the unbatched ones up to float rounding. A family uses
// it through model/pass_batching.h; a caller hands it to a transfer in
// TransferOptions::batcher.
//
// Thread-safety: all methods may be called from any thread.
#ifndef STYLUS_MODEL_PASS_BATCHER_H_
#define STYLUS_MODEL_PASS_BATCHER_H_

#include <chrono>
#include <cstdint>
#include <memory>

namespace stylus::model {

class PassBatcher {
 public:
  PassBatcher(int64_t max_rows, std::chrono::microseconds max_delay);
  ~PassBatcher();

  int64_t batches() const;  // Passes run for more than one call...
  int64_t calls() const;    // ...and the calls they held.

  struct Impl;  // Defined in pass_batcher.cc; RunPass (pass_batching.h) uses it.

 private:
  friend Impl& BatcherImpl(PassBatcher* batcher);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_PASS_BATCHER_H_
