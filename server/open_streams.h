// The streams a server has open, so that shutdown can drain them: each is
// told to stop taking frames, return every frame it took, and end.
//
// Thread-safety: all methods may be called concurrently. Drain is called
// with the registry's lock held and must not block or finish the call
// inline (a stream hands the work to the executor).
#ifndef STYLUS_SERVER_OPEN_STREAMS_H_
#define STYLUS_SERVER_OPEN_STREAMS_H_

#include <set>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace stylus::server {

class DrainableStream {
 public:
  virtual void Drain() = 0;

 protected:
  ~DrainableStream() = default;
};

class OpenStreams {
 public:
  // False once draining has begun: the stream must not start.
  bool Add(DrainableStream* stream) {
    absl::MutexLock lock(&mu_);
    if (draining_) return false;
    open_.insert(stream);
    return true;
  }
  // Before the stream is destroyed.
  void Remove(DrainableStream* stream) {
    absl::MutexLock lock(&mu_);
    open_.erase(stream);
  }
  // Drains every open stream; later Adds fail. The number drained.
  int DrainAll() {
    absl::MutexLock lock(&mu_);
    draining_ = true;
    for (DrainableStream* s : open_) s->Drain();
    return static_cast<int>(open_.size());
  }

 private:
  absl::Mutex mu_;
  std::set<DrainableStream*> open_ ABSL_GUARDED_BY(mu_);
  bool draining_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_OPEN_STREAMS_H_
