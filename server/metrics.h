// Prometheus metrics of a running server (docs/service.md "Metrics"), served
// over HTTP at /metrics when `stylus-server --metrics-listen ADDR` is given:
// the conventional gRPC server series (grpc_server_started_total,
// grpc_server_handled_total, grpc_server_msg_received_total,
// grpc_server_msg_sent_total, grpc_server_handling_seconds; labels
// grpc_service, grpc_method, grpc_type) and Stylus's own (stylus_*). Values
// that are states (open streams, queue depth, loaded models, memory) are read
// when Prometheus scrapes.
//
// Thread-safety: every method may be called from any thread.
#ifndef STYLUS_SERVER_METRICS_H_
#define STYLUS_SERVER_METRICS_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace stylus::server {

// What a scrape reads from the server at that moment.
struct MetricsState {
  int open_streams = 0;
  int queued_tasks = 0;
  int running_tasks = 0;
  int loaded_models = 0;
  int64_t unary_batches = 0;
  int64_t batched_calls = 0;
};

class Metrics {
 public:
  // Serves /metrics on `listen` ("host:port"; port 0 picks a free one;
  // server/http_endpoint.h); `state` is called at each scrape. UNAVAILABLE
  // when it cannot bind, INVALID_ARGUMENT for an address it cannot read.
  static absl::StatusOr<std::unique_ptr<Metrics>> Start(const std::string& listen,
                                                        std::function<MetricsState()> state);
  ~Metrics();
  int port() const;

  // The gRPC series of one method, resolved once and kept for the server's
  // life, so that counting a stream's messages looks nothing up; `type` is
  // "unary" or "bidi_stream".
  struct Rpc;
  const Rpc* Series(const std::string& service, const std::string& method, const char* type);
  void CallStarted(const Rpc* rpc);
  void CallHandled(const Rpc* rpc, absl::StatusCode code, double seconds);
  void MessageReceived(const Rpc* rpc);
  void MessageSent(const Rpc* rpc);

  // Stylus's: the model's compute time of a unary call or of a batch of
  // live steps, by model; frames transferred, by model and "unary"/"stream";
  // seconds from reading the request that made a stream frame final to
  // queueing it for the client; a content guard's back-off, by model; the
  // streams in one batch of live steps.
  void ModelSeconds(const std::string& model, double seconds);
  void Frames(const std::string& model, const char* kind, int64_t frames);
  void StreamFrameSeconds(double seconds);
  void GuardBackoff(const std::string& model);
  void StepBatch(int64_t streams);

 private:
  struct Impl;
  explicit Metrics(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_METRICS_H_
