// What the RPC handlers share: the models, the style bank, the compute
// executor, limits, access checks, and the unary call pattern.
#ifndef STYLUS_SERVER_SERVICE_CONTEXT_H_
#define STYLUS_SERVER_SERVICE_CONTEXT_H_

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "model/pass_batcher.h"
#include "server/call_log.h"
#include "server/executor.h"
#include "server/metrics.h"
#include "server/open_streams.h"
#include "server/raw_message.h"
#include "server/registry.h"
#include "server/step_batcher.h"
#include "server/style_bank.h"
#include "server/token_auth.h"
#include "stylus/v1/stylus.pb.h"

namespace stylus::server {

// What one call may ask of the process (each a stylus-server flag).
struct CallLimits {
  int64_t max_clip_frames = 36000;  // Frames per clip in a unary call (20 min at 30 fps).
  int max_joints = 256;             // Joints per skeleton, in any call or stream.
  int max_unary_calls = 64;         // Unary calls accepted and not yet answered.
  // A stream waiting this long for the client's next message is closed
  // (0: never).
  std::chrono::milliseconds stream_idle_timeout{120000};
};

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
  CallLimits limits;
  std::atomic<int> open_streams{0};
  OpenStreams streams;  // Drained at shutdown.
  std::atomic<int> unary_calls{0};  // Accepted and not yet answered.
  // Set when shutdown begins: new unary calls end UNAVAILABLE unrun.
  std::atomic<bool> refusing_calls{false};
  // When a unary call was last answered (steady clock, ns since its epoch): shutdown
  // keeps the connections open a moment after it, so that a large reply
  // still in the socket's buffer reaches its client before the connection
  // closes.
  std::atomic<int64_t> last_answer_ns{0};
};

// Records that a call has just been answered (ServiceContext::last_answer_ns).
void MarkAnswered(ServiceContext* service);

// A clip from a request, within the limits: RESOURCE_EXHAUSTED naming `what`,
// the size and the flag for one over --max-clip-frames or --max-joints;
// then the checks of wire::ClipFromProto.
absl::StatusOr<motion::Motion> ReadClip(const ServiceContext& service, const v1::Clip& clip,
                                        const std::string& what);
// RESOURCE_EXHAUSTED when a skeleton of `joints` joints is over --max-joints.
absl::Status CheckJoints(const ServiceContext& service, int joints, const std::string& what);

inline constexpr char kStyleService[] = "stylus.v1.StyleService";
inline constexpr char kModelService[] = "stylus.v1.ModelService";

// Runs `work` on the executor and finishes the call with its status: the
// unary pattern of every StyleService/ModelService method. A call whose
// client has gone or whose deadline has passed before the work starts is not
// computed. UNAVAILABLE when the executor no longer accepts work (shutdown).
// OK, or UNAUTHENTICATED when the server wants a token and the call has no
// valid one (the token is never logged).
absl::Status CheckToken(const ServiceContext& service, const grpc::CallbackServerContext* ctx);

// Runs a unary call: `parsed` is how its request parsed (server/raw_message.h);
// when it is not OK the call ends with it, unrun. Counted in the metrics (when
// on) under `grpc_service` and `rpc`. A call without a valid token (when
// tokens are on) ends UNAUTHENTICATED unrun.
grpc::ServerUnaryReactor* RunUnaryCall(ServiceContext* service, grpc::CallbackServerContext* ctx,
                                       const char* grpc_service, const std::string& rpc,
                                       const absl::Status& parsed,
                                       std::function<CallOutcome()> work);

// The unary pattern with typed messages: parses `raw_request` as a Request,
// runs `work` on it, and serializes its Response into `raw_response` when
// the call succeeds.
template <class Request, class Response>
grpc::ServerUnaryReactor* RunUnary(
    ServiceContext* service, grpc::CallbackServerContext* ctx, const char* grpc_service,
    const std::string& rpc, const grpc::ByteBuffer* raw_request, grpc::ByteBuffer* raw_response,
    std::function<CallOutcome(const Request& request, Response* response)> work) {
  // Shared: std::function needs a copyable callable.
  auto messages = std::make_shared<std::pair<Request, Response>>();
  const absl::Status parsed = ParseMessage(*raw_request, "the request", &messages->first);
  return RunUnaryCall(service, ctx, grpc_service, rpc, parsed,
                      [messages, raw_response, work = std::move(work)] {
                        CallOutcome out = work(messages->first, &messages->second);
                        if (out.status.ok())
                          out.status = SerializeMessage(messages->second, raw_response);
                        return out;
                      });
}

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVICE_CONTEXT_H_
