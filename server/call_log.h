// The server's log: text for people (the default) or one JSON object per
// line for log shippers (--log-format json), and the one line each call
// writes when it ends: method, model, frames, time, status, request id, peer.
//
// Thread-safety: SetUpLogging once at start-up, before any call; the rest
// from any thread.
#ifndef STYLUS_SERVER_CALL_LOG_H_
#define STYLUS_SERVER_CALL_LOG_H_

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "spdlog/sinks/sink.h"

namespace stylus::server {

enum class LogFormat { kText, kJson };

absl::StatusOr<LogFormat> ParseLogFormat(const std::string& name);  // "text" or "json".

// Makes the default logger write `format` to `sink` (null: stderr). JSON
// lines: {"time":"...Z","level":"info","msg":"..."}; a call's line has its
// fields instead of "msg".
void SetUpLogging(LogFormat format, std::shared_ptr<spdlog::sinks::sink> sink = nullptr);

// Who made a call: the request id (the client's x-request-id metadata when
// it is 1-128 printable characters without spaces, else one made here) and
// the peer address. The id goes back to the client in the response's
// initial metadata.
struct CallOrigin {
  std::string request_id;
  std::string peer;
};
CallOrigin IdentifyCall(grpc::CallbackServerContext* ctx);

// What a handler reports for the log line.
struct CallOutcome {
  absl::Status status;
  std::string model;
  int64_t frames = 0;
  std::string note = {};       // Appended to the log line when not empty (e.g. "guard=configured").
  double model_seconds = 0;    // The model's compute time, when it ran.
  bool guard_backoff = false;  // The content guard chose a weaker form.
};

// One line per call: rpc, model, frames, milliseconds, status (and its
// message when not OK), request id, peer. Warning level when not OK.
void LogCall(const std::string& rpc, const CallOrigin& origin, const CallOutcome& outcome,
             double ms);

// The longest client-supplied field a log line holds (model id, message,
// note, peer); a longer one is cut there and its size noted.
inline constexpr size_t kMaxLoggedField = 512;
std::string Capped(const std::string& text);

// `text` for a text log line: control characters as \xNN, backslashes and
// quotes escaped, so that no client string starts a line of its own.
std::string TextEscape(const std::string& text);

// `text` as a JSON string literal's contents (quotes, backslashes and
// control characters escaped; other bytes kept).
std::string JsonEscape(const std::string& text);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_CALL_LOG_H_
