// Live-stage load against a real stylus-server process (docs/service.md
// "Live streams"): one client process opens N streams at R Hz for S seconds
// (gRPC callback API: the client does not wait on any stream) and reports
// the per-frame latency, from a frame's send to its stylized frame's arrival
// (p50/p99/max), frames late (over the budget) and lost, and the server's
// CPU and resident memory. It sweeps N upwards until a point misses the
// budget, for a server that batches live steps and one that does not, in the
// same run, and reports the most streams each held. Then unary throughput,
// batched and not: frames/s of Transfer calls one at a time and from
// concurrent callers, on the streams' model and on --unary-model (an offline
// model, whose windows batch across calls).
//
// usage: stream_load [--model live] [--rate 30] [--seconds 10]
//                    [--streams 1,16,64,128,256,384,512,768,1000]
//                    [--budget-ms B (default: lookahead frames + 33 ms)]
//                    [--server-bin PATH] [--server-threads 2] [--unary-calls 40]
//                    [--unary-model contrastive] [--modes batched,unbatched]
//                    [--max-queue-delay-us N (the batched server's; default its own)]
// The server runs with its defaults otherwise; OPENBLAS_CORETYPE is passed
// through from the environment when set (and then printed).
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "absl/synchronization/mutex.h"
#include "bench/bench_support.h"
#include "client/client.h"
#include "motion/bvh.h"
#include "stylus/v1/stylus.grpc.pb.h"
#include "wire/wire.h"

namespace stylus::bench {
namespace {

// One TransferStream: frames are sent when the ticker says, one write in
// flight at a time (later ones queue); every response's latency is recorded.
class LoadStream : public grpc::ClientBidiReactor<v1::StreamRequest, v1::StreamResponse> {
 public:
  LoadStream(v1::StyleService::Stub* stub, const v1::StreamRequest& config,
             const std::vector<v1::StreamRequest>* clip, int total)
      : clip_(clip), sent_(total) {
    stub->async()->TransferStream(&ctx_, this);
    Queue(config);
    StartRead(&response_);
    StartCall();
  }

  void Send(int64_t index) {
    v1::StreamRequest r = (*clip_)[index % clip_->size()];
    r.mutable_frame()->set_index(index);
    sent_[index] = Clock::now();
    Queue(std::move(r));
  }
  void Close() {
    absl::MutexLock lock(&mu_);
    closing_ = true;
    if (!writing_) StartWritesDone();
  }
  void OnWriteDone(bool ok) override {
    absl::MutexLock lock(&mu_);
    writing_ = false;
    pending_.pop_front();
    if (!ok) return;
    if (!pending_.empty()) {
      writing_ = true;
      StartWrite(&pending_.front());
    } else if (closing_) {
      StartWritesDone();
    }
  }
  void OnReadDone(bool ok) override {
    if (!ok) return;
    const int64_t i = response_.frame().index();
    latency_ms_.push_back(1000 * std::chrono::duration<double>(Clock::now() - sent_[i]).count());
    StartRead(&response_);
  }
  void OnDone(const grpc::Status& s) override {
    absl::MutexLock lock(&mu_);
    status_ = s;
    done_ = true;
  }
  // After OnDone.
  bool WaitDone(absl::Duration timeout) {
    absl::MutexLock lock(&mu_);
    return mu_.AwaitWithTimeout(absl::Condition(&done_), timeout);
  }
  const std::vector<double>& latency_ms() const { return latency_ms_; }
  grpc::Status status() {
    absl::MutexLock lock(&mu_);
    return status_;
  }
  void Cancel() { ctx_.TryCancel(); }

 private:
  void Queue(v1::StreamRequest r) {
    absl::MutexLock lock(&mu_);
    pending_.push_back(std::move(r));
    if (!writing_) {
      writing_ = true;
      StartWrite(&pending_.front());
    }
  }

