// Dynamic batching of live streams' network steps (docs/service.md
// "Batching"): the pending steps of every open stream on one model run as
// one forward pass per tick, one step per stream per batch, so each
// stream's steps stay in order (Triton's sequence batcher). A tick starts
// when `max_batch` streams wait or the oldest has waited `max_delay`; the
// batch then takes every waiting stream of the oldest one's model, up to
// `max_batch`. The forward passes run on the batcher's own thread; what
// comes before (features) and after (decoding, post-processing) runs on the
// streams' executor tasks, in parallel.
//
// Thread-safety: all methods may be called from any thread.
#ifndef STYLUS_SERVER_STEP_BATCHER_H_
#define STYLUS_SERVER_STEP_BATCHER_H_

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "model/frame_streamer.h"
#include "model/style_model.h"
#include "server/executor.h"
#include "server/metrics.h"

namespace stylus::server {

class StepBatcher {
 public:
  // `metrics` (may be null) counts each batch's size.
  StepBatcher(Executor* executor, int max_batch, std::chrono::microseconds max_delay,
              Metrics* metrics = nullptr);
  // Stop(), if it has not run yet.
  ~StepBatcher();
  // Takes no more steps (Submit returns false from now on), runs the steps
  // already submitted and joins the batcher's thread. Idempotent.
  void Stop();

  // Runs every step `stream` has queued (a batchable stream, fed), in
  // batches with other streams' steps, then `done` with the status on the
  // executor. False (and nothing runs) once shutting down. `model_id`
  // labels the batch's compute time in the metrics.
  bool Submit(std::shared_ptr<const model::StyleModel> model, const std::string& model_id,
              model::FrameStreamer* stream, std::function<void(absl::Status)> done);

  // Batches run and steps they held, since the start.
  int64_t batches() const;
  int64_t steps() const;

 private:
  struct Entry {
    std::shared_ptr<const model::StyleModel> model;
    std::string model_id;
    model::FrameStreamer* core;
    std::function<void(absl::Status)> done;
    std::chrono::steady_clock::time_point since;
  };
  void Loop();

  Executor* const executor_;
  const int max_batch_;
  const std::chrono::microseconds max_delay_;
  Metrics* const metrics_;
  mutable absl::Mutex mu_;
  std::deque<Entry> waiting_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  int64_t batches_ ABSL_GUARDED_BY(mu_) = 0, steps_ ABSL_GUARDED_BY(mu_) = 0;
  std::thread thread_;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_STEP_BATCHER_H_
