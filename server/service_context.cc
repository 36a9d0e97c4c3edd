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

namespace {

// The metrics of a finished unary call.
void CountUnary(Metrics* metrics, const char* grpc_service, const std::string& rpc,
                const CallOutcome& outcome, double seconds) {
  if (metrics == nullptr) return;
  const Metrics::Rpc* series = metrics->Series(grpc_service, rpc, "unary");
  metrics->CallHandled(series, outcome.status.code(), seconds);
  if (!outcome.status.ok()) return;
  metrics->MessageSent(series);
  if (outcome.model_seconds > 0) metrics->ModelSeconds(outcome.model, outcome.model_seconds);
  if (outcome.frames > 0 && outcome.model_seconds > 0) {
    metrics->Frames(outcome.model, "unary", outcome.frames);
  }
  if (outcome.guard_backoff) metrics->GuardBackoff(outcome.model);
}

}  // namespace

absl::Status CheckToken(const ServiceContext& service, const grpc::CallbackServerContext* ctx) {
  if (service.auth == nullptr) return absl::OkStatus();
  const auto& metadata = ctx->client_metadata();
  const auto it = metadata.find("authorization");
  const absl::string_view value = it == metadata.end()
                                      ? absl::string_view()
                                      : absl::string_view(it->second.data(), it->second.size());
  if (service.auth->Allows(value)) return absl::OkStatus();
  return absl::UnauthenticatedError(
      it == metadata.end()
          ? "this server needs a token: send the metadata 'authorization: Bearer TOKEN' "
            "(stylus --token, $STYLUS_TOKEN)"
          : "the token is not one this server accepts");
}

grpc::ServerUnaryReactor* RunUnary(ServiceContext* service, grpc::CallbackServerContext* ctx,
                                   const char* grpc_service, const std::string& rpc,
                                   std::function<CallOutcome()> work) {
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  const auto start = std::chrono::steady_clock::now();
  Metrics* metrics = service->metrics;
  if (metrics != nullptr) {
    const Metrics::Rpc* series = metrics->Series(grpc_service, rpc, "unary");
    metrics->CallStarted(series);
    metrics->MessageReceived(series);
  }
  if (absl::Status token = CheckToken(*service, ctx); !token.ok()) {
    const CallOutcome outcome{token, "", 0};
    LogCall(rpc, outcome, 0);
    CountUnary(metrics, grpc_service, rpc, outcome, 0);
    reactor->Finish(ToGrpcStatus(outcome.status));
    return reactor;
  }
  auto run = [ctx, reactor, rpc, start, metrics, grpc_service, work = std::move(work)] {
    CallOutcome outcome;
    if (ctx->IsCancelled()) {
      outcome.status = absl::CancelledError("cancelled or past its deadline before it ran");
    } else {
      outcome = work();
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    LogCall(rpc, outcome, ms);
    CountUnary(metrics, grpc_service, rpc, outcome, ms / 1000);
    reactor->Finish(ToGrpcStatus(outcome.status));
  };
  if (!service->executor->Submit(run)) {
    CallOutcome outcome{absl::UnavailableError("the server is shutting down"), "", 0};
    LogCall(rpc, outcome, 0);
    CountUnary(metrics, grpc_service, rpc, outcome, 0);
    reactor->Finish(ToGrpcStatus(outcome.status));
  }
  return reactor;
}

}  // namespace stylus::server
