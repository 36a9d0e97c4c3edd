// stylus::Client: typed calls to a Stylus server. No LibTorch: clips are
// motion::Motion values (read and written with motion/bvh.h).
//
// Every call has a deadline (ClientOptions::deadline); errors come back as
// absl::Status with the server's code and message (INVALID_ARGUMENT names the
// clip, frame or joint to fix; UNAVAILABLE when no server answers).
// Thread-safety: a Client may be used from several threads at once.
#ifndef STYLUS_CLIENT_CLIENT_H_
#define STYLUS_CLIENT_CLIENT_H_

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"
#include "motion/rig_roles.h"
#include "stylus/v1/stylus.grpc.pb.h"

namespace stylus {

// TLS to the server (a server started with --tls-cert). PEM text, not paths:
// ReadTlsFiles reads them.
struct TlsOptions {
  bool enabled = false;
  std::string ca_pem;       // Trusted roots; empty: the system's.
  std::string cert_pem;     // Mutual TLS: this client's certificate...
  std::string key_pem;      // ...and its key.
  std::string server_name;  // Checked against the certificate instead of the address's host.
};

// TLS options from PEM files (any path may be empty; a CA or a certificate
// turns TLS on). INVALID_ARGUMENT for a certificate without its key (or the
// other way round) or a file that is not PEM; NOT_FOUND for a missing file.
absl::StatusOr<TlsOptions> ReadTlsFiles(const std::string& ca_file, const std::string& cert_file,
                                        const std::string& key_file);

struct ClientOptions {
  // A gRPC target: host:port, or dns:///name:port or ipv4:a:p,b:q for
  // several servers; calls go round-robin over every address it resolves,
  // and one refused UNAVAILABLE is retried on another (up to 3 tries).
  std::string address = "localhost:50051";
  std::chrono::milliseconds deadline{60000};  // Per unary call; per stream, x10.
  int max_message_mb = 64;
  // Sent as "authorization: Bearer TOKEN" with every call when not empty
  // (a server started with --auth-tokens).
  std::string token;
  TlsOptions tls;  // Off: plain text.
  // The longest wait between attempts to reach a server that went away
  // (gRPC's default grows to 2 minutes; a stage bridge wants a server back
  // within a second of its restart). 0: gRPC's default.
  int max_reconnect_backoff_ms = 0;
};

struct CallOptions {
  std::string model;  // Empty: the server's default.
  v1::PostProcess postprocess = v1::POSTPROCESS_DEFAULT;
  // Transfer and Interpolate: when set, receives how the model's content
  // guard treated the call (left empty for a model without one).
  v1::ContentGuardNote* content_guard = nullptr;
  // Transfer: whose timing the output keeps (v1::Timing); with TIMING_STYLE,
  // `time_warp` (when set) receives what was done.
  v1::Timing timing = v1::TIMING_CONTENT;
  v1::TimeWarp* time_warp = nullptr;
  // Transfer: an exact output length in frames (0: none; 0.5-2x the content's).
  int fit_frames = 0;
  // Transfer and Interpolate: when set, receives where the output's movement
  // came from (packages with movement from examples) and its foot contacts.
  v1::MovementNote* movement = nullptr;
  std::vector<v1::FootContact>* contacts = nullptr;
  // For a content clip (or stream) on another rig than the model's: roles
  // the server should not guess (motion/rig_roles.h), sent with its skeleton.
  motion::JointMap joint_map = {};
};

// A style: a clip to encode on the server, or a name saved with EncodeStyle.
struct Style {
  Style(const motion::Motion* clip = nullptr, std::string name = "",  // NOLINT
        motion::JointMap joint_map = {})
      : clip(clip), name(std::move(name)), joint_map(std::move(joint_map)) {}
  const motion::Motion* clip;
  std::string name;
  motion::JointMap joint_map;  // The clip's, as CallOptions::joint_map.
};

// A style change sent in a stream (live models): from input frame `frame`
// on, the style (a clip, a saved name, or neither) and/or the strength,
// cross-faded over `fade_frames` frames. Sent just before that frame.
struct StreamChange {
  int64_t frame = 0;
  Style style;
  std::optional<double> strength;
  int fade_frames = 0;
};

struct StreamResult {
  motion::Motion output;
  // Per output frame: seconds from sending its input frame to receiving it.
  std::vector<double> latency_s;
  std::vector<int64_t> indices;  // The input frame index each output carries.
};

absl::Status FromGrpcStatus(const grpc::Status& status);

// "default", "none", "feet" or "full" (what --postprocess takes);
// INVALID_ARGUMENT lists them.
absl::StatusOr<v1::PostProcess> ParsePostProcess(const std::string& name);

class LiveStream;
struct LiveStreamConfig;

class Client {
 public:
  explicit Client(const ClientOptions& options);

  // grpc.health.v1 Check of the whole server: true when SERVING (false when
  // NOT_SERVING, e.g. while it shuts down). Needs no token.
  absl::StatusOr<bool> Serving();
  absl::StatusOr<std::vector<v1::ModelInfo>> ListModels();
  absl::StatusOr<v1::ModelInfo> GetModel(const std::string& model);
  absl::StatusOr<v1::ModelInfo> LoadModel(const std::string& model);
  absl::Status UnloadModel(const std::string& model);

  absl::StatusOr<motion::Motion> Transfer(const motion::Motion& content, const Style& style,
                                          const CallOptions& options = {});
  // The style code; with `save_as`, also saved on the server under that name.
  absl::StatusOr<std::vector<float>> EncodeStyle(const motion::Motion& clip,
                                                 const std::string& save_as = "",
                                                 const CallOptions& options = {});
  // `weights`: one per style for the whole clip; or `schedule`: one row of
  // weights per content frame (used when not empty).
  absl::StatusOr<motion::Motion> Interpolate(const motion::Motion& content,
                                             const std::vector<Style>& styles,
                                             const std::vector<double>& weights,
                                             const std::vector<std::vector<double>>& schedule = {},
                                             const CallOptions& options = {});
  // Streams `content`'s frames at `rate` frames per second (0: as fast as the
  // server takes them) and collects the stylized frames as they come;
  // `changes` (in frame order) change the style on the way.
  absl::StatusOr<StreamResult> Stream(const motion::Motion& content, const Style& style,
                                      double rate, const CallOptions& options = {},
                                      const std::vector<StreamChange>& changes = {});
  // A stream the caller feeds frame by frame (client/live_stream.h): the
  // config is sent at once; an error here is the server refusing it.
  absl::StatusOr<std::unique_ptr<LiveStream>> OpenStream(
      const LiveStreamConfig& config,
      std::function<void(int64_t index, const double* values)> on_frame);
  absl::StatusOr<std::map<std::string, double>> ComputeMetrics(const motion::Motion& output,
                                                               const motion::Motion* content,
                                                               const motion::Motion* style);

 private:
  std::unique_ptr<grpc::ClientContext> Context(double deadline_scale = 1) const;
  absl::Status SetStyle(const Style& style, v1::StyleRef* out) const;

  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::ModelService::Stub> models_;
  std::unique_ptr<v1::StyleService::Stub> styles_;
};

}  // namespace stylus

#endif  // STYLUS_CLIENT_CLIENT_H_
