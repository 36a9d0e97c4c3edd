// Soak: mixed traffic against a real stylus-server process for a set time,
// watching its memory, file descriptors and threads (docs/service.md
// "Soak and drain").
//
// Traffic, all at once:
//  - streams: --streams clients, each opening streams one after another on
//    the live model or `contrastive` (alternating), sending 30-300 frames of
//    a real clip at --rate Hz, and either half-closing or cutting the call
//    (a third of them) part-way;
//  - unary: --unary-clients clients calling Transfer, Interpolate,
//    EncodeStyle (saved names from a small set) and ComputeMetrics;
//  - bad input: bytes that are no request, clips on another skeleton, an
//    unknown model, every few seconds;
//  - models: cyclic/v1 unloaded and loaded again every 10 s (admin token);
//  - with --hostile N: N clients replaying hostile probes one after another
//    (bench/hostile's): a 16 MiB request without a token, one of empty
//    frames and one of empty rotations with a token, 300 000 style names,
//    a stream that never reads, 100 000 style changes far ahead, a request
//    with a 1 MiB model id.
// Every call but the hostile ones carries a token (the server runs with
// --auth-tokens and --admin-tokens). The streams' frame latency (a frame
// sent to its stylized frame back) is reported as percentiles.
// Prints, every --report-s: requests, errors by code, RSS, fds, threads;
// at the end the same against the figures right after --warmup-s.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <sys/types.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/synchronization/mutex.h"
#include "bench/bench_support.h"
#include "client/client.h"
#include "motion/bvh.h"
#include "wire/wire.h"

namespace stylus::bench {
namespace {

struct Tally {
  absl::Mutex mu;
  std::map<std::string, int64_t> by_code ABSL_GUARDED_BY(mu);  // "OK", "INVALID_ARGUMENT", ...
  std::atomic<int64_t> frames_out{0};
  std::atomic<int64_t> hostile{0};
  std::vector<double> latency_ms ABSL_GUARDED_BY(mu);  // Of stream frames, after the warm-up.
  std::atomic<bool> record{false};
  std::atomic<int64_t> streams{0};
  std::atomic<int64_t> unary{0};

