#include "bridge/bridge.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "formats/scene_file.h"
#include "motion/kinematics.h"
#include "spdlog/spdlog.h"

namespace stylus::bridge {

using Clock = std::chrono::steady_clock;

namespace {

constexpr int kRing = 512;  // Input frames kept for fades and holds.

// Blends two rows on one skeleton: rotations by slerp, the root's position
// linearly; w = 0 gives `a`.
std::vector<double> Blend(const motion::Skeleton& sk, const double* a, const double* b, double w) {
  motion::Motion one = motion::RestMotion(sk, 2, 1.0 / 30);
  std::copy(a, a + sk.num_channels(), one.frame(0));
  std::copy(b, b + sk.num_channels(), one.frame(1));
  motion::LocalPose pa = motion::PoseAt(one, 0), pb = motion::PoseAt(one, 1);
  for (int j = 0; j < sk.num_joints(); ++j) {
    pa.rotations[j] = motion::Slerp(pa.rotations[j], pb.rotations[j], w);
    pa.translations[j] = pa.translations[j] + (pb.translations[j] - pa.translations[j]) * w;
  }
  std::vector<motion::Vec3> euler(sk.num_joints());
  motion::SetPose(&one, 0, pa, &euler);
  return std::vector<double>(one.frame(0), one.frame(0) + sk.num_channels());
}

lo_address ParseAddress(const std::string& host_port) {
  std::string host, port;
  if (!SplitHostPort(host_port, &host, &port)) return nullptr;
  return lo_address_new(host.c_str(), port.c_str());
}

}  // namespace

bool SplitHostPort(const std::string& host_port, std::string* host, std::string* port) {
  std::vector<std::string> parts = absl::StrSplit(host_port, absl::MaxSplits(':', 1));
  int n = 0;
  if (parts.size() != 2 || parts[0].empty() || !absl::SimpleAtoi(parts[1], &n) || n <= 0 ||
      n > 65535) {
    return false;
  }
  *host = parts[0];
  *port = parts[1];
  return true;
}

struct Bridge::Input {
  std::vector<double> row;  // On the performer's skeleton.
  VmcTransform root;        // VMC: the avatar's root transform.
  double time = 0;    // The sender's clock, s: /VMC/Ext/T; binary BVH: (frame index + 1) / fps.
  double in_us = 0;   // The bridge's time on it before the push.
  int64_t index = 0;  // The bridge's own index of it.
};

struct Bridge::Performer {
  std::string source;
  bool vmc = true;  // Else a BVH broadcast avatar.
  VmcSkeleton vmc_skeleton;
  motion::Skeleton skeleton;  // What streams.
  int avatar_index = 0;       // BVH: as it came.
  std::string avatar_name;
  lo_address out = nullptr;
  absl::Mutex mu;
  std::shared_ptr<LiveStream> stream;  // Pushed to outside mu.
  int64_t taken = 0;          // Input frames taken (the bridge's own index).
  int64_t stream_first = 0;   // `taken` when the current stream opened.
  bool fade_in = false;       // The current stream follows a failure: fade it in.
  std::vector<Input> ring = std::vector<Input>(kRing);
  std::vector<double> last_out;
  double last_time = -1;
  Clock::time_point next_attempt = Clock::now();
  double backoff_s = 0.05;
  bool ever_streamed = false;
  bool usable = true;  // False: no humanoid skeleton to stream; passed through.
  int64_t last_sent = -1;  // The newest input frame the engine has had.
};

Bridge::Bridge(BridgeOptions options) : options_(std::move(options)) {
  ClientOptions c = options_.client;
  if (c.max_reconnect_backoff_ms == 0) c.max_reconnect_backoff_ms = 500;
  client_ = std::make_unique<Client>(c);
  c.deadline = std::chrono::milliseconds(1000);
  info_client_ = std::make_unique<Client>(c);
  style_label_ = !options_.style_label.empty() ? options_.style_label : options_.style_name;
}

Bridge::~Bridge() { Stop(); }

absl::Status Bridge::Start() {
  const bool bvh_in = !options_.bvh_in.empty() || options_.bvh_in_udp >= 0;
  const bool bvh_out = options_.bvh_out_port >= 0 || !options_.bvh_out_udp.empty();
  if (options_.vmc_out.empty() && !bvh_in) {
    return absl::InvalidArgumentError("--vmc-out HOST:PORT is required (the engine's VMC receiver)");
  }
  if (bvh_in && !bvh_out) {
    return absl::InvalidArgumentError(
        "--bvh-in/--bvh-in-udp needs --bvh-out PORT or --bvh-out-udp HOST:PORT: BVH broadcast "
        "performers go on to the engine as BVH broadcast");
  }
  if (bvh_out && !bvh_in) {
    return absl::InvalidArgumentError(
        "--bvh-out/--bvh-out-udp needs a BVH broadcast in (--bvh-in or --bvh-in-udp)");
  }
  if (bvh_in && !options_.bvh_skeleton) {
    return absl::InvalidArgumentError(
        "--bvh-skeleton FILE is required with a BVH broadcast in: the stream sends values only "
        "(export "
        "the performer's skeleton from the capture software as a BVH file)");
  }
  if (absl::Status s = StartBvh(); !s.ok()) return s;
  for (const std::string& out : options_.vmc_out) {
    lo_address a = ParseAddress(out);
    if (a == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat("--vmc-out ", out, ": expected HOST:PORT"));
    }
    lo_address_free(a);
  }
  server_ = lo_server_new_with_proto(std::to_string(options_.vmc_in_port).c_str(), LO_UDP, nullptr);
  if (server_ == nullptr) {
    return absl::UnavailableError(
        absl::StrCat("--vmc-in ", options_.vmc_in_port, ": cannot bind the UDP port (in use?)"));
  }
  port_ = lo_server_get_port(server_);
  lo_server_add_method(server_, nullptr, nullptr, &Bridge::OnMessage, this);
  lo_server_add_bundle_handlers(server_, &Bridge::OnBundleStart, &Bridge::OnBundleEnd, this);
  receiver_ = std::thread([this] { ReceiveLoop(); });
  return absl::OkStatus();
}

