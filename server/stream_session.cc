#include "server/stream_session.h"

#include <grpcpp/alarm.h>

#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "model/style_schedule.h"
#include "server/postprocess_option.h"
#include "server/services.h"
#include "server/status.h"
#include "wire/wire.h"

namespace stylus::server {
namespace {

class StreamSession : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>,
                      public DrainableStream {
 public:
  StreamSession(ServiceContext* service, grpc::CallbackServerContext* ctx)
      : service_(service),
        ctx_(ctx),
        origin_(IdentifyCall(ctx)),
        series_(service->metrics != nullptr
                    ? service->metrics->Series(kStyleService, kMethod, kType)
                    : nullptr),
        start_(std::chrono::steady_clock::now()) {
    if (series_ != nullptr) service_->metrics->CallStarted(series_);
    service_->open_streams.fetch_add(1);  // Every session, until Destroy.
    // The caller first: a call without a valid token takes no stream slot.
    if (absl::Status token = CheckAccess(*service_, ctx, Access::kServe); !token.ok()) {
      Refuse(token);
      return;
    }
    admitted_ = true;
    if (service_->admitted_streams.fetch_add(1) >= service_->max_streams) {
      Refuse(absl::ResourceExhaustedError(absl::StrCat("the server already runs its maximum of ",
                                                       service_->max_streams, " streams")));
      return;
    }
    if (!service_->streams.Add(this)) {
      Refuse(absl::UnavailableError("the server is shutting down"));
      return;
    }
    registered_ = true;
    if (service_->limits.stream_idle_timeout.count() > 0) {
      absl::MutexLock lock(&mu_);
      ArmIdleAlarmLocked(start_);
    }
    StartRead(&read_bytes_);
  }

  void OnReadDone(bool ok) override {
    {
      // One critical section, so that a task which checks for a drain after
      // starting this read (AfterTask) sees either this read done and
      // refused, or a task of it counted in busy_.
      absl::MutexLock lock(&mu_);
      reading_ = false;
      // A message that arrives once the drain has begun is not taken: the
      // drain's task, or the task that started this read, ends the stream.
      if (draining_) return;
      // A read that fails after the call was finished (cancellation) needs
      // no handling: the session is about to be done.
      if (finished_) return;
      ++busy_;  // From here on nobody else finishes the call.
    }
    if (ok) {
      read_at_ = std::chrono::steady_clock::now();
      ++messages_read_;
      if (series_ != nullptr) service_->metrics->MessageReceived(series_);
    }
    // A task returns true when it handed its steps to the batcher, whose
    // continuation then ends the task.
    // The request is parsed in place: the next read starts after the task
    // (AfterTask), and each parse reuses the arena of the one before.
    std::function<bool()> task;
    if (ok) {
      task = [this] {
        absl::StatusOr<const v1::StreamRequest*> parsed = requests_.Parse(
            read_bytes_, messages_read_, "stream message",
            [this](const grpc::ByteBuffer& bytes, const std::string& what) {
              return CheckRequestBudget(*service_, bytes, v1::StreamRequest::descriptor(), what);
            });
        if (!parsed.ok()) {
          absl::MutexLock lock(&mu_);
          Fail(parsed.status());
          return false;
        }
        return Handle(**parsed);
      };
    } else {
      task = [this] { return HandleEnd(); };
    }
    if (!service_->executor->Submit([this, task] {
          if (!task()) AfterTask();
        })) {
      mu_.Lock();  // ReleaseLocked unlocks.
      Fail(absl::UnavailableError("the server is shutting down"));
      ReleaseLocked();
    }
  }

  // Shutdown: take no more frames, return every frame taken, and end the
  // call UNAVAILABLE (the client reconnects elsewhere). Called with the
  // registry's lock held: hands the work to the executor, never finishes
  // inline.
  void Drain() override {
    absl::MutexLock lock(&mu_);
    if (draining_ || done_ || finished_ || failed_ || ending_) return;
    draining_ = true;
    outcome_.status = absl::UnavailableError(
        "the server is shutting down: every frame it received was returned (trailing metadata "
        "stylus-frames-received); reconnect");
    // A task that runs now ends the stream when it is done (AfterTask); with
    // none, and a read waiting for the client, a task of its own does.
    if (busy_ > 0 || (!reading_ && !read_paused_)) return;
    ++busy_;
    if (!service_->executor->Submit([this] {
          if (!HandleEnd()) AfterTask();
        })) {
      --busy_;  // The executor is gone: nothing left to flush with.
    }
  }

  void OnWriteDone(bool ok) override {
    const v1::StreamResponse* next = nullptr;
    bool resume = false;
    {
      absl::MutexLock lock(&mu_);
      // Kept for a later frame: a response's storage is reused, not freed.
      if (spare_.size() < kSpareResponses) spare_.push_back(std::move(writes_.front()));
      writes_.pop_front();
      writing_ = false;
      if (!ok) Fail(absl::CancelledError("the client stopped reading"));
      if (ok && series_ != nullptr) service_->metrics->MessageSent(series_);
      if (failed_) {
        writes_.clear();
      } else if (!writes_.empty()) {
        writing_ = true;
        next = &writes_.front();
      }
      if (read_paused_ && ok) {
        paused_since_ = std::chrono::steady_clock::now();  // The client reads: progress.
        if (!failed_ && !finished_ && !draining_ && !ending_ &&
            static_cast<int>(writes_.size()) <= service_->limits.max_stream_backlog / 2) {
          // Read on, from a task of its own (AfterTask chooses what comes next).
          read_paused_ = false;
          resume = true;
          ++busy_;
        }
      }
    }
    if (next != nullptr) Write(*next);
    if (resume) {
      if (!service_->executor->Submit([this] { AfterTask(); })) {
        mu_.Lock();  // ReleaseLocked unlocks.
        Fail(absl::UnavailableError("the server is shutting down"));
        ReleaseLocked();
      }
      return;
    }
    if (next == nullptr) MaybeFinishOutsideLock();
  }

  void OnCancel() override {
    {
      absl::MutexLock lock(&mu_);
      Fail(absl::CancelledError("the client cancelled the stream or its deadline passed"));
    }
    MaybeFinishOutsideLock();
  }

  // gRPC calls this once the call is over, but an executor task of this
  // session may still be running: then the task deletes the session.
  void OnDone() override {
    bool now = false;
    {
      absl::MutexLock lock(&mu_);
      done_ = true;
      now = busy_ == 0 && !alarm_set_;
      // A pending alarm's callback runs soon (on another thread, not
      // fired); the last one out destroys the session.
      if (alarm_set_) idle_alarms_[alarm_index_].Cancel();
    }
    if (now) Destroy();
  }

 private:
  // Ends the call from the constructor, before any operation: marked
  // finished, so that a cancellation that follows does not finish it again.
  void Refuse(const absl::Status& status) {
    {
      absl::MutexLock lock(&mu_);
      failed_ = finished_ = true;
      reading_ = false;
      outcome_.status = status;
    }
    Finish(ToGrpcStatus(status));
  }

  // Runs on the executor; at most one at a time per session. True when the
  // task continues in the batcher (AfterSteps ends it).
  bool Handle(const v1::StreamRequest& request) {
    absl::Status s;
    bool batched = false;
    if (request.has_config()) {
      s = streamer_ ? absl::InvalidArgumentError("a second config message; send it first, once")
                    : Configure(request.config());
    } else if (request.has_frame()) {
      s = streamer_ ? AddFrame(request.frame(), &batched)
                    : absl::InvalidArgumentError(
                          "the first message must be a config (model, style, skeleton, fps)");
    } else if (request.has_change()) {
      s = streamer_ ? ChangeStyle(request.change())
                    : absl::InvalidArgumentError(
                          "the first message must be a config (model, style, skeleton, fps)");
    } else {
      s = absl::InvalidArgumentError("an empty stream message: send a config or a frame");
    }
    if (!s.ok()) {
      absl::MutexLock lock(&mu_);
      Fail(s);
    }
    return batched;
  }

  bool HandleEnd() {
    absl::Status s;
    bool batched = false;
    if (streamer_ && streamer_->received() > 0) {
      if (Batched()) {
        motion::Motion none = chunk_;
        none.num_frames = 0;
        none.values.clear();
        s = streamer_->Feed(none, /*end=*/true);
        if (s.ok()) s = SubmitSteps(&batched);
      } else {
        absl::StatusOr<motion::Motion> rest = streamer_->Finish();
        if (rest.ok()) {
          Enqueue(*rest);
        } else {
          s = rest.status();
        }
      }
    }
    absl::MutexLock lock(&mu_);
    if (!s.ok()) Fail(s);
    ending_ = true;
    return batched;
  }

  bool Batched() const { return service_->batcher != nullptr && streamer_->batchable(); }

  // Hands the steps fed to the batcher; AfterSteps continues on the executor.
  absl::Status SubmitSteps(bool* batched) {
    if (!streamer_->has_steps()) {
      absl::StatusOr<motion::Motion> out = streamer_->Collect();
      if (!out.ok()) return out.status();
      Enqueue(*out);
      return absl::OkStatus();
    }
    if (!service_->batcher->Submit(model_, outcome_.model, streamer_.get(),
                                   [this](absl::Status s) { AfterSteps(s); })) {
      return absl::UnavailableError("the server is shutting down");
    }
    *batched = true;
    return absl::OkStatus();
  }

  void AfterSteps(const absl::Status& stepped) {
    absl::Status s = stepped;
    if (s.ok()) {
      absl::StatusOr<motion::Motion> out = streamer_->Collect();
      if (out.ok()) {
        Enqueue(*out);
      } else {
        s = out.status();
      }
    }
    if (!s.ok()) {
      absl::MutexLock lock(&mu_);
      Fail(s);
    }
    AfterTask();
  }

  absl::Status Configure(const v1::StreamConfig& config) {
    absl::StatusOr<HostedModel> m = service_->registry->Get(config.model());
    if (!m.ok()) return m.status();
    outcome_.model = m->id;
    absl::StatusOr<motion::PostProcessMode> post = ToPostProcessMode(config.postprocess());
    if (!post.ok()) return post.status();
    if (!(std::isfinite(config.fps()) && config.fps() > 0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("config: fps must be a positive number, got ", config.fps()));
    }
    absl::StatusOr<motion::Skeleton> sk = wire::SkeletonFromProto(config.skeleton(), "config");
    if (!sk.ok()) return sk.status();
    absl::StatusOr<model::StyleCode> style =
        ResolveStyle(*service_, *m, config.style(), "config style");
    if (!style.ok()) return style.status();
    KeepExample(&*style);
    absl::StatusOr<motion::JointMap> joint_map =
        wire::JointMapFromProto(config.skeleton(), "config");
    if (!joint_map.ok()) return joint_map.status();
    absl::StatusOr<std::unique_ptr<model::FrameStreamer>> streamer = m->model->OpenStream(
        {*style, *sk, 1.0 / config.fps(), *post, *joint_map, MovementFor(*service_, config.style())});
    if (!streamer.ok()) return streamer.status();
    streamer_ = *std::move(streamer);
    model_ = m->model;
    hosted_ = *m;
    chunk_ = motion::RestMotion(*sk, 0, 1.0 / config.fps());
    prev_euler_.assign(sk->num_joints(), motion::Vec3{});
    return absl::OkStatus();
  }

  // The configured style clip's reading (movement from examples) stays
  // with the stream while its bytes fit the server's memory pool
  // (--max-memory-mb); when they do not, and for styles changed to later,
  // the stream's movement comes from the style library alone.
  void KeepExample(model::StyleCode* code) {
    if (code->example == nullptr) return;
    MemoryHold hold(service_->call_memory,
                    static_cast<int64_t>(motion::MovementClipBytes(*code->example)));
    if (!hold.ok()) {
      code->example = nullptr;
      return;
    }
    example_hold_ = std::move(hold);
  }

  absl::Status ChangeStyle(const v1::StyleChange& change) {
    model::StyleChange c;
    // Stream frames count from the first frame's index (from the next
    // frame's when none has arrived yet).
    c.from_frame = streamer_->received() > 0 ? change.from_frame() - first_index_ : 0;
    c.fade_frames = change.fade_frames();
    // A change no frame of this stream can reach would wait in it forever.
    if (c.from_frame >= service_->max_stream_frames ||
        c.fade_frames > service_->max_stream_frames) {
      return absl::InvalidArgumentError(
          absl::StrCat("style change from frame ", change.from_frame(), " over ",
                       change.fade_frames(), " frames: past the last frame a stream may have (",
                       service_->max_stream_frames, ", --max-stream-frames)"));
    }
    if (change.has_strength()) c.strength = change.strength();
    if (change.has_style()) {
      absl::StatusOr<model::StyleCode> code =
          ResolveStyle(*service_, *hosted_, change.style(), "style change");
      if (!code.ok()) return code.status();
      c.code = *std::move(code);
      c.code->example = nullptr;  // The library's takes move a changed style.
      c.movement = MovementFor(*service_, change.style());
    } else if (change.has_blend()) {
      const v1::StyleBlend& blend = change.blend();
      if (blend.styles_size() == 0 || blend.weights_size() != blend.styles_size()) {
        return absl::InvalidArgumentError(
            absl::StrCat("style change: a blend needs one weight per style (got ",
                         blend.styles_size(), " styles and ", blend.weights_size(), " weights)"));
      }
      std::vector<model::StyleCode> codes;
      std::vector<double> weights;
      for (int i = 0; i < blend.styles_size(); ++i) {
        absl::StatusOr<model::StyleCode> code = ResolveStyle(
            *service_, *hosted_, blend.styles(i), absl::StrCat("style change blend style ", i));
        if (!code.ok()) return code.status();
        codes.push_back(*std::move(code));
        if (!std::isfinite(blend.weights(i)))
          return absl::InvalidArgumentError("style change: blend weights must be finite");
        weights.push_back(blend.weights(i));
      }
      c.code = model::MixStyles(codes, weights);
      // The movement of the style with the largest weight.
      const int main = static_cast<int>(std::max_element(weights.begin(), weights.end()) -
                                        weights.begin());
      c.movement = MovementFor(*service_, blend.styles(main));
    }
    return streamer_->ChangeStyle(c);
  }

  absl::Status AddFrame(const v1::Frame& frame, bool* batched) {
    if (streamer_->received() == 0) {
      first_index_ = frame.index();
    } else if (frame.index() != first_index_ + streamer_->received()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "frame index ", frame.index(), " where ", first_index_ + streamer_->received(),
          " was expected: frames must arrive in order, without gaps or repeats"));
    }
    if (streamer_->received() >= service_->max_stream_frames) {
      return absl::ResourceExhaustedError(absl::StrCat("the stream reached the server's limit of ",
                                                       service_->max_stream_frames, " frames"));
    }
    chunk_.num_frames = 0;
    chunk_.values.clear();
    if (absl::Status s = wire::AppendFrame(frame, "stream", &prev_euler_, &chunk_); !s.ok()) {
      return s;
    }
    ++outcome_.frames;
    if (Batched()) {
      if (absl::Status s = streamer_->Feed(chunk_); !s.ok()) return s;
      return SubmitSteps(batched);
    }
    absl::StatusOr<motion::Motion> out = streamer_->Push(chunk_);
    if (!out.ok()) return out.status();
    Enqueue(*out);
    return absl::OkStatus();
  }