  void Count(grpc::StatusCode code) {
    absl::MutexLock lock(&mu);
    ++by_code[absl::StatusCodeToString(static_cast<absl::StatusCode>(code))];
  }
  void Count(const absl::Status& s) { Count(static_cast<grpc::StatusCode>(s.code())); }
  std::string Codes() {
    absl::MutexLock lock(&mu);
    std::string out;
    for (const auto& [code, n] : by_code) out += " " + code + "=" + std::to_string(n);
    return out;
  }
};

struct ProcessFigures {
  long rss_kb = 0;
  int fds = 0;
  int threads = 0;
};

ProcessFigures Measure(pid_t pid) {
  ProcessFigures f;
  f.rss_kb = RssKb(pid);
  const std::string proc = "/proc/" + std::to_string(pid);
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(proc + "/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++f.fds;
  }
  for (auto it = std::filesystem::directory_iterator(proc + "/task", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++f.threads;
  }
  return f;
}

constexpr char kToken[] = "soak-serving-token";
constexpr char kAdminToken[] = "soak-admin-token";

struct Soak {
  std::string address;
  motion::Motion walk, old, run;
  double rate = 30;
  std::atomic<bool> stop{false};
  Tally tally;

  // A stream's first message: `model`, the walk's skeleton, the old walk's style.
  v1::StreamRequest Config(const std::string& model) const {
    v1::StreamRequest config;
    config.mutable_config()->set_model(model);
    config.mutable_config()->set_fps(walk.fps());
    wire::SkeletonToProto(walk.skeleton, config.mutable_config()->mutable_skeleton());
    wire::ClipToProto(old, config.mutable_config()->mutable_style()->mutable_clip());
    return config;
  }

  // One stream: `frames` frames at `rate`, cut after `cut_at` frames when >= 0.
  void OneStream(v1::StyleService::Stub* stub, const std::string& model, int frames, int cut_at) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
    auto stream = stub->TransferStream(&ctx);
    std::vector<std::atomic<int64_t>> sent_ns(frames);
    std::thread writer([&] {
      if (!stream->Write(Config(model))) return;
      const auto start = Clock::now();
      for (int f = 0; f < frames; ++f) {
        if (f == cut_at || stop) {
          ctx.TryCancel();
          return;
        }
        std::this_thread::sleep_until(
            start + std::chrono::microseconds(static_cast<int64_t>(f * 1e6 / rate)));
        v1::StreamRequest r;
        wire::FrameToProto(walk, f % walk.num_frames, f, r.mutable_frame());
        sent_ns[f] = Clock::now().time_since_epoch().count();
        if (!stream->Write(r)) return;
      }
      stream->WritesDone();
    });
    v1::StreamResponse response;
    std::vector<double> latencies;
    while (stream->Read(&response)) {
      ++tally.frames_out;
      const int64_t i = response.frame().index();
      if (i >= 0 && i < frames && sent_ns[i] > 0) {
        latencies.push_back((Clock::now().time_since_epoch().count() - sent_ns[i]) / 1e6);
      }
    }
    if (tally.record) {
      absl::MutexLock lock(&tally.mu);
      tally.latency_ms.insert(tally.latency_ms.end(), latencies.begin(), latencies.end());
    }
    writer.join();
    tally.Count(stream->Finish().error_code());
    ++tally.streams;
  }

  void StreamClient(int id) {
    auto stub =
        v1::StyleService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
    std::mt19937 rng(id);
    for (int n = 0; !stop; ++n) {
      const int frames = 30 + static_cast<int>(rng() % 271);
      const int cut_at = rng() % 3 == 0 ? static_cast<int>(rng() % frames) : -1;
      OneStream(stub.get(), (id + n) % 2 == 0 ? "live" : "contrastive", frames, cut_at);
    }
  }

  void UnaryClient(int id) {
    ClientOptions options;
    options.address = address;
    options.token = kToken;
    Client client(options);
    std::mt19937 rng(1000 + id);
    const std::vector<std::string> models = {"contrastive", "cyclic/v2", "live"};
    for (int n = 0; !stop; ++n) {
      CallOptions call;
      call.model = models[n % models.size()];
      absl::Status s;
      switch (n % 4) {
        case 0:
          s = client.Transfer(walk, {&old, ""}, call).status();
          break;
        case 1:
          s = client.Interpolate(walk, {{&old, ""}, {&run, ""}}, {0.5, 0.5}, {}, call).status();
          break;
        case 2:
          s = client.EncodeStyle(old, "soak-" + std::to_string(rng() % 8), call).status();
          break;
        default:
          s = client.ComputeMetrics(walk, &walk, &old).status();
      }
      tally.Count(s);
      ++tally.unary;
    }
  }

  // Bad input and model reloads, a few times a second.
  void Troublemaker() {
    ClientOptions options;
    options.address = address;
    options.token = kToken;
    Client client(options);
    options.token = kAdminToken;
    Client admin(options);
    auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
    grpc::GenericStub generic(channel);
    std::mt19937 rng(7);
    motion::Motion other_rig = walk;
    other_rig.skeleton = run.skeleton;  // Keeps frames; the server checks the skeleton.
    auto last_reload = Clock::now();
    for (int n = 0; !stop; ++n) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      switch (n % 3) {
        case 0: {  // Bytes that are no request.
          std::string bytes(1 + rng() % 300, '\0');
          for (char& c : bytes) c = static_cast<char>(rng());
          tally.Count(Raw(&generic, "/stylus.v1.StyleService/Transfer", bytes, kToken));
          break;
        }
        case 1: {
          CallOptions call;
          call.model = "no-such/model";
          tally.Count(client.Transfer(walk, {&old, ""}, call).status());
          break;
        }
        default:
          tally.Count(client.Transfer(other_rig, {&old, ""}).status());
      }
      ++tally.unary;
      if (Since(last_reload) > 10) {
        tally.Count(admin.UnloadModel("cyclic/v1"));
        tally.Count(admin.LoadModel("cyclic/v1").status());
        tally.unary += 2;
        last_reload = Clock::now();
      }
    }
  }