void Bridge::Stop() {
  if (stop_.exchange(true)) return;
  if (receiver_.joinable()) receiver_.join();
  for (std::thread& t : bvh_threads_) t.join();
  bvh_threads_.clear();
  std::map<std::string, std::unique_ptr<Performer>> performers;
  {
    absl::MutexLock lock(&mu_);
    performers.swap(performers_);
  }
  for (auto& [source, p] : performers) {
    std::shared_ptr<LiveStream> stream;
    {
      absl::MutexLock lock(&p->mu);
      stream = std::move(p->stream);
    }
    if (stream) stream->Close().IgnoreError();  // Outside p->mu: its callback takes it.
    if (p->out) lo_address_free(p->out);
  }
  // Last: the streams' callbacks, now ended, sent on these.
  for (int* fd : {&bvh_udp_fd_, &bvh_listen_fd_, &bvh_send_fd_}) {
    if (*fd >= 0) close(*fd);
    *fd = -1;
  }
  {
    absl::MutexLock lock(&out_mu_);
    for (Engine& e : engines_) close(e.fd);
    engines_.clear();
  }
  if (server_) lo_server_free(server_);
  server_ = nullptr;
}

BridgeStats Bridge::stats() const {
  absl::MutexLock lock(&mu_);
  BridgeStats s = stats_;
  if (!added_us_.empty()) {
    std::vector<double> v = added_us_;
    std::sort(v.begin(), v.end());
    s.added_p50_us = v[v.size() / 2];
    s.added_p99_us = v[std::min(v.size() - 1, v.size() * 99 / 100)];
  }
  return s;
}

void Bridge::ReceiveLoop() {
  while (!stop_.load()) lo_server_recv_noblock(server_, 20);
}

int Bridge::OnBundleStart(lo_timetag, void* self) {
  static_cast<Bridge*>(self)->in_bundle_ = true;
  return 0;
}

int Bridge::OnBundleEnd(void* self) {
  Bridge* b = static_cast<Bridge*>(self);
  b->in_bundle_ = false;
  auto it = b->pending_.find(b->bundle_source_);
  if (it != b->pending_.end() && !it->second.bones.empty()) {
    VmcFrame frame = std::move(it->second);
    b->pending_.erase(it);
    b->OnFrame(b->bundle_source_, std::move(frame));
  }
  return 0;
}

