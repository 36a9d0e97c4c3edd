// A fixed pool of compute threads. RPC handlers hand model work to it so that
// gRPC's own threads never run a forward pass (house rule 7).
//
// Thread-safety: all methods may be called from any thread.
#ifndef STYLUS_SERVER_EXECUTOR_H_
#define STYLUS_SERVER_EXECUTOR_H_

#include <deque>
#include <functional>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace stylus::server {

class Executor {
 public:
  explicit Executor(int threads);
  // Runs every task already accepted, then joins the threads.
  ~Executor();

  // Queues `task`; false (and the task is not run) once Shutdown was called.
  bool Submit(std::function<void()> task);
  // Stops accepting tasks; those accepted still run. Idempotent.
  void Shutdown();
  int threads() const { return static_cast<int>(threads_.size()); }
  // Tasks accepted and not yet started, and tasks running now.
  int queued() const;
  int running() const;

 private:
  void Loop();

  mutable absl::Mutex mu_;
  std::deque<std::function<void()>> tasks_ ABSL_GUARDED_BY(mu_);
  int running_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::vector<std::thread> threads_;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_EXECUTOR_H_
