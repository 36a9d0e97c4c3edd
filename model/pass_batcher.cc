#include "model/pass_batcher.h"

#include <algorithm>
#include <exception>
#include <list>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "model/pass_batching.h"

namespace stylus::model {
namespace {

struct Call {
  const std::vector<torch::Tensor>* inputs;
  torch::Tensor output;
  std::exception_ptr error;
  bool done = false;
};

struct Group {
  const void* owner;
  int pass_id;
  std::vector<std::vector<int64_t>> shapes;  // Each input's sizes but dim 0.
  std::vector<Call*> calls;
  int64_t rows = 0;
  bool full = false;    // rows reached max_rows: the leader stops waiting.
  bool closed = false;  // Its leader took it: no one joins any more.
};

// Runs the group's pass once on every call's inputs, or records its error.
void RunGroup(Group* group, const Pass& pass) {
  try {
    if (group->calls.size() == 1) {
      group->calls.front()->output = pass(*group->calls.front()->inputs);
      return;
    }
    std::vector<torch::Tensor> joined;
    for (size_t i = 0; i < group->calls.front()->inputs->size(); ++i) {
      std::vector<torch::Tensor> parts;
      for (const Call* c : group->calls) parts.push_back((*c->inputs)[i]);
      joined.push_back(torch::cat(parts, 0));
    }
    const torch::Tensor out = pass(joined);
    int64_t offset = 0;
    for (Call* c : group->calls) {
      const int64_t rows = c->inputs->front().size(0);
      c->output = out.narrow(0, offset, rows);
      offset += rows;
    }
  } catch (...) {
    for (Call* c : group->calls) c->error = std::current_exception();
  }
}

}  // namespace

struct PassBatcher::Impl {
  int64_t max_rows;
  std::chrono::microseconds max_delay;
  absl::Mutex mu;
  std::list<Group> open ABSL_GUARDED_BY(mu);
  int64_t batches ABSL_GUARDED_BY(mu) = 0;
  int64_t calls ABSL_GUARDED_BY(mu) = 0;
};

PassBatcher::Impl& BatcherImpl(PassBatcher* batcher) { return *batcher->impl_; }

PassBatcher::PassBatcher(int64_t max_rows, std::chrono::microseconds max_delay)
    : impl_(std::make_unique<Impl>()) {
  impl_->max_rows = std::max<int64_t>(1, max_rows);
  impl_->max_delay = max_delay;
}

PassBatcher::~PassBatcher() = default;

int64_t PassBatcher::batches() const {
  absl::MutexLock lock(&impl_->mu);
  return impl_->batches;
}

int64_t PassBatcher::calls() const {
  absl::MutexLock lock(&impl_->mu);
  return impl_->calls;
}

torch::Tensor RunPass(PassBatcher* batcher, const void* owner, int pass_id,
                      const std::vector<torch::Tensor>& inputs, const Pass& pass) {
  if (batcher == nullptr || inputs.empty()) return pass(inputs);
  PassBatcher::Impl& b = BatcherImpl(batcher);
  std::vector<std::vector<int64_t>> shapes;
  for (const torch::Tensor& t : inputs) {
    const auto sizes = t.sizes();
    shapes.emplace_back(sizes.begin() + 1, sizes.end());
  }
  const int64_t rows = inputs.front().size(0);
  Call me{&inputs, {}, nullptr, false};
  Group* group = nullptr;
  {
    absl::MutexLock lock(&b.mu);
    for (Group& g : b.open) {
      if (!g.closed && g.owner == owner && g.pass_id == pass_id && g.shapes == shapes &&
          g.rows + rows <= b.max_rows) {
        group = &g;
        break;
      }
    }
    if (group != nullptr) {  // A follower: the group's leader runs the pass.
      group->calls.push_back(&me);
      group->rows += rows;
      if (group->rows >= b.max_rows) group->full = true;
      b.mu.Await(absl::Condition(&me.done));
      if (me.error) std::rethrow_exception(me.error);
      return me.output;
    }
    b.open.push_back(Group{owner, pass_id, std::move(shapes), {&me}, rows});
    group = &b.open.back();
    group->full = rows >= b.max_rows;
    b.mu.AwaitWithTimeout(absl::Condition(&group->full), absl::FromChrono(b.max_delay));
    group->closed = true;
    if (group->calls.size() > 1) {
      ++b.batches;
      b.calls += static_cast<int64_t>(group->calls.size());
    }
  }
  RunGroup(group, pass);
  {
    absl::MutexLock lock(&b.mu);
    for (Call* c : group->calls) c->done = true;
    for (auto it = b.open.begin(); it != b.open.end(); ++it) {
      if (&*it == group) {
        b.open.erase(it);
        break;
      }
    }
  }
  if (me.error) std::rethrow_exception(me.error);
  return me.output;
}

}  // namespace stylus::model
