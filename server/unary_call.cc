#include "server/unary_call.h"

#include <chrono>

#include "server/status.h"

namespace stylus::server {
namespace {

class UnaryCall final : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  UnaryCall(ServiceContext* service, grpc::CallbackServerContext* ctx, const UnaryMethod* method)
      : service_(service),
        ctx_(ctx),
        method_(method),
        origin_(IdentifyCall(ctx)),
        series_(service->metrics != nullptr
                    ? service->metrics->Series(method->grpc_service, method->rpc, "unary")
                    : nullptr),
        start_(std::chrono::steady_clock::now()) {
    if (series_ != nullptr) service_->metrics->CallStarted(series_);
    // Everything that can refuse the call, before a byte of its request is read.
    absl::Status refused = CheckAccess(*service_, ctx, method_->access);
    if (refused.ok() && service_->refusing_calls.load()) {
      refused = absl::UnavailableError("the server is shutting down");
    }
    if (refused.ok()) {
      counted_ = true;
      if (service_->unary_calls.fetch_add(1) + 1 > service_->limits.max_unary_calls) {
        refused = absl::ResourceExhaustedError(
            absl::StrCat("the server already has ", service_->limits.max_unary_calls,
                         " calls waiting or running (--max-unary-calls); retry with backoff"));
      }
    }
    if (!refused.ok()) {
      outcome_.status = refused;
      End();
      return;
    }
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      // The client cancelled, or half-closed without a request.
      outcome_.status = absl::InvalidArgumentError("the call ended before its request arrived");
      End();
      return;
    }
    if (series_ != nullptr) service_->metrics->MessageReceived(series_);
    if (!service_->executor->Submit([this] { Run(); })) {
      outcome_.status = absl::UnavailableError("the server is shutting down");
      End();
    }
  }

  void OnDone() override {
    if (counted_) {
      // Answered once gRPC has handed the reply to the transport; shutdown
      // lingers a moment after the last answer (server.cc).
      MarkAnswered(service_);
      service_->unary_calls.fetch_sub(1);
    }
    delete this;
  }

 private:
  void Run() {
    if (ctx_->IsCancelled()) {
      outcome_.status = absl::CancelledError("cancelled or past its deadline before it ran");
    } else {
      outcome_ = method_->run(request_, &response_);
    }
    request_.Clear();  // The request's bytes go now, not with the reply.
    End();
  }

  // Logs and counts the call (before its client can see the answer), then
  // answers it.
  void End() {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    LogCall(method_->rpc, origin_, outcome_, seconds * 1000);
    Count(seconds);
    if (outcome_.status.ok()) {
      StartWriteAndFinish(&response_, grpc::WriteOptions(), grpc::Status::OK);
    } else {
      Finish(ToGrpcStatus(outcome_.status));
    }
  }

  void Count(double seconds) {
    Metrics* metrics = service_->metrics;
    if (metrics == nullptr) return;
    metrics->CallHandled(series_, outcome_.status.code(), seconds);
    if (!outcome_.status.ok()) return;
    metrics->MessageSent(series_);
    if (outcome_.model_seconds > 0) metrics->ModelSeconds(outcome_.model, outcome_.model_seconds);
    if (outcome_.frames > 0 && outcome_.model_seconds > 0) {
      metrics->Frames(outcome_.model, "unary", outcome_.frames);
    }
    if (outcome_.guard_backoff) metrics->GuardBackoff(outcome_.model);
  }

  ServiceContext* const service_;
  grpc::CallbackServerContext* const ctx_;
  const UnaryMethod* const method_;
  const CallOrigin origin_;
  const Metrics::Rpc* const series_;
  const std::chrono::steady_clock::time_point start_;
  bool counted_ = false;  // In service_->unary_calls.
  grpc::ByteBuffer request_;
  grpc::ByteBuffer response_;
  CallOutcome outcome_;
};

}  // namespace

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* StartUnaryCall(
    ServiceContext* service, grpc::CallbackServerContext* ctx, const UnaryMethod* method) {
  return new UnaryCall(service, ctx, method);
}

}  // namespace stylus::server