int Bridge::OnMessage(const char* path, const char* types, lo_arg** argv, int argc, lo_message msg,
                      void* self) {
  Bridge* b = static_cast<Bridge*>(self);
  lo_address from = lo_message_get_source(msg);
  const std::string source = from == nullptr ? "?"
                                             : absl::StrCat(lo_address_get_hostname(from), ":",
                                                            lo_address_get_port(from));
  auto malformed = [&] {
    absl::MutexLock lock(&b->mu_);
    ++b->stats_.malformed;
    return 0;
  };
  auto floats = [&](int from_arg, int n, float* out) {
    for (int i = 0; i < n; ++i) {
      const char t = types[from_arg + i];
      if (t == 'f') {
        out[i] = argv[from_arg + i]->f;
      } else if (t == 'd') {
        out[i] = static_cast<float>(argv[from_arg + i]->d);
      } else {
        return false;
      }
    }
    return true;
  };
  const std::string p = path;
  if (p == "/stylus/style" && argc == 1 && types[0] == 's') {
    b->ChangeStyle(&argv[0]->s);
    return 0;
  }
  if (p == "/stylus/strength" && argc == 1 && (types[0] == 'f' || types[0] == 'd')) {
    b->ChangeStrength(types[0] == 'f' ? argv[0]->f : argv[0]->d);
    return 0;
  }
  // A source is taken only while there is room: frames being assembled and
  // performers together stay within max_performers.
  if (!b->pending_.count(source)) {
    absl::MutexLock lock(&b->mu_);
    if (!b->performers_.count(source) &&
        static_cast<int>(b->performers_.size() + b->pending_.size()) >= b->options_.max_performers) {
      ++b->stats_.refused;
      return 0;
    }
  }
  if (b->options_.vmc_out.empty()) {  // A BVH broadcast chain: VMC performers have nowhere to go.
    absl::MutexLock lock(&b->mu_);
    ++b->stats_.refused;
    return 0;
  }
  b->bundle_source_ = source;
  if (p == "/VMC/Ext/Root/Pos" || p == "/VMC/Ext/Bone/Pos") {
    float pq[7];
    if (argc < 8 || types[0] != 's' || !floats(1, 7, pq)) return malformed();
    const VmcTransform t = FromUnity(pq, pq + 3);
    VmcFrame& frame = b->pending_[source];
    if (p == "/VMC/Ext/Root/Pos") {
      // Outside bundles, a root after bones starts the next frame.
      if (!b->in_bundle_ && !frame.bones.empty()) {
        VmcFrame done = std::move(frame);
        b->pending_.erase(source);
        b->OnFrame(source, std::move(done));
      }
      b->pending_[source].root = t;
    } else if (IsUnityBone(&argv[0]->s)) {
      frame.bones[&argv[0]->s] = t;
    }
  } else if (p == "/VMC/Ext/T") {
    float t;
    if (argc < 1 || !floats(0, 1, &t)) return malformed();
    VmcFrame& frame = b->pending_[source];
    frame.time = t;
    // Outside bundles, the time closes a frame.
    if (!b->in_bundle_ && !frame.bones.empty()) {
      VmcFrame done = std::move(frame);
      b->pending_.erase(source);
      b->OnFrame(source, std::move(done));
    }
  }
  return 0;  // Other VMC messages (/VMC/Ext/OK, blend shapes, ...) are not needed.
}

// The performer `source`, or a new one when there is room (nullptr: refused).
Bridge::Performer* Bridge::Find(const std::string& source) {
  auto it = performers_.find(source);
  if (it != performers_.end()) return it->second.get();
  if (static_cast<int>(performers_.size()) >= options_.max_performers) {
    ++stats_.refused;
    return nullptr;
  }
  auto performer = std::make_unique<Performer>();
  performer->source = source;
  Performer* p = performer.get();
  performers_.emplace(source, std::move(performer));
  stats_.performers = static_cast<int>(performers_.size());
  return p;
}