  // One unary call of raw bytes; its status code.
  grpc::StatusCode Raw(grpc::GenericStub* stub, const std::string& method, const std::string& bytes,
                       const char* token) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    if (token != nullptr) ctx.AddMetadata("authorization", std::string("Bearer ") + token);
    grpc::Slice slice(bytes);
    grpc::ByteBuffer request(&slice, 1), response;
    grpc::CompletionQueue cq;
    auto call = stub->PrepareUnaryCall(&ctx, method, request, &cq);
    call->StartCall();
    grpc::Status status;
    call->Finish(&response, &status, nullptr);
    void* tag;
    bool ok;
    cq.Next(&tag, &ok);
    return status.error_code();
  }

  // Hostile probes, one after another, until the end.
  void HostileClient(int id) {
    auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
    grpc::GenericStub generic(channel);
    auto stub = v1::StyleService::NewStub(channel);
    std::string empty_frames;
    for (int i = 0; i < 8 * 1024 * 1024 - 16; ++i) empty_frames.append("\x12\x00", 2);
    const std::string big = WireField(2, empty_frames);
    empty_frames.clear();
    empty_frames.shrink_to_fit();
    std::string frame, clip;
    for (int j = 0; j < 22; ++j) frame += WireField(4, "");
    for (int f = 0; f < 30000; ++f) clip += WireField(2, frame);
    const std::string empty_rotations = WireField(2, clip);
    std::string names;
    for (int i = 0; i < 300000; ++i) names += WireField(3, WireField(2, "a"));
    const std::string long_id = WireField(1, std::string(1 << 20, 'x'));
    struct RawProbe {
      const char* method;
      const std::string* bytes;
      const char* token;
    };
    const std::vector<RawProbe> raw = {
        {"/stylus.v1.StyleService/Transfer", &big, nullptr},
        {"/stylus.v1.StyleService/Transfer", &big, kToken},
        {"/stylus.v1.StyleService/Transfer", &empty_rotations, kToken},
        {"/stylus.v1.StyleService/Interpolate", &names, kToken},
        {"/stylus.v1.ModelService/GetModel", &long_id, kToken},
    };
    const int kinds = static_cast<int>(raw.size()) + 2;
    for (int n = id; !stop; ++n) {
      grpc::StatusCode code = grpc::OK;
      const int k = n % kinds;
      switch (k < static_cast<int>(raw.size()) ? -1 : k - static_cast<int>(raw.size())) {
        case -1:
          code = Raw(&generic, raw[k].method, *raw[k].bytes, raw[k].token);
          break;
        case 0: {  // A stream that never reads, for 5 s.
          grpc::ChannelArguments args;
          args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
          args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 65536);
          auto own = v1::StyleService::NewStub(
              grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args));
          grpc::ClientContext ctx;
          ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
          auto stream = own->TransferStream(&ctx);
          const v1::StreamRequest config = Config("live");
          std::thread writer([&] {
            if (!stream->Write(config)) return;
            for (int f = 0; f < 100000 && !stop; ++f) {
              v1::StreamRequest r;
              wire::FrameToProto(walk, f % walk.num_frames, f, r.mutable_frame());
              if (!stream->Write(r)) return;
            }
          });
          for (int i = 0; i < 50 && !stop; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
          ctx.TryCancel();
          writer.join();
          code = stream->Finish().error_code();
          break;
        }
        default: {  // 100 000 style changes far ahead.
          grpc::ClientContext ctx;
          ctx.AddMetadata("authorization", std::string("Bearer ") + kToken);
          auto stream = stub->TransferStream(&ctx);
          const v1::StreamRequest config = Config("live");
          if (stream->Write(config)) {
            for (int i = 0; i < 100000 && !stop; ++i) {
              v1::StreamRequest c;
              c.mutable_change()->set_from_frame(50000 + i);
              c.mutable_change()->set_strength(0.5);
              if (!stream->Write(c)) break;
            }
            stream->WritesDone();
          }
          v1::StreamResponse response;
          while (stream->Read(&response)) {
          }
          code = stream->Finish().error_code();
        }
      }
      tally.Count(code);
      ++tally.hostile;
    }
  }
};

