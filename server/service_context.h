// What the RPC handlers share: the models, the style bank, the compute
// executor, limits, and the per-call log line.
#ifndef STYLUS_SERVER_SERVICE_CONTEXT_H_
#define STYLUS_SERVER_SERVICE_CONTEXT_H_

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "model/pass_batcher.h"
#include "server/executor.h"
#include "server/metrics.h"
#include "server/registry.h"
#include "server/step_batcher.h"
#include "server/style_bank.h"
#include "server/token_auth.h"

namespace stylus::server {

struct ServiceContext {
  ModelRegistry* registry = nullptr;
  StyleBank* styles = nullptr;
  Executor* executor = nullptr;
  // Batches live streams' steps (null: each stream steps alone).
  StepBatcher* batcher = nullptr;
  // Batches unary transfers' network passes (null: each call runs alone).
  model::PassBatcher* pass_batcher = nullptr;
  Metrics* metrics = nullptr;  // With --metrics-listen.
  TokenAuth* auth = nullptr;   // With --auth-tokens: calls need a token.
  int max_streams = 16;
  int64_t max_stream_frames = 30 * 60 * 60;  // One hour at 30 fps.
  std::atomic<int> open_streams{0};
};

// What a handler reports for the log line.
struct CallOutcome {
  absl::Status status;
  std::string model;
  int64_t frames = 0;
  std::string note = {};       // Appended to the log line when not empty (e.g. "guard=configured").
  double model_seconds = 0;    // The model's compute time, when it ran.
  bool guard_backoff = false;  // The content guard chose a weaker form.
};

inline constexpr char kStyleService[] = "stylus.v1.StyleService";
inline constexpr char kModelService[] = "stylus.v1.ModelService";

// One spdlog line per call: rpc, model, frames, milliseconds, status.
void LogCall(const std::string& rpc, const CallOutcome& outcome, double ms);

// Runs `work` on the executor and finishes the call with its status: the
// unary pattern of every StyleService/ModelService method. A call whose
// client has gone or whose deadline has passed before the work starts is not
// computed. UNAVAILABLE when the executor no longer accepts work (shutdown).
// OK, or UNAUTHENTICATED when the server wants a token and the call has no
// valid one (the token is never logged).
absl::Status CheckToken(const ServiceContext& service, const grpc::CallbackServerContext* ctx);

// Counted in the metrics (when on) under `grpc_service` and `rpc`. A call
// without a valid token (when tokens are on) ends UNAUTHENTICATED unrun.
grpc::ServerUnaryReactor* RunUnary(ServiceContext* service, grpc::CallbackServerContext* ctx,
                                   const char* grpc_service, const std::string& rpc,
                                   std::function<CallOutcome()> work);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVICE_CONTEXT_H_