  grpc::ClientContext ctx_;
  const std::vector<v1::StreamRequest>* clip_;
  std::vector<Clock::time_point> sent_;
  v1::StreamResponse response_;
  std::vector<double> latency_ms_;  // Touched by the read reactions only.
  absl::Mutex mu_;
  std::deque<v1::StreamRequest> pending_ ABSL_GUARDED_BY(mu_);
  bool writing_ ABSL_GUARDED_BY(mu_) = false;
  bool closing_ ABSL_GUARDED_BY(mu_) = false;
  bool done_ ABSL_GUARDED_BY(mu_) = false;
  grpc::Status status_ ABSL_GUARDED_BY(mu_);
};

struct Point {
  int streams = 0;
  double p50 = 0, p99 = 0, max = 0;
  int64_t sent = 0, received = 0, late = 0;
  int failed = 0;
  double cpu_cores = 0, rss_mb = 0, client_cores = 0;
  bool held = false;
};

Point RunPoint(ServerProcess* server, int n, double rate, double seconds, double budget_ms,
               const v1::StreamRequest& config, const std::vector<v1::StreamRequest>& clip) {
  // Separate connections, ~100 streams each, as a stage's machines would.
  std::vector<std::unique_ptr<v1::StyleService::Stub>> stubs;
  for (int c = 0; c * 100 < n; ++c) {
    grpc::ChannelArguments args;
    args.SetInt("stylus.bench.channel", c);  // Distinct args: a connection of its own.
    args.SetMaxReceiveMessageSize(64 << 20);
    stubs.push_back(v1::StyleService::NewStub(
        grpc::CreateCustomChannel(server->address(), grpc::InsecureChannelCredentials(), args)));
  }
  const int total = static_cast<int>(std::lround(rate * seconds));
  std::vector<std::unique_ptr<LoadStream>> streams;
  for (int i = 0; i < n; ++i) {
    streams.push_back(std::make_unique<LoadStream>(stubs[i / 100].get(), config, &clip, total));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // Configs in.
  const double cpu0 = CpuSeconds(server->pid), client0 = CpuSeconds(getpid());
  const Clock::time_point start = Clock::now();
  for (int t = 0; t < total; ++t) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(t / rate)));
    for (auto& s : streams) s->Send(t);
  }
  Point p;
  p.streams = n;
  p.cpu_cores = (CpuSeconds(server->pid) - cpu0) / Since(start);
  p.client_cores = (CpuSeconds(getpid()) - client0) / Since(start);
  p.rss_mb = RssKb(server->pid) / 1024.0;
  for (auto& s : streams) s->Close();
  std::vector<double> all;
  for (auto& s : streams) {
    if (!s->WaitDone(absl::Seconds(60))) {
      s->Cancel();
      s->WaitDone(absl::Seconds(10));
    }
    if (!s->status().ok()) ++p.failed;
    all.insert(all.end(), s->latency_ms().begin(), s->latency_ms().end());
  }
  p.sent = static_cast<int64_t>(n) * total;
  p.received = static_cast<int64_t>(all.size());
  for (double l : all) p.late += l > budget_ms;
  p.p50 = Percentile(all, 0.5);
  p.p99 = Percentile(all, 0.99);
  p.max = all.empty() ? 0 : *std::max_element(all.begin(), all.end());
  p.held = p.failed == 0 && p.received == p.sent && p.p99 <= budget_ms;
  return p;
}

void PrintPoint(const char* mode, const Point& p) {
  std::printf(
      "%-9s %5d streams: latency p50 %6.1f ms  p99 %6.1f ms  max %7.1f ms | late %lld, lost "
      "%lld of %lld, failed streams %d | server CPU %.2f cores, RSS %.0f MB (client CPU %.2f) | "
      "%s\n",
      mode, p.streams, p.p50, p.p99, p.max, static_cast<long long>(p.late),
      static_cast<long long>(p.sent - p.received), static_cast<long long>(p.sent), p.failed,
      p.cpu_cores, p.rss_mb, p.client_cores, p.held ? "held" : "NOT held");
  std::fflush(stdout);
}