void Print(const char* when, double t, const ProcessFigures& f, Soak& soak) {
  std::printf(
      "%-6s t=%6.0f s  rss %7.1f MB  fds %4d  threads %4d  streams %lld  unary %lld  "
      "hostile %lld  frames out %lld  codes:%s\n",
      when, t, f.rss_kb / 1024.0, f.fds, f.threads,
      static_cast<long long>(soak.tally.streams.load()),
      static_cast<long long>(soak.tally.unary.load()),
      static_cast<long long>(soak.tally.hostile.load()),
      static_cast<long long>(soak.tally.frames_out.load()), soak.tally.Codes().c_str());
  std::fflush(stdout);
}

int Main(int argc, char** argv) {
  std::string server_bin = std::string(STYLUS_BINARY_DIR) + "/server/stylus-server";
  double seconds = 1800, warmup_s = 300, report_s = 60, rate = 30;
  int streams = 50, unary_clients = 2, hostile = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf(
          "usage: soak [--seconds 1800] [--warmup-s 300] [--report-s 60] [--streams 50]\n"
          "            [--unary-clients 2] [--rate 30] [--hostile 0] [--server-bin PATH]\n\n"
          "Drives a stylus-server it starts with mixed traffic (streams opened\n"
          "and cut, unary calls, bad input, model unload/load) for --seconds and\n"
          "prints requests, errors by code, RSS, open fds and threads; at the end\n"
          "the growth after --warmup-s against the targets (RSS < 5%%, no fd or\n"
          "thread growth), and the streams' frame latency. --hostile N adds N\n"
          "clients replaying hostile probes. Exit 1 if the server died or a target\n"
          "was missed.\n");
      return 0;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "soak: %s needs a value\n", a.c_str());
      return 2;
    }
    const char* v = argv[++i];
    bool ok = true;
    if (a == "--seconds")
      ok = absl::SimpleAtod(v, &seconds) && seconds > 0;
    else if (a == "--warmup-s")
      ok = absl::SimpleAtod(v, &warmup_s) && warmup_s >= 0;
    else if (a == "--report-s")
      ok = absl::SimpleAtod(v, &report_s) && report_s > 0;
    else if (a == "--rate")
      ok = absl::SimpleAtod(v, &rate) && rate > 0;
    else if (a == "--streams")
      ok = absl::SimpleAtoi(v, &streams) && streams >= 0;
    else if (a == "--unary-clients")
      ok = absl::SimpleAtoi(v, &unary_clients) && unary_clients >= 0;
    else if (a == "--hostile")
      ok = absl::SimpleAtoi(v, &hostile) && hostile >= 0;
    else if (a == "--server-bin")
      server_bin = v;
    else
      ok = false;
    if (!ok) {
      std::fprintf(stderr, "soak: bad option %s %s (see --help)\n", a.c_str(), v);
      return 2;
    }
  }
  if (warmup_s >= seconds) {
    std::fprintf(stderr, "soak: --warmup-s must be shorter than --seconds\n");
    return 2;
  }
  if (const char* core = std::getenv("OPENBLAS_CORETYPE")) {
    std::printf("OPENBLAS_CORETYPE=%s (set in the environment; the server inherits it)\n", core);
  }
  const std::string src = STYLUS_SOURCE_DIR;
  Soak soak;
  soak.rate = rate;
  for (auto [clip, name] : {std::pair{&soak.walk, "walk_normal"}, std::pair{&soak.old, "walk_old"},
                            std::pair{&soak.run, "run"}}) {
    absl::StatusOr<motion::Motion> m = motion::ReadBvhFile(src + "/samples/" + name + ".bvh");
    if (!m.ok()) {
      std::fprintf(stderr, "soak: %s\n", std::string(m.status().message()).c_str());
      return 1;
    }
    *clip = *std::move(m);
  }
  const std::string tokens = "/tmp/stylus_soak." + std::to_string(getpid());
  std::ofstream(tokens + ".serving") << kToken << "\n";
  std::ofstream(tokens + ".admin") << kAdminToken << "\n";
  ServerProcess server;
  if (!server.Start(server_bin,
                    {"--models", src + "/models", "--max-streams", "4096", "--auth-tokens",
                     tokens + ".serving", "--admin-tokens", tokens + ".admin"})) {
    std::fprintf(stderr, "soak: %s did not start\n", server_bin.c_str());
    return 1;
  }
  soak.address = server.address();
  std::printf(
      "soak: %d stream clients at %.0f Hz, %d unary clients, bad input and model reloads, "
      "%d hostile clients, for %.0f s (warm-up %.0f s) against pid %d\n",
      streams, rate, unary_clients, hostile, seconds, warmup_s, server.pid);
  const auto start = Clock::now();
  std::vector<std::thread> clients;
  for (int i = 0; i < streams; ++i) clients.emplace_back([&soak, i] { soak.StreamClient(i); });
  for (int i = 0; i < unary_clients; ++i) clients.emplace_back([&soak, i] { soak.UnaryClient(i); });
  clients.emplace_back([&soak] { soak.Troublemaker(); });
  for (int i = 0; i < hostile; ++i) clients.emplace_back([&soak, i] { soak.HostileClient(i); });

  ProcessFigures warm = Measure(server.pid);
  bool warmed = warmup_s == 0;
  soak.tally.record = warmed;
  Print("start", 0, warm, soak);
  double next_report = report_s;
  bool alive = true;
  while (Since(start) < seconds) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    if (kill(server.pid, 0) != 0 || RssKb(server.pid) <= 0) {
      alive = false;
      break;
    }
    if (!warmed && Since(start) >= warmup_s) {
      warm = Measure(server.pid);
      warmed = true;
      soak.tally.record = true;
      Print("warm", Since(start), warm, soak);
    }
    if (Since(start) >= next_report) {
      Print("now", Since(start), Measure(server.pid), soak);
      next_report += report_s;
    }
  }
  soak.stop = true;
  for (std::thread& t : clients) t.join();
  // Let the last calls' sessions go before the final figures.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const ProcessFigures end = alive ? Measure(server.pid) : ProcessFigures{};
  alive = alive && end.rss_kb > 0;
  Print("end", Since(start), end, soak);
  if (!alive) {
    std::printf("FAIL: the server died\n");
    return 1;
  }
  const double rss_growth = 100.0 * (end.rss_kb - warm.rss_kb) / warm.rss_kb;
  const bool rss_ok = rss_growth < 5, fds_ok = end.fds <= warm.fds,
             threads_ok = end.threads <= warm.threads;
  std::printf(
      "after warm-up: RSS %.1f -> %.1f MB (%+.1f%%, target < 5%%: %s); fds %d -> %d (%s); "
      "threads %d -> %d (%s)\n",
      warm.rss_kb / 1024.0, end.rss_kb / 1024.0, rss_growth, rss_ok ? "met" : "MISSED", warm.fds,
      end.fds, fds_ok ? "met" : "MISSED", warm.threads, end.threads, threads_ok ? "met" : "MISSED");
  {
    absl::MutexLock lock(&soak.tally.mu);
    const std::vector<double>& l = soak.tally.latency_ms;
    std::printf(
        "stream frame latency after warm-up: p50 %.1f ms, p99 %.1f ms, max %.1f ms (%zu frames)\n",
        Percentile(l, 0.5), Percentile(l, 0.99),
        l.empty() ? 0.0 : *std::max_element(l.begin(), l.end()), l.size());
  }
  const int code = server.Stop();
  std::remove((tokens + ".serving").c_str());
  std::remove((tokens + ".admin").c_str());
  std::printf("server exit code after SIGTERM: %d\n", code);
  return rss_ok && fds_ok && threads_ok && code == 0 ? 0 : 1;
}

}  // namespace
}  // namespace stylus::bench

int main(int argc, char** argv) { return stylus::bench::Main(argc, argv); }
