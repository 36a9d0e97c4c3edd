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
#include "model/movement.h"
#include "model/pass_batcher.h"
#include "server/call_log.h"
#include "server/executor.h"
#include "server/metrics.h"
#include "server/open_streams.h"
#include "server/raw_message.h"
#include "server/registry.h"
#include "server/request_budget.h"
#include "server/step_batcher.h"
#include "server/style_bank.h"
#include "server/token_auth.h"
#include "stylus/v1/stylus.pb.h"

namespace stylus::server {

// What one call may ask of the process (each a stylus-server flag). The
// counts and sizes within a request are the request budget's
// (server/request_budget.h), checked before it is parsed.
struct CallLimits {
  int max_unary_calls = 64;         // Unary calls accepted and not yet answered.
  int max_styles = 16;              // Styles in one Interpolate call or one blend.
  // Output frames a stream may hold for a client that does not read them;
  // past this the stream stops reading the client's frames until it reads.
  int max_stream_backlog = 128;
  // A stream waiting this long for the client's next message, or for it to
  // read the stream's output, is closed (0: never).
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
  TokenAuth* admin_auth = nullptr;        // With --admin-tokens: loading models needs one of these.
  const RequestBudget* budget = nullptr;  // What reading a request may cost.
  MemoryPool* call_memory = nullptr;      // What unary calls in progress may hold.
  // Takes of styles for movement from examples (--style-library; null: none).
  const model::StyleLibrary* style_library = nullptr;
  int max_streams = 16;
  int64_t max_stream_frames = 30 * 60 * 60;  // One hour at 30 fps.
  CallLimits limits;
  std::atomic<int> open_streams{0};      // Stream sessions alive (shutdown waits for 0).
  std::atomic<int> admitted_streams{0};  // Of those, let in (counted against max_streams).
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

inline constexpr char kStyleService[] = "stylus.v1.StyleService";
inline constexpr char kModelService[] = "stylus.v1.ModelService";

// Who may make a call: serving calls (transfers, streams, style and model
// queries) or administration (LoadModel, UnloadModel).
enum class Access { kServe, kAdmin };

// OK when the call's `authorization` metadata lets it in for `access`
// (the token is never logged):
// - no --auth-tokens and no --admin-tokens: everyone may do everything;
// - serving calls need a token from --auth-tokens or --admin-tokens (open
//   when only --admin-tokens is given);
// - administration needs a token from --admin-tokens; with tokens on and
//   none of those, PERMISSION_DENIED for a serving token.
// UNAUTHENTICATED for no token or an unknown one.
absl::Status CheckAccess(const ServiceContext& service, const grpc::CallbackServerContext* ctx,
                         Access access);

// The request budget's check of `bytes` as a `type` (server/request_budget.h).
absl::Status CheckRequestBudget(const ServiceContext& service, const grpc::ByteBuffer& bytes,
                                const google::protobuf::Descriptor* type, const std::string& what);

// What a unary call's request of `bytes` may take to serve, held from the
// call's memory pool (--max-memory-mb) until the hold goes: the budget's
// check first, then the parse's estimate plus the working memory the call's
// frames need. RESOURCE_EXHAUSTED when the pool cannot hold it now.
absl::StatusOr<MemoryHold> ReserveCall(const ServiceContext& service, const grpc::ByteBuffer& bytes,
                                       const google::protobuf::Descriptor* type);

// Working memory a transfer needs per byte of its request, beyond the parsed
// request (measured: docs/notes/operations.md "Memory per call").
inline constexpr int64_t kWorkingBytesPerRequestByte = 20;

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVICE_CONTEXT_H_