int Main(int argc, char** argv) {
  std::string server_bin = std::string(STYLUS_BINARY_DIR) + "/server/stylus-server";
  std::string model = "live", unary_model = "contrastive",
              streams_arg = "1,16,64,128,256,384,512,768,1000";
  double rate = 30, seconds = 10, budget_ms = -1;
  int server_threads = 2, unary_calls = 40, queue_delay_us = -1;
  std::string modes = "batched,unbatched";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help") {
      std::printf(
          "usage: stream_load [--model live] [--rate 30] [--seconds 10]\n"
          "                   [--streams 1,16,64,128,256,384,512,768,1000]\n"
          "                   [--budget-ms B] [--server-bin PATH] [--server-threads 2]\n"
          "                   [--unary-calls 40] [--unary-model contrastive]\n"
          "                   [--modes batched,unbatched] [--max-queue-delay-us N]\n\n"
          "Opens N streams of a real clip at --rate Hz against a stylus-server it\n"
          "starts, for each N of --streams, batched and unbatched (--max-batch 0),\n"
          "and prints per-frame latency, frames late and lost, server CPU and RSS,\n"
          "and the most streams held within the budget (default: the model's\n"
          "lookahead in frames + 33 ms). Then unary Transfer throughput, one call\n"
          "at a time and from 8 callers, on --model and on --unary-model (--unary-calls 0:\n"
          "none). --modes runs one of the two servers only; --max-queue-delay-us\n"
          "is passed to the batched one.\n");
      return 0;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "stream_load: %s needs a value\n", a.c_str());
      return 2;
    }
    const char* v = argv[++i];
    bool ok = true;
    if (a == "--model")
      model = v;
    else if (a == "--rate")
      ok = absl::SimpleAtod(v, &rate) && rate > 0;
    else if (a == "--seconds")
      ok = absl::SimpleAtod(v, &seconds) && seconds > 0;
    else if (a == "--streams")
      streams_arg = v;
    else if (a == "--budget-ms")
      ok = absl::SimpleAtod(v, &budget_ms);
    else if (a == "--server-bin")
      server_bin = v;
    else if (a == "--server-threads")
      ok = absl::SimpleAtoi(v, &server_threads);
    else if (a == "--unary-model")
      unary_model = v;
    else if (a == "--unary-calls")
      ok = absl::SimpleAtoi(v, &unary_calls) && unary_calls >= 0;
    else if (a == "--modes")
      modes = v;
    else if (a == "--max-queue-delay-us")
      ok = absl::SimpleAtoi(v, &queue_delay_us) && queue_delay_us >= 0;
    else
      ok = false;
    if (!ok) {
      std::fprintf(stderr, "stream_load: bad option %s %s (see --help)\n", a.c_str(), v);
      return 2;
    }
  }
  std::vector<int> sweep;
  for (absl::string_view s : absl::StrSplit(streams_arg, ',')) {
    int n = 0;
    if (!absl::SimpleAtoi(s, &n) || n < 1) {
      std::fprintf(stderr, "stream_load: --streams takes positive counts, e.g. 1,16,64\n");
      return 2;
    }
    sweep.push_back(n);
  }
  if (const char* core = std::getenv("OPENBLAS_CORETYPE")) {
    std::printf("OPENBLAS_CORETYPE=%s (set in the environment; the server inherits it)\n", core);
  }
  const std::string models = std::string(STYLUS_SOURCE_DIR) + "/models";
  absl::StatusOr<motion::Motion> clip =
      motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/walk_normal.bvh");
  absl::StatusOr<motion::Motion> style =
      motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/walk_old.bvh");
  if (!clip.ok() || !style.ok()) {
    std::fprintf(stderr, "stream_load: cannot read the samples\n");
    return 1;
  }
  std::vector<v1::StreamRequest> frames(clip->num_frames);
  for (int f = 0; f < clip->num_frames; ++f)
    wire::FrameToProto(*clip, f, f, frames[f].mutable_frame());

  int lookahead = 0;
  std::vector<bool> runs;
  for (absl::string_view m : absl::StrSplit(modes, ',')) {
    if (m != "batched" && m != "unbatched") {
      std::fprintf(stderr, "stream_load: --modes takes batched and/or unbatched\n");
      return 2;
    }
    runs.push_back(m == "batched");
  }
  for (const bool batched : runs) {
    ServerProcess server;
    std::vector<std::string> args = {
        "--models", models, "--threads", std::to_string(server_threads), "--max-streams", "4096"};
    args.push_back(batched ? "--batch-unary" : "--max-batch");
    if (!batched) args.push_back("0");
    if (batched && queue_delay_us >= 0) {
      args.push_back("--max-queue-delay-us");
      args.push_back(std::to_string(queue_delay_us));
    }
    if (!server.Start(server_bin, args)) {
      std::fprintf(stderr, "stream_load: cannot start %s\n", server_bin.c_str());
      return 1;
    }
    ClientOptions co;
    co.address = server.address();
    Client client(co);
    absl::StatusOr<v1::ModelInfo> info = client.GetModel(model);
    absl::StatusOr<std::vector<float>> code = client.EncodeStyle(*style, "load", {model});
    if (!info.ok() || !code.ok()) {
      std::fprintf(stderr, "stream_load: %s\n",
                   (info.ok() ? code.status() : info.status()).ToString().c_str());
      return 1;
    }
    lookahead = info->lookahead();
    const double budget = budget_ms >= 0 ? budget_ms : 1000.0 * lookahead / info->fps() + 33;
    if (batched == runs.front()) {
      std::printf(
          "model %s (%s, lookahead %d frames at %.0f Hz); streams at %.0f Hz for %.0f s; "
          "budget p99 <= %.1f ms\n",
          info->id().c_str(), info->live() ? "live" : "offline", lookahead, info->fps(), rate,
          seconds, budget);
    }
    v1::StreamRequest config;
    config.mutable_config()->set_model(model);
    config.mutable_config()->mutable_style()->set_name("load");
    config.mutable_config()->set_fps(rate);
    config.mutable_config()->set_postprocess(v1::POSTPROCESS_FULL);
    wire::SkeletonToProto(clip->skeleton, config.mutable_config()->mutable_skeleton());
    int most = 0;
    for (int n : sweep) {
      const Point p = RunPoint(&server, n, rate, seconds, budget, config, frames);
      PrintPoint(batched ? "batched" : "unbatched", p);
      if (!p.held) break;
      most = n;
    }
    std::printf("%s: most streams held within %.1f ms at p99: %d\n",
                batched ? "batched" : "unbatched", budget, most);

    // Unary throughput: a 120-frame clip (saved style), one call at a time,
    // then 8 callers at once, on the streams' model and on --unary-model.
    for (const std::string& m : {model, unary_model}) {
      if (unary_calls == 0) break;
      const std::string style_name = "load-" + absl::StrReplaceAll(m, {{"/", "-"}});
      if (absl::StatusOr<std::vector<float>> c = client.EncodeStyle(*style, style_name, {m});
          !c.ok()) {
        std::fprintf(stderr, "stream_load: %s\n", c.status().ToString().c_str());
        return 1;
      }
      for (const int callers : {1, 8}) {
        std::atomic<int> failures{0};
        const Clock::time_point t0 = Clock::now();
        std::vector<std::thread> threads;
        for (int c = 0; c < callers; ++c) {
          threads.emplace_back([&, c] {
            for (int i = c; i < unary_calls; i += callers) {
              if (!client.Transfer(*clip, {nullptr, style_name}, {m}).ok()) ++failures;
            }
          });
        }
        for (auto& t : threads) t.join();
        const double secs = Since(t0);
        std::printf(
            "%-9s unary Transfer (%d frames, %s): %d caller(s): %.0f frames/s (%d calls in "
            "%.1f s, %d failed)\n",
            batched ? "batched" : "unbatched", clip->num_frames, m.c_str(), callers,
            unary_calls * clip->num_frames / secs, unary_calls, secs, failures.load());
      }
    }
    std::printf("server exit on SIGTERM: %d\n", server.Stop());
  }
  return 0;
}

}  // namespace
}  // namespace stylus::bench

int main(int argc, char** argv) { return stylus::bench::Main(argc, argv); }