void Bridge::OnFrame(const std::string& source, VmcFrame frame) {
  const Clock::time_point arrived = Clock::now();
  Performer* p;
  {
    absl::MutexLock lock(&mu_);
    const bool known = performers_.count(source) > 0;
    p = Find(source);
    if (p == nullptr) return;
    ++stats_.received;
    if (!known) {
      const size_t k = std::min(performers_.size() - 1, options_.vmc_out.size() - 1);
      absl::StatusOr<VmcSkeleton> skeleton = VmcSkeleton::FromFrame(frame);
      p->out = ParseAddress(options_.vmc_out[k]);
      if (skeleton.ok()) {
        p->vmc_skeleton = *std::move(skeleton);
        p->skeleton = p->vmc_skeleton.skeleton();
        spdlog::info("performer {}: {} bones, out to {}", source, p->skeleton.num_joints(),
                     options_.vmc_out[k]);
      } else {
        // The show goes on: its frames pass through, unstyled.
        p->usable = false;
        spdlog::warn("performer {}: {}; passing it through unstyled", source,
                     std::string(skeleton.status().message()));
      }
    }
  }
  if (!p->usable) {
    {
      absl::MutexLock lock(&p->mu);
      SendVmc(p, frame);
    }
    absl::MutexLock lock(&mu_);
    ++stats_.passed;
    return;
  }
  Input in;
  in.row = p->vmc_skeleton.Row(frame);
  in.root = frame.root;
  in.time = frame.time;
  Take(p, std::move(in), arrived);
}

void Bridge::OnBroadcast(BroadcastFrame frame) {
  const Clock::time_point arrived = Clock::now();
  const std::string source = "bvh " + frame.avatar_name;
  absl::StatusOr<std::vector<double>> row = BroadcastRow(*options_.bvh_skeleton, frame.values);
  Performer* p;
  {
    absl::MutexLock lock(&mu_);
    if (!row.ok()) {
      ++stats_.malformed;
      // Logged for the first few and then every thousandth: the names and
      // counts are the sender's, the log's size is not.
      if (bvh_warnings_++ % 1000 < 3) {
        spdlog::warn("BVH broadcast, avatar {} '{}': {}", frame.avatar_index, frame.avatar_name,
                     std::string(row.status().message()));
      }
      return;
    }
    const bool known = performers_.count(source) > 0;
    p = Find(source);
    if (p == nullptr) return;
    ++stats_.received;
    if (!known) {
      p->vmc = false;
      p->skeleton = *options_.bvh_skeleton;
      p->avatar_index = frame.avatar_index;
      p->avatar_name = frame.avatar_name;
      spdlog::info("performer {} (avatar {}): {} joints", source, frame.avatar_index,
                   p->skeleton.num_joints());
    }
  }
  Input in;
  in.row = *std::move(row);
  // The binary form's frame index as a clock (seconds, from 1/fps: 0 is
  // "no clock"), for the order of frames over UDP.
  in.time =
      frame.frame_index >= 0 ? (static_cast<double>(frame.frame_index) + 1) / options_.fps : 0;
  Take(p, std::move(in), arrived);
}

