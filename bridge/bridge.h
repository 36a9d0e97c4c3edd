// stylus-bridge: a mocap stage's stream in (VMC, or BVH broadcast as Axis
// Neuron / Axis Studio send it), one Stylus TransferStream per performer,
// the stylized motion out to the engine in the same form, frame by frame. The show goes on: when a
// stream fails or the server is away, the performer's own motion passes through (or the last output
// holds) while the bridge reconnects with backoff, then the style fades back in.
#ifndef STYLUS_BRIDGE_BRIDGE_H_
#define STYLUS_BRIDGE_BRIDGE_H_

#include <lo/lo.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "bridge/bvh_broadcast.h"
#include "bridge/vmc.h"
#include "client/client.h"
#include "client/live_stream.h"

namespace stylus::bridge {

struct BridgeOptions {
  // Where VMC performers send (a Marionette's default port); live control
  // (/stylus/style, /stylus/strength) comes here too, whatever the chain.
  int vmc_in_port = 39539;
  // Where each VMC performer's stylized motion goes, "host:port", given to
  // performers in the order they first send; the last serves any further.
  std::vector<std::string> vmc_out;
  // BVH broadcast in: the capture software's text stream ("host:port",
  // TCP; the bridge connects and reconnects), and/or a UDP port for its
  // binary form. Performers are told apart by avatar name.
  std::string bvh_in;
  int bvh_in_udp = -1;
  // The stage's skeleton for BVH broadcast performers (its BVH file), and
  // its humanoid roles where its joint names don't say them.
  std::optional<motion::Skeleton> bvh_skeleton;
  motion::JointMap bvh_joint_map;
  // BVH broadcast out: a TCP port engines connect to for the text form,
  // and/or "host:port" to send the binary form to (UDP).
  int bvh_out_port = -1;
  std::string bvh_out_udp;
  ClientOptions client;
  std::string model = "live";
  std::optional<motion::Motion> style_clip;  // Or:
  std::string style_name;
  std::string style_label;  // What the console calls the starting style (the clip's path).
  v1::PostProcess postprocess = v1::POSTPROCESS_DEFAULT;
  double fps = 60;           // The performers' frame rate, as the stream's config says it.
  int fade_frames = 15;      // Back to the style after a reconnect; style changes.
  bool hold = false;         // While the stream is down: hold the last output, not pass through.
  double max_backoff_s = 0.5;  // Reconnect attempts: 50 ms doubling up to this.
  // Sources (performers) taken at most: each opens a stream on the server,
  // and any UDP sender is a source. Frames from further sources are refused.
  int max_performers = 32;
};

struct BridgeStats {
  int64_t received = 0;     // Frames from performers.
  int64_t styled = 0;       // Frames sent stylized (fading included).
  int64_t passed = 0;       // Frames sent as the performer's own (stream down).
  int64_t held = 0;         // Frames sent holding the last output (--hold).
  int64_t out_of_order = 0;  // Frames older than one already taken: dropped.
  int64_t malformed = 0;    // Messages with the wrong arguments: dropped.
  int64_t refused = 0;      // Messages from sources past --max-performers: dropped.
  int64_t engine_drops = 0;  // BVH text engines closed for not taking frames (1 MB behind).
  int64_t reconnects = 0;   // Streams opened after the first.
  int64_t stream_failures = 0;
  int performers = 0;
  // The bridge's own time per frame, in microseconds: from a frame's last
  // packet to its push on the stream (or its pass-through sent), plus from
  // the stylized frame's arrival to its packet sent. Waiting on the server
  // is not in it. p50 and p99 over the last 4096 frames.
  double added_p50_us = 0, added_p99_us = 0;
};

// "host:port" (a port 1-65535) apart; false when it is not one.
bool SplitHostPort(const std::string& host_port, std::string* host, std::string* port);

class Bridge {
 public:
  explicit Bridge(BridgeOptions options);
  ~Bridge();

