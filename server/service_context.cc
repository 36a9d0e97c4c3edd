#include "server/service_context.h"

#include <chrono>

#include "server/status.h"
#include "spdlog/spdlog.h"

namespace stylus::server {

void LogCall(const std::string& rpc, const CallOutcome& outcome, double ms) {
  const std::string status =
      outcome.status.ok() ? "OK" : std::string(absl::StatusCodeToString(outcome.status.code()));
  if (outcome.status.ok()) {
    spdlog::info("rpc={} model={} frames={} ms={:.1f} status={}{}{}", rpc,
                 outcome.model.empty() ? "-" : outcome.model, outcome.frames, ms, status,
                 outcome.note.empty() ? "" : " ", outcome.note);
  } else {
    spdlog::warn("rpc={} model={} frames={} ms={:.1f} status={} message=\"{}\"", rpc,
                 outcome.model.empty() ? "-" : outcome.model, outcome.frames, ms, status,
                 std::string(outcome.status.message()));
  }
}

grpc::ServerUnaryReactor* RunUnary(ServiceContext* service, grpc::CallbackServerContext* ctx,
                                   const std::string& rpc, std::function<CallOutcome()> work) {
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  const auto start = std::chrono::steady_clock::now();
  auto run = [ctx, reactor, rpc, start, work = std::move(work)] {
    CallOutcome outcome;
    if (ctx->IsCancelled()) {
      outcome.status = absl::CancelledError("cancelled or past its deadline before it ran");
    } else {
      outcome = work();
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    LogCall(rpc, outcome, ms);
    reactor->Finish(ToGrpcStatus(outcome.status));
  };
  if (!service->executor->Submit(run)) {
    CallOutcome outcome{absl::UnavailableError("the server is shutting down"), "", 0};
    LogCall(rpc, outcome, 0);
    reactor->Finish(ToGrpcStatus(outcome.status));
  }
  return reactor;
}

}  // namespace stylus::server