// One input frame of a performer: pushed on its stream, or (the stream
// down) sent on as it came or holding the last output.
void Bridge::Take(Performer* p, Input input, Clock::time_point arrived) {
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::micro>(Clock::now() - t).count();
  };
  std::shared_ptr<LiveStream> dead, push_to;
  std::vector<double> push_row;
  int64_t push_index = 0, index = 0;
  bool passed = false, held = false;
  int64_t passed_late = 0;
  double direct_us = -1;
  {
    absl::MutexLock lock(&p->mu);
    // Older than a frame already taken: reordered on the way, dropped. Over
    // a second older: the sender's clock started again (it restarted).
    if (input.time > 0 && input.time < p->last_time && input.time > p->last_time - 1.0) {
      absl::MutexLock s(&mu_);  // Lock order: a performer's, then the bridge's.
      ++stats_.out_of_order;
      return;
    }
    p->last_time = input.time > 0 && input.time < p->last_time ? input.time
                                                               : std::max(p->last_time, input.time);
    index = p->taken++;
    Input& in = p->ring[index % kRing];
    in = std::move(input);
    in.index = index;
    if (p->stream && !p->stream->alive()) {
      dead = std::move(p->stream);
      p->next_attempt = Clock::now();
      p->backoff_s = 0.05;
      passed_late += SendLost(p, index);
    }
    if (!p->stream && Clock::now() >= p->next_attempt) Reconnect(p);
    if (p->stream && p->stream->alive()) {
      // Pushed below, outside the lock: its stylized frame comes back on
      // the stream's thread meanwhile.
      push_to = p->stream;
      push_row = in.row;
      push_index = index - p->stream_first;
    } else if (options_.hold && !p->last_out.empty()) {
      Emit(p, p->last_out.data(), in);
      p->last_sent = index;
      held = true;
    } else {
      Emit(p, in.row.data(), in);
      p->last_sent = index;
      passed = true;
    }
    if (passed || held) direct_us = since(arrived);
  }
  if (push_to) {
    const bool pushed = push_to->Push(push_row.data(), push_index);
    // The push's own time counts (the write to the server's socket).
    const double in_us = since(arrived);
    absl::MutexLock lock(&p->mu);
    Input& in = p->ring[index % kRing];
    in.in_us = in_us;
    if (!pushed) {  // The stream ended just now: this frame goes as it came.
      passed_late += SendLost(p, index);
      Emit(p, in.row.data(), in);
      p->last_sent = std::max(p->last_sent, index);
      passed = true;
    }
  }
  if (dead) {
    const absl::Status s = dead->Close();
    spdlog::warn("performer {}: stream ended ({}); passing the performer through and reconnecting",
                 p->source, s.ToString());
    absl::MutexLock lock(&mu_);
    ++stats_.stream_failures;
  }
  absl::MutexLock lock(&mu_);
  stats_.passed += passed + passed_late;
  stats_.held += held;
  if (direct_us >= 0) AddLatency(direct_us);
}

void Bridge::AddLatency(double us) {
  constexpr size_t kKept = 4096;
  if (added_us_.size() < kKept) {
    added_us_.push_back(us);
  } else {
    added_us_[added_next_] = us;
  }
  added_next_ = (added_next_ + 1) % kKept;
}

// The frames before `index` a failed stream took but never returned (its
// look-ahead) go out as they came in, so the engine misses none; p->mu
// held. Returns how many.
int64_t Bridge::SendLost(Performer* p, int64_t index) {
  int64_t sent = 0;
  for (int64_t i = std::max(p->last_sent + 1, index - kRing + 1); i < index; ++i) {
    const Input& lost = p->ring[i % kRing];
    Emit(p, lost.row.data(), lost);
    p->last_sent = i;
    ++sent;
  }
  return sent;
}

// Opens the performer's stream (p->mu held). On failure the next attempt
// waits twice as long, up to max_backoff_s.
void Bridge::Reconnect(Performer* p) {
  LiveStreamConfig config;
  config.model = options_.model;
  config.skeleton = p->skeleton;
  config.fps = options_.fps;
  config.postprocess = options_.postprocess;
  if (!p->vmc) config.joint_map = options_.bvh_joint_map;
  std::optional<StreamChange> change;
  {
    absl::MutexLock lock(&mu_);
    change = last_change_;
  }
  if (options_.style_clip) {
    config.style.clip = &*options_.style_clip;
  } else {
    config.style.name = options_.style_name;
  }
  if (change && (change->style.clip != nullptr || !change->style.name.empty())) {
    config.style = change->style;
  }
  const int64_t first = p->taken - 1;
  auto on_frame = [this, p, first](int64_t local, const double* values) {
    const Clock::time_point arrived = Clock::now();
    absl::MutexLock lock(&p->mu);
    const int64_t index = first + local;
    if (index < 0 || index >= p->taken || p->taken - index > kRing || index <= p->last_sent) return;
    const Input& in = p->ring[index % kRing];
    std::vector<double> row(values, values + p->skeleton.num_channels());
    if (p->fade_in && local < options_.fade_frames) {
      row = Blend(p->skeleton, in.row.data(), row.data(),
                  static_cast<double>(local + 1) / (options_.fade_frames + 1));
    }
    p->last_out = row;
    Emit(p, row.data(), in);
    p->last_sent = index;
    const double us =
        in.in_us + std::chrono::duration<double, std::micro>(Clock::now() - arrived).count();
    absl::MutexLock s(&mu_);
    ++stats_.styled;
    AddLatency(us);
  };
  absl::StatusOr<std::unique_ptr<LiveStream>> stream = client_->OpenStream(config, on_frame);
  if (!stream.ok()) {
    p->next_attempt = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(p->backoff_s));
    p->backoff_s = std::min(options_.max_backoff_s, p->backoff_s * 2);
    return;
  }
  p->stream = *std::move(stream);
  p->stream_first = first;
  p->fade_in = p->ever_streamed;
  if (p->ever_streamed) {
    absl::MutexLock lock(&mu_);
    ++stats_.reconnects;
  }
  p->ever_streamed = true;
  if (change && change->strength) {
    StreamChange strength = *change;
    strength.style = Style();
    strength.frame = 0;
    strength.fade_frames = 0;
    p->stream->Change(strength);
  }
}