  // Binds the ports and starts receiving. INVALID_ARGUMENT for a bad
  // address or a chain without an output, UNAVAILABLE when a port cannot
  // be bound.
  absl::Status Start();
  void Stop();
  int port() const { return port_; }
  int bvh_out_port() const { return bvh_out_port_; }
  int bvh_in_udp_port() const { return bvh_udp_port_; }
  BridgeStats stats() const;

  // Live control for every performer (and for streams opened later):
  // a saved style's name or a clip, the strength, each faded in.
  void ChangeStyle(const std::string& name_or_path);
  void ChangeStrength(double strength);

  // For the console (bridge/console.h): the style, strength, counters, the
  // model's saved styles, and per performer its bones with the world
  // positions of its last input and last output frame, as JSON.
  std::string StateJson();

 private:
  struct Performer;
  void ReceiveLoop();
  void OnFrame(const std::string& source, VmcFrame frame);
  void OnBroadcast(BroadcastFrame frame);
  Performer* Find(const std::string& source) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  struct Input;
  void Take(Performer* p, Input in, std::chrono::steady_clock::time_point arrived);
  void Reconnect(Performer* p);
  int64_t SendLost(Performer* p, int64_t index);
  // Sends `row` (the performer's skeleton) to the engine in the performer's
  // form, with `in`'s root transform, time and names; p->mu held.
  void Emit(Performer* p, const double* row, const Input& in);
  void SendVmc(Performer* p, const VmcFrame& frame);
  void SendBroadcast(const BroadcastFrame& frame);
  absl::Status StartBvh();
  void BvhTextLoop();
  void BvhUdpLoop();
  void BvhOutLoop();
  void ApplyChange(const StreamChange& change) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  static int OnMessage(const char* path, const char* types, lo_arg** argv, int argc, lo_message msg,
                       void* self);
  static int OnBundleStart(lo_timetag time, void* self);
  static int OnBundleEnd(void* self);

  BridgeOptions options_;
  std::unique_ptr<Client> client_;
  lo_server server_ = nullptr;
  int port_ = 0;
  std::thread receiver_;
  std::atomic<bool> stop_{false};

  // Receiver thread only: the frame being assembled per source.
  std::map<std::string, VmcFrame> pending_;
  bool in_bundle_ = false;
  std::string bundle_source_;

  // BVH broadcast: its reader threads, the engines connected for the text
  // form (each with the bytes it has not taken yet, bounded), the binary
  // form's destination.
  std::vector<std::thread> bvh_threads_;
  int bvh_udp_fd_ = -1, bvh_udp_port_ = -1, bvh_listen_fd_ = -1, bvh_out_port_ = -1;
  int bvh_send_fd_ = -1;
  std::vector<unsigned char> bvh_send_addr_;
  struct Engine {
    int fd;
    std::string unsent;
  };
  absl::Mutex out_mu_;
  std::vector<Engine> engines_ ABSL_GUARDED_BY(out_mu_);
  int64_t bvh_warnings_ ABSL_GUARDED_BY(mu_) = 0;  // Frames that fit no skeleton, logged.

  mutable absl::Mutex mu_;
  std::map<std::string, std::unique_ptr<Performer>> performers_ ABSL_GUARDED_BY(mu_);
  BridgeStats stats_ ABSL_GUARDED_BY(mu_);
  std::optional<StreamChange> last_change_ ABSL_GUARDED_BY(mu_);
  std::string style_label_ ABSL_GUARDED_BY(mu_);
  double strength_ ABSL_GUARDED_BY(mu_) = 1;
  std::unique_ptr<Client> info_client_;  // Short deadlines, for the console.
  std::vector<std::string> saved_styles_ ABSL_GUARDED_BY(mu_);
  std::chrono::steady_clock::time_point saved_styles_at_ ABSL_GUARDED_BY(mu_);
  std::vector<double> added_us_ ABSL_GUARDED_BY(mu_);  // A ring of the last 4096.
  size_t added_next_ ABSL_GUARDED_BY(mu_) = 0;
  void AddLatency(double us) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  std::vector<std::unique_ptr<motion::Motion>> change_clips_ ABSL_GUARDED_BY(mu_);
};

}  // namespace stylus::bridge

#endif  // STYLUS_BRIDGE_BRIDGE_H_