  void Enqueue(const motion::Motion& frames) {
    if (frames.num_frames == 0) return;
    const int64_t first = first_index_ + streamer_->emitted() - frames.num_frames;
    std::vector<v1::StreamResponse> batch(frames.num_frames);
    {
      absl::MutexLock lock(&mu_);
      for (int f = 0; f < frames.num_frames && !spare_.empty(); ++f) {
        batch[f] = std::move(spare_.back());
        spare_.pop_back();
      }
    }
    for (int f = 0; f < frames.num_frames; ++f) {
      v1::StreamResponse& r = batch[f];
      wire::FrameToProto(frames, f, first + f, r.mutable_frame());
      r.mutable_frame()->set_timestamp((first + f) * frames.frame_time);
    }
    if (Metrics* m = service_->metrics) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - read_at_).count();
      for (int f = 0; f < frames.num_frames; ++f) m->StreamFrameSeconds(s);
    }
    absl::MutexLock lock(&mu_);
    if (failed_) return;
    for (auto& r : batch) writes_.push_back(std::move(r));
  }

  // After each task: start the next read, a write, or the end of the call.
  // The session stays busy until the new operations have been started, so
  // that a concurrent OnCancel cannot Finish the call in between (starting an
  // operation on a finished call is an API misuse).
  void AfterTask() {
    bool read = false;
    bool end = false;
    bool paused = false;
    const v1::StreamResponse* write = nullptr;
    {
      absl::MutexLock lock(&mu_);
      if (!failed_ && !ending_ && !finished_) (draining_ ? end : read) = true;
      if (read && static_cast<int>(writes_.size()) >= service_->limits.max_stream_backlog) {
        // Back-pressure: the client does not read what it is sent, so its
        // next frames wait in its own send buffer, not here. OnWriteDone
        // reads on once it has read half of the backlog.
        read = false;
        paused = read_paused_ = true;
        paused_since_ = std::chrono::steady_clock::now();
      }
      if (!writing_ && !writes_.empty() && !failed_ && !finished_) {
        writing_ = true;
        write = &writes_.front();
      }
    }
    if (write != nullptr) Write(*write);
    if (end) {
      // Draining: flush instead of reading on; the session stays busy until
      // the end's own AfterTask (ending_ is set by then).
      if (!HandleEnd()) AfterTask();
      return;
    }
    if (read) {
      {
        absl::MutexLock lock(&mu_);
        reading_ = true;
        waiting_since_ = std::chrono::steady_clock::now();
      }
      StartRead(&read_bytes_);
    }
    mu_.Lock();
    // A drain that began after the choice to read found this task busy and
    // left the end to it: end now, unless the read has already completed and
    // queued a task of its own (busy_ > 1), whose AfterTask ends the stream.
    if ((read || paused) && draining_ && busy_ == 1 && !ending_ && !failed_ && !finished_) {
      mu_.Unlock();
      if (!HandleEnd()) AfterTask();
      return;
    }
    ReleaseLocked();
  }

  // Ends a task (busy_ -> false) with mu_ held, and releases mu_. Then, in
  // this order of preference: destroys the session if gRPC is done with it,
  // or finishes the call if it should end now, or leaves it. Nothing touches
  // the session after this returns: once the lock is released, OnDone may
  // delete it at any moment.
  void ReleaseLocked() ABSL_UNLOCK_FUNCTION(mu_) {
    --busy_;
    const bool done = done_ && busy_ == 0 && !alarm_set_;
    const bool finish = !done && ShouldFinishLocked();
    absl::Status status;
    if (finish) {
      finished_ = true;
      status = outcome_.status;
    }
    mu_.Unlock();
    if (done) {
      Destroy();
    } else if (finish) {
      FinishCall(status);
    }
  }

  // The idle timeout: an alarm at `since` + the timeout. When it fires, a
  // stream that has waited that long for the client's next message is ended;
  // any other is re-armed from the time it started waiting.
  void ArmIdleAlarmLocked(std::chrono::steady_clock::time_point since)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    alarm_set_ = true;
    const auto at =
        std::chrono::system_clock::now() +
        (since + service_->limits.stream_idle_timeout - std::chrono::steady_clock::now());
    // Re-armed from its own callback: set the other alarm, not the one whose
    // callback is running.
    alarm_index_ ^= 1;
    idle_alarms_[alarm_index_].Set(at, [this](bool fired) { OnIdleAlarm(fired); });
  }

  void OnIdleAlarm(bool fired) {
    bool destroy = false;
    bool finish = false;
    bool cancel = false;
    {
      absl::MutexLock lock(&mu_);
      alarm_set_ = false;
      if (done_) {
        destroy = busy_ == 0;
      } else if (fired && !finished_ && !failed_) {
        const auto now = std::chrono::steady_clock::now();
        const bool waiting = reading_ && busy_ == 0;
        const bool stalled = read_paused_ && busy_ == 0;
        const double timeout_s =
            std::chrono::duration<double>(service_->limits.stream_idle_timeout).count();
        if (waiting && now - waiting_since_ >= service_->limits.stream_idle_timeout) {
          Fail(absl::DeadlineExceededError(
              absl::StrCat("no message from the client for ", timeout_s,
                           " s (--stream-idle-timeout-s): the stream is closed")));
          finish = true;
        } else if (stalled && now - paused_since_ >= service_->limits.stream_idle_timeout) {
          // Its write may never complete: cancelling the call completes it.
          Fail(absl::DeadlineExceededError(
              absl::StrCat("the client read none of the stream's output for ", timeout_s,
                           " s (--stream-idle-timeout-s): the stream is closed")));
          finish = cancel = true;
        } else {
          ArmIdleAlarmLocked(waiting ? waiting_since_ : stalled ? paused_since_ : now);
        }
      }
    }
    if (destroy) {
      Destroy();
    } else if (finish) {
      if (cancel) ctx_->TryCancel();
      MaybeFinishOutsideLock();
    }
  }

  // Starts writing `response` (the front of writes_, which stays until
  // OnWriteDone; one write in flight at a time, so one buffer serves).
  void Write(const v1::StreamResponse& response) {
    const absl::Status s = SerializeMessage(response, &write_bytes_);
    if (!s.ok()) {
      {
        absl::MutexLock lock(&mu_);
        Fail(s);
      }
      OnWriteDone(false);
      return;
    }
    StartWrite(&write_bytes_);
  }

  bool ShouldFinishLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (finished_ || busy_ > 0 || writing_) return false;
    return failed_ || (ending_ && writes_.empty());
  }

  // The end: the call is done and no task of the session runs any more, so
  // nothing else reads or writes the session.
  void Destroy() {
    if (registered_) service_->streams.Remove(this);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
            .count();
    LogCall(kMethod, origin_, outcome_, ms);
    if (Metrics* m = service_->metrics) {
      m->CallHandled(series_, outcome_.status.code(), ms / 1000);
      if (outcome_.frames > 0) m->Frames(outcome_.model, "stream", outcome_.frames);
    }
    // Counted out last: once no stream is open, every stream's line is logged
    // (and shutdown's linger runs from the last stream's end).
    if (registered_) MarkAnswered(service_);
    if (admitted_) service_->admitted_streams.fetch_sub(1);
    service_->open_streams.fetch_sub(1);
    delete this;
  }

  // Records the first error; queued writes are dropped.
  void Fail(const absl::Status& s) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (failed_) return;
    failed_ = true;
    outcome_.status = s;
    if (!writing_) writes_.clear();
  }

  // From gRPC's reactions (which gRPC runs to completion before OnDone).
  void MaybeFinishOutsideLock() {
    absl::Status status;
    {
      absl::MutexLock lock(&mu_);
      if (!ShouldFinishLocked()) return;
      finished_ = true;
      status = outcome_.status;
    }
    FinishCall(status);
  }

  // Ends the call with `status`, telling the client how many frames the
  // server took (all of which it returned unless the status says otherwise).
  // Called once, after the last task (outcome_.frames is settled).
  void FinishCall(const absl::Status& status) {
    ctx_->AddTrailingMetadata("stylus-frames-received", std::to_string(outcome_.frames));
    Finish(ToGrpcStatus(status));
  }

  static constexpr char kMethod[] = "TransferStream";
  static constexpr char kType[] = "bidi_stream";

  ServiceContext* const service_;
  grpc::CallbackServerContext* const ctx_;
  const CallOrigin origin_;
  bool registered_ = false;  // In service_->streams (set in the constructor).
  bool admitted_ = false;    // Let in, and counted in service_->admitted_streams.
  // The method's metric series (null without metrics).
  const Metrics::Rpc* const series_;
  const std::chrono::steady_clock::time_point start_;
  // When the request being handled was read (written by OnReadDone before
  // its task runs; read by that task).
  std::chrono::steady_clock::time_point read_at_;
  grpc::ByteBuffer read_bytes_;   // Read buffer; the task parses it...
  StreamRequests<v1::StreamRequest> requests_;  // ...into this, and reads it in place.
  int64_t messages_read_ = 0;     // Counted by OnReadDone, read by the task.
  grpc::ByteBuffer write_bytes_;  // The write in flight.

  // Touched by the executor task only (one at a time per session).
  std::unique_ptr<model::FrameStreamer> streamer_;
  MemoryHold example_hold_;  // For the style clip's reading it keeps.
  std::shared_ptr<const model::StyleModel> model_;
  std::optional<HostedModel> hosted_;  // The model configured (style names are its).
  motion::Motion chunk_;
  std::vector<motion::Vec3> prev_euler_;
  int64_t first_index_ = 0;

  absl::Mutex mu_;
  std::deque<v1::StreamResponse> writes_ ABSL_GUARDED_BY(mu_);
  static constexpr size_t kSpareResponses = 4;
  std::vector<v1::StreamResponse> spare_ ABSL_GUARDED_BY(mu_);  // Written, for reuse.
  bool writing_ ABSL_GUARDED_BY(mu_) = false;
  // Executor tasks of this session queued or running (a reaction that gRPC
  // runs inline, inside StartRead, can queue one while another ends).
  int busy_ ABSL_GUARDED_BY(mu_) = 0;
  bool ending_ ABSL_GUARDED_BY(mu_) = false;
  bool failed_ ABSL_GUARDED_BY(mu_) = false;
  bool finished_ ABSL_GUARDED_BY(mu_) = false;
  bool done_ ABSL_GUARDED_BY(mu_) = false;      // OnDone has run.
  bool draining_ ABSL_GUARDED_BY(mu_) = false;  // Shutdown: no more frames taken.
  // A read is started and not done, since waiting_since_.
  bool reading_ ABSL_GUARDED_BY(mu_) = true;
  // No read is started because the client has not read the backlog
  // (--max-stream-backlog), since paused_since_ or its last read.
  bool read_paused_ ABSL_GUARDED_BY(mu_) = false;
  std::chrono::steady_clock::time_point paused_since_ ABSL_GUARDED_BY(mu_);
  std::chrono::steady_clock::time_point waiting_since_ ABSL_GUARDED_BY(mu_) = start_;
  grpc::Alarm idle_alarms_[2];
  int alarm_index_ ABSL_GUARDED_BY(mu_) = 0;     // The one set last.
  bool alarm_set_ ABSL_GUARDED_BY(mu_) = false;  // Its callback has yet to run.
  CallOutcome outcome_;                          // status guarded by mu_; model/frames by the task.
};

}  // namespace

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* StartStreamSession(
    ServiceContext* service, grpc::CallbackServerContext* ctx) {
  return new StreamSession(service, ctx);
}

}  // namespace stylus::server