void Bridge::Emit(Performer* p, const double* row, const Input& in) {
  if (p->vmc) {
    VmcFrame out = p->vmc_skeleton.FrameOf(row, in.root);
    out.time = in.time;  // The engine sees the capture's clock.
    SendVmc(p, out);
    return;
  }
  BroadcastFrame out;
  out.avatar_index = p->avatar_index;
  out.avatar_name = p->avatar_name;
  out.values.assign(row, row + p->skeleton.num_channels());
  out.frame_index = in.time > 0 ? std::llround(in.time * options_.fps) - 1 : in.index;
  SendBroadcast(out);
}

// One VMC frame as one bundle: the root, every bone, then OK and the time.
void Bridge::SendVmc(Performer* p, const VmcFrame& frame) {
  lo_bundle bundle = lo_bundle_new(LO_TT_IMMEDIATE);
  float pq[7];
  lo_message root = lo_message_new();
  ToUnity(frame.root, pq, pq + 3);
  lo_message_add_string(root, "root");
  for (float v : pq) lo_message_add_float(root, v);
  lo_bundle_add_message(bundle, "/VMC/Ext/Root/Pos", root);
  for (const auto& [name, t] : frame.bones) {
    lo_message m = lo_message_new();
    ToUnity(t, pq, pq + 3);
    lo_message_add_string(m, name.c_str());
    for (float v : pq) lo_message_add_float(m, v);
    lo_bundle_add_message(bundle, "/VMC/Ext/Bone/Pos", m);
  }
  lo_message ok = lo_message_new();
  lo_message_add_int32(ok, 1);
  lo_bundle_add_message(bundle, "/VMC/Ext/OK", ok);
  lo_message time = lo_message_new();
  lo_message_add_float(time, static_cast<float>(frame.time));
  lo_bundle_add_message(bundle, "/VMC/Ext/T", time);
  lo_send_bundle(p->out, bundle);
  lo_bundle_free_recursive(bundle);
}

void Bridge::ChangeStyle(const std::string& name_or_path) {
  StreamChange change;
  change.fade_frames = options_.fade_frames;
  absl::MutexLock lock(&mu_);
  if (formats::FormatOfPath(name_or_path).ok()) {
    absl::StatusOr<motion::Motion> clip = formats::ReadMotionFile(name_or_path);
    if (!clip.ok()) {
      spdlog::warn("style {}: {}", name_or_path, std::string(clip.status().message()));
      return;
    }
    change_clips_.push_back(std::make_unique<motion::Motion>(*std::move(clip)));
    change.style.clip = change_clips_.back().get();
  } else {
    change.style.name = name_or_path;
  }
  if (last_change_) change.strength = last_change_->strength;
  last_change_ = change;
  style_label_ = name_or_path;
  ApplyChange(change);
  spdlog::info("style -> {}", name_or_path);
}

void Bridge::ChangeStrength(double strength) {
  StreamChange change;
  change.fade_frames = options_.fade_frames;
  change.strength = std::clamp(strength, 0.0, 1.0);
  absl::MutexLock lock(&mu_);
  StreamChange kept = last_change_.value_or(StreamChange{});
  kept.strength = change.strength;
  last_change_ = kept;
  strength_ = *change.strength;
  ApplyChange(change);
  spdlog::info("strength -> {}", *change.strength);
}

