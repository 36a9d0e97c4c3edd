#include "server/service_context.h"

#include <chrono>

#include "absl/strings/str_cat.h"
#include "server/status.h"
#include "spdlog/spdlog.h"
#include "wire/wire.h"

namespace stylus::server {

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

void MarkAnswered(ServiceContext* service) {
  service->last_answer_ns.store(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                    std::chrono::steady_clock::now().time_since_epoch())
                                    .count());
}

absl::Status CheckJoints(const ServiceContext& service, int joints, const std::string& what) {
  if (joints <= service.limits.max_joints) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat(what, ": ", joints,
                                                   " joints, over this server's limit of ",
                                                   service.limits.max_joints, " (--max-joints)"));
}

absl::StatusOr<motion::Motion> ReadClip(const ServiceContext& service, const v1::Clip& clip,
                                        const std::string& what) {
  if (absl::Status s = CheckJoints(service, clip.skeleton().joints_size(), what); !s.ok()) return s;
  if (clip.frames_size() > service.limits.max_clip_frames) {
    return absl::ResourceExhaustedError(
        absl::StrCat(what, ": ", clip.frames_size(), " frames, over this server's limit of ",
                     service.limits.max_clip_frames,
                     " per call (--max-clip-frames); split the clip or stream it"));
  }
  return wire::ClipFromProto(clip, what);
}

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

grpc::ServerUnaryReactor* RunUnaryCall(ServiceContext* service, grpc::CallbackServerContext* ctx,
                                       const char* grpc_service, const std::string& rpc,
                                       const absl::Status& parsed,
                                       std::function<CallOutcome()> work) {
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  const CallOrigin origin = IdentifyCall(ctx);
  const auto start = std::chrono::steady_clock::now();
  Metrics* metrics = service->metrics;
  if (metrics != nullptr) {
    const Metrics::Rpc* series = metrics->Series(grpc_service, rpc, "unary");
    metrics->CallStarted(series);
    metrics->MessageReceived(series);
  }
  absl::Status refused = CheckToken(*service, ctx);
  if (refused.ok()) refused = parsed;
  if (refused.ok() && service->refusing_calls.load()) {
    refused = absl::UnavailableError("the server is shutting down");
  }
  // Counted from here until the call is answered; over the cap, refused.
  const int calls = service->unary_calls.fetch_add(1) + 1;
  if (refused.ok() && calls > service->limits.max_unary_calls) {
    refused = absl::ResourceExhaustedError(
        absl::StrCat("the server already has ", service->limits.max_unary_calls,
                     " calls waiting or running (--max-unary-calls); retry with backoff"));
  }
  if (!refused.ok()) {
    service->unary_calls.fetch_sub(1);
    const CallOutcome outcome{refused, "", 0};
    LogCall(rpc, origin, outcome, 0);
    CountUnary(metrics, grpc_service, rpc, outcome, 0);
    reactor->Finish(ToGrpcStatus(outcome.status));
    return reactor;
  }
  auto run = [service, ctx, reactor, rpc, origin, start, metrics, grpc_service,
              work = std::move(work)] {
    CallOutcome outcome;
    if (ctx->IsCancelled()) {
      outcome.status = absl::CancelledError("cancelled or past its deadline before it ran");
    } else {
      outcome = work();
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    LogCall(rpc, origin, outcome, ms);
    CountUnary(metrics, grpc_service, rpc, outcome, ms / 1000);
    MarkAnswered(service);  // Before the count drops, so shutdown's wait sees it.
    service->unary_calls.fetch_sub(1);
    reactor->Finish(ToGrpcStatus(outcome.status));
  };
  if (!service->executor->Submit(run)) {
    service->unary_calls.fetch_sub(1);
    CallOutcome outcome{absl::UnavailableError("the server is shutting down"), "", 0};
    LogCall(rpc, origin, outcome, 0);
    CountUnary(metrics, grpc_service, rpc, outcome, 0);
    reactor->Finish(ToGrpcStatus(outcome.status));
  }
  return reactor;
}

}  // namespace stylus::server
