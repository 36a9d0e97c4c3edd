// A running Stylus gRPC server: models loaded from a directory, the Model and
// Style services, grpc.health.v1 and server reflection.
//
// Thread-safety: Shutdown may be called from any thread, once or more.
#ifndef STYLUS_SERVER_SERVER_H_
#define STYLUS_SERVER_SERVER_H_

#include <chrono>
#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace stylus::server {

// The largest --max-message-mb (gRPC counts message sizes in an int).
inline constexpr int kMaxMessageMb = 1024;

struct ServerOptions {
  std::string models_dir = "models";
  std::string default_model;               // "<name>/<version>"; empty: the first found.
  std::string listen = "localhost:50051";  // Port 0 picks a free port.
  int threads = 2;                         // Compute executor threads.
  int torch_threads = 1;                   // LibTorch intra-op threads per forward.
  int max_streams = 1024;
  // Batching (docs/service.md "Batching"): the most live streams' steps
  // (server/step_batcher.h), or unary transfers' windows
  // (model/pass_batcher.h), in one forward; 0: none, each call runs alone.
  int max_batch = 256;
  int max_queue_delay_us = 500;
  // Unary transfers batch too (off by default: on a CPU the calls already
  // run in parallel on the executor's threads, and waiting for others costs
  // more than a bigger forward saves; docs/service.md "Batching").
  bool batch_unary = false;
  // Serves Prometheus metrics at http://ADDR/metrics when not empty
  // (server/metrics.h); port 0 picks a free one (metrics_port()).
  std::string metrics_listen;
  // When not empty, calls need "authorization: Bearer TOKEN" with a token
  // from this file (server/token_auth.h); health checks stay open.
  std::string auth_tokens;
  // When not empty, LoadModel and UnloadModel need a token from this file
  // (which also serves); without it, a server with auth_tokens loads no
  // models after start-up (server/service_context.h CheckAccess).
  std::string admin_tokens;
  // Serves grpc.reflection (the API's description) when set; it runs on
  // gRPC's synchronous threads, at most max_sync_threads of them.
  bool reflection = false;
  // TLS (server/tls.h): certificate and key; with client_ca, mutual TLS.
  // Empty: plain text.
  std::string tls_cert;
  std::string tls_key;
  std::string tls_client_ca;
  int max_message_mb = 32;  // At most kMaxMessageMb.
  int64_t max_stream_frames = 30 * 60 * 60;
  // Limits that protect the process (docs/service.md "Limits").
  int64_t max_clip_frames = 36000;     // Per clip in a unary call.
  int max_joints = 256;                // Per skeleton.
  int max_unary_calls = 64;            // Waiting or running; more: RESOURCE_EXHAUSTED.
  int max_styles = 16;                 // Styles per Interpolate call or blend.
  int max_stream_backlog = 128;        // Output frames a stream holds for a client not reading.
  // Memory gRPC may use for connections and messages in flight (its
  // ResourceQuota), and the working memory unary calls may reserve (each
  // reserves its estimate before it runs); 0: unbounded.
  int64_t max_memory_mb = 2048;
  int max_saved_styles = 1000;         // Names saved per model.
  // Movement from examples (model/movement.h): a folder of style takes, and
  // their labels when their names carry none.
  std::string style_library;
  std::string style_library_labels;
  double stream_idle_timeout_s = 120;  // 0: streams may wait forever.
};

// What the server is doing now.
struct ServerLoad {
  int open_streams = 0;
  int queued_tasks = 0;       // Compute work accepted and waiting for a thread.
  int running_tasks = 0;      // Compute work running now.
  int64_t batches = 0;        // Live step batches run since the start...
  int64_t batched_steps = 0;  // ...and the steps they held.
  int64_t unary_batches = 0;  // Unary network passes run for several calls...
  int64_t batched_calls = 0;  // ...and the calls they held.
};

class StylusServer {
 public:
  // Loads the models and starts serving. NOT_FOUND / INVALID_ARGUMENT from the
  // model directory; UNAVAILABLE when the address cannot be bound.
  static absl::StatusOr<std::unique_ptr<StylusServer>> Start(const ServerOptions& options);
  ~StylusServer();

  // The port actually bound (useful with port 0).
  int port() const;
  // The metrics port bound, 0 without metrics.
  int metrics_port() const;
  // Reads the token files again (SIGHUP; they are also re-read when they
  // change): the serving tokens in force, or the error (FAILED_PRECONDITION
  // without --auth-tokens). A file that cannot be read or holds no valid
  // token revokes every token it held.
  absl::StatusOr<int> ReloadTokens();
  // What is running now; not to be called while Shutdown runs.
  ServerLoad load() const;
  // Stops accepting calls; drains open streams (no more frames taken; every
  // frame taken is returned, then the stream ends UNAVAILABLE); lets unary
  // calls finish; cancels what is left at `deadline`; drains the executor.
  void Shutdown(std::chrono::system_clock::time_point deadline);
  // Blocks until Shutdown has completed.
  void Wait();

 private:
  struct Impl;
  explicit StylusServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVER_H_