// Sends `change` on every performer's stream from its next frame. Called
// with mu_ held: takes each performer's lock after releasing it (a
// performer's lock comes before the bridge's).
void Bridge::ApplyChange(const StreamChange& change) {
  std::vector<Performer*> all;
  for (auto& [source, p] : performers_) all.push_back(p.get());
  mu_.Unlock();
  for (Performer* p : all) {
    absl::MutexLock pl(&p->mu);
    StreamChange c = change;
    c.frame = p->taken - p->stream_first;
    if (p->stream) p->stream->Change(c);
  }
  mu_.Lock();
}

namespace {

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      absl::StrAppend(&out, absl::StrFormat("\\u%04x", c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string JsonPositions(const motion::Skeleton& sk, const std::vector<double>& row) {
  if (row.empty()) return "[]";
  motion::Motion one = motion::RestMotion(sk, 1, 1.0 / 30);
  std::copy(row.begin(), row.end(), one.values.begin());
  const std::vector<motion::Vec3> p = motion::GlobalPositions(one)[0];
  std::string out = "[";
  for (size_t j = 0; j < p.size(); ++j) {
    absl::StrAppendFormat(&out, "%s[%.4f,%.4f,%.4f]", j ? "," : "", p[j].x, p[j].y, p[j].z);
  }
  return out + "]";
}

}  // namespace

std::string Bridge::StateJson() {
  bool refresh;
  {
    absl::MutexLock lock(&mu_);
    refresh = Clock::now() - saved_styles_at_ >= std::chrono::seconds(5);
    if (refresh) saved_styles_at_ = Clock::now();
  }
  if (refresh) {  // The model's saved styles, asked again every 5 s at most.
    absl::StatusOr<v1::ModelInfo> info = info_client_->GetModel(options_.model);
    absl::MutexLock lock(&mu_);
    if (info.ok()) saved_styles_.assign(info->saved_styles().begin(), info->saved_styles().end());
  }
  const BridgeStats st = stats();
  std::vector<Performer*> all;
  std::string out;
  {
    absl::MutexLock lock(&mu_);
    absl::StrAppendFormat(&out, "{\"model\":%s,\"style\":%s,\"strength\":%.3f,\"saved_styles\":[",
                          JsonString(options_.model), JsonString(style_label_), strength_);
    for (size_t i = 0; i < saved_styles_.size(); ++i) {
      absl::StrAppend(&out, i ? "," : "", JsonString(saved_styles_[i]));
    }
    for (auto& [source, p] : performers_) all.push_back(p.get());
  }
  absl::StrAppendFormat(&out,
                        "],\"stats\":{\"received\":%d,\"styled\":%d,\"passed\":%d,\"held\":%d,"
                        "\"out_of_order\":%d,\"malformed\":%d,\"stream_failures\":%d,"
                        "\"reconnects\":%d,\"added_us_p50\":%.0f,\"added_us_p99\":%.0f},"
                        "\"performers\":[",
                        st.received, st.styled, st.passed, st.held, st.out_of_order, st.malformed,
                        st.stream_failures, st.reconnects, st.added_p50_us, st.added_p99_us);
  bool first = true;
  for (Performer* p : all) {
    absl::MutexLock lock(&p->mu);
    if (!p->usable || p->taken == 0) continue;
    const motion::Skeleton& sk = p->skeleton;
    absl::StrAppend(&out, first ? "" : ",", "{\"source\":", JsonString(p->source),
                    ",\"streaming\":", p->stream && p->stream->alive() ? "true" : "false",
                    ",\"parents\":[");
    first = false;
    for (int j = 0; j < sk.num_joints(); ++j)
      absl::StrAppend(&out, j ? "," : "", sk.joint(j).parent);
    absl::StrAppend(&out, "],\"input\":", JsonPositions(sk, p->ring[(p->taken - 1) % kRing].row),
                    ",\"output\":", JsonPositions(sk, p->last_out), "}");
  }
  return out + "]}";
}

}  // namespace stylus::bridge
