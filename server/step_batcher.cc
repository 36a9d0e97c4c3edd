#include "server/step_batcher.h"

#include <utility>
#include <vector>

#include "model/runtime.h"

namespace stylus::server {

StepBatcher::StepBatcher(Executor* executor, int max_batch, std::chrono::microseconds max_delay,
                         Metrics* metrics)
    : executor_(executor), max_batch_(max_batch), max_delay_(max_delay), metrics_(metrics) {
  thread_ = std::thread([this] { Loop(); });
}

StepBatcher::~StepBatcher() { Stop(); }

void StepBatcher::Stop() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  if (thread_.joinable()) thread_.join();
}

bool StepBatcher::Submit(std::shared_ptr<const model::StyleModel> model,
                         const std::string& model_id, model::FrameStreamer* stream,
                         std::function<void(absl::Status)> done) {
  absl::MutexLock lock(&mu_);
  if (stopping_) return false;
  waiting_.push_back({std::move(model), model_id, stream->step_core(), std::move(done),
                      std::chrono::steady_clock::now()});
  return true;
}

int64_t StepBatcher::batches() const {
  absl::MutexLock lock(&mu_);
  return batches_;
}

int64_t StepBatcher::steps() const {
  absl::MutexLock lock(&mu_);
  return steps_;
}

void StepBatcher::Loop() {
  // One compute thread, as set for the server: a batch's products are small,
  // and the streams' other work runs on the executor's threads meanwhile.
  model::InitComputeThreadsHere();
  for (;;) {
    std::vector<Entry> batch;
    {
      absl::MutexLock lock(&mu_);
      mu_.Await(absl::Condition(
          +[](StepBatcher* b)
               ABSL_NO_THREAD_SAFETY_ANALYSIS { return b->stopping_ || !b->waiting_.empty(); },
          this));
      if (waiting_.empty()) return;  // Stopping, and nothing left.
      // Wait for a full batch or the oldest entry's deadline.
      const auto deadline = waiting_.front().since + max_delay_;
      const absl::Time until =
          absl::Now() + absl::FromChrono(deadline - std::chrono::steady_clock::now());
      mu_.AwaitWithDeadline(absl::Condition(
                                +[](StepBatcher* b) ABSL_NO_THREAD_SAFETY_ANALYSIS {
                                  return b->stopping_ ||
                                         static_cast<int>(b->waiting_.size()) >= b->max_batch_;
                                },
                                this),
                            until);
      // Every waiting stream of the oldest's model, in order, up to max_batch.
      const model::StyleModel* model = waiting_.front().model.get();
      for (auto it = waiting_.begin();
           it != waiting_.end() && static_cast<int>(batch.size()) < max_batch_;) {
        if (it->model.get() == model) {
          batch.push_back(std::move(*it));
          it = waiting_.erase(it);
        } else {
          ++it;
        }
      }
      ++batches_;
      steps_ += static_cast<int64_t>(batch.size());
    }
    if (metrics_ != nullptr) metrics_->StepBatch(static_cast<int64_t>(batch.size()));
    std::vector<model::FrameStreamer*> cores;
    for (const Entry& e : batch) cores.push_back(e.core);
    const auto t0 = std::chrono::steady_clock::now();
    const absl::Status s = batch.front().model->StepStreams(cores);
    if (metrics_ != nullptr) {
      metrics_->ModelSeconds(
          batch.front().model_id,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::vector<Entry> again;
    for (Entry& e : batch) {
      if (s.ok() && e.core->has_steps()) {
        again.push_back(std::move(e));
        continue;
      }
      auto done = std::move(e.done);
      if (!executor_->Submit([done, s] { done(s); })) done(s);
    }
    if (!again.empty()) {
      // Their next steps go first: they have waited longest.
      absl::MutexLock lock(&mu_);
      for (auto it = again.rbegin(); it != again.rend(); ++it) waiting_.push_front(std::move(*it));
    }
  }
}

}  // namespace stylus::server
