// hostile: replays hostile clients' probes against a real stylus-server
// process (tokens on) and checks what each may cost it. For every probe it
// prints the status the server answered, the server's peak resident memory
// over the probe (VmHWM, reset before each probe through
// /proc/PID/clear_refs) above its resident memory before, and its threads;
// then "N passed, N failed". Exit status 1 when a probe fails.
//   hostile [--server PATH] [--models DIR] [--only NAME] [--baseline]
// Run by ctest (tests/CMakeLists.txt: hostile_clients); the figures are in
// docs/notes/operations.md "Hostile clients".
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_support.h"
#include "motion/bvh.h"
#include "stylus/v1/stylus.grpc.pb.h"
#include "wire/wire.h"

namespace stylus::bench {
namespace {

constexpr char kToken[] = "serve-token-1";
constexpr char kAdminToken[] = "admin-token-1";
constexpr double kMiB = 1024.0 * 1024.0;

std::string Flag(int argc, char** argv, const std::string& name, const std::string& fallback) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (argv[i] == name) return argv[i + 1];
  }
  return fallback;
}

long StatusField(pid_t pid, const std::string& field) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(f, line);) {
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  }
  return -1;
}

// The server's memory over one probe: resident memory before it, and the
// peak during it (the kernel's high-water mark, reset at the start).
class PeakMeter {
 public:
  explicit PeakMeter(pid_t pid) : pid_(pid) {
    std::ofstream("/proc/" + std::to_string(pid) + "/clear_refs") << "5";
    before_kb_ = StatusField(pid, "VmRSS");
  }
  double PeakMb() const { return (StatusField(pid_, "VmHWM") - before_kb_) / 1024.0; }
  double NowMb() const { return (StatusField(pid_, "VmRSS") - before_kb_) / 1024.0; }

 private:
  pid_t pid_;
  long before_kb_;
};

grpc::ByteBuffer Bytes(const std::string& s) {
  grpc::Slice slice(s);
  return grpc::ByteBuffer(&slice, 1);
}

struct Probe {
  std::string name;
  std::string expect;  // What the server should do.
  grpc::StatusCode code = grpc::OK;
  std::string got;
  double peak_mb = 0;
  long threads = 0;
  std::string note;
  bool pass = false;
};

class Suite {
 public:
  Suite(std::string server, std::string models)
      : server_(std::move(server)), models_(std::move(models)) {}

  // `baseline`: without the flags an older server lacks (--admin-tokens),
  // to measure it against the same probes.
  bool Start(bool baseline) {
    dir_ = "/tmp/stylus_hostile." + std::to_string(getpid());
    std::filesystem::create_directories(dir_);
    tokens_ = dir_ + "/tokens";
    WriteFile(tokens_, std::string(kToken) + "\n");
    WriteFile(dir_ + "/admin", std::string(kAdminToken) + "\n");
    log_ = dir_ + "/server.log";
    std::remove(log_.c_str());
    setenv("STYLUS_SERVER_LOG", log_.c_str(), 1);
    metrics_port_ = FreePort();
    std::vector<std::string> args = {"--models",
                                     models_,
                                     "--auth-tokens",
                                     tokens_,
                                     "--metrics-listen",
                                     "127.0.0.1:" + std::to_string(metrics_port_),
                                     "--stream-idle-timeout-s",
                                     "3",
                                     "--max-streams",
                                     "4"};
    if (!baseline) args.insert(args.end(), {"--admin-tokens", dir_ + "/admin"});
    if (!server_process_.Start(server_, args)) return false;
    channel_ = grpc::CreateChannel(server_process_.address(), grpc::InsecureChannelCredentials());
    return true;
  }
  ~Suite() {
    server_process_.Stop();
    std::filesystem::remove_all(dir_);
  }
  pid_t pid() const { return server_process_.pid; }
  std::shared_ptr<grpc::Channel> channel() const { return channel_; }
  std::string address() const { return server_process_.address(); }
  const std::string& tokens_path() const { return tokens_; }
  const std::string& log_path() const { return log_; }
  int metrics_port() const { return metrics_port_; }

  // One unary call of `method` with `bytes` as its request.
  grpc::Status Unary(const std::string& method, const std::string& bytes, const std::string& token,
                     grpc::ByteBuffer* response = nullptr) {
    grpc::GenericStub stub(channel_);
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    if (!token.empty()) ctx.AddMetadata("authorization", "Bearer " + token);
    grpc::ByteBuffer request = Bytes(bytes), reply;
    std::promise<grpc::Status> done;
    stub.UnaryCall(&ctx, method, {}, &request, &reply, [&](grpc::Status s) { done.set_value(s); });
    grpc::Status s = done.get_future().get();
    if (response != nullptr) *response = reply;
    return s;
  }

  static void WriteFile(const std::string& path, const std::string& text) {
    std::ofstream(path + ".tmp") << text;
    std::rename((path + ".tmp").c_str(), path.c_str());
  }

 private:
  std::string server_, models_, dir_, tokens_, log_;
  int metrics_port_ = 0;
  ServerProcess server_process_;
  std::shared_ptr<grpc::Channel> channel_;
};

std::string CodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::OK:
      return "OK";
    case grpc::CANCELLED:
      return "CANCELLED";
    case grpc::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::PERMISSION_DENIED:
      return "PERMISSION_DENIED";
    case grpc::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::UNIMPLEMENTED:
      return "UNIMPLEMENTED";
    case grpc::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::UNAUTHENTICATED:
      return "UNAUTHENTICATED";
    default:
      return "code " + std::to_string(static_cast<int>(code));
  }
}

motion::Motion Sample(const std::string& name) {
  return *motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/" + name);
}

// A TransferStream with a token, its config sent (the live model, a style clip).
struct OpenStream {
  grpc::ClientContext ctx;
  std::unique_ptr<v1::StyleService::Stub> stub;
  std::unique_ptr<grpc::ClientReaderWriter<v1::StreamRequest, v1::StreamResponse>> stream;

  bool Open(const std::shared_ptr<grpc::Channel>& channel, const std::string& token,
            const motion::Motion& content, const motion::Motion& style) {
    stub = v1::StyleService::NewStub(channel);
    if (!token.empty()) ctx.AddMetadata("authorization", "Bearer " + token);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
    stream = stub->TransferStream(&ctx);
    v1::StreamRequest config;
    config.mutable_config()->set_model("live");
    config.mutable_config()->set_fps(content.fps());
    wire::SkeletonToProto(content.skeleton, config.mutable_config()->mutable_skeleton());
    wire::ClipToProto(style, config.mutable_config()->mutable_style()->mutable_clip());
    return stream->Write(config);
  }
};

}  // namespace
}  // namespace stylus::bench

int main(int argc, char** argv) {
  using namespace stylus;
  using namespace stylus::bench;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::puts(
          "usage: hostile [--server PATH] [--models DIR] [--only NAME] [--baseline]\n\n"
          "Replays hostile clients' probes against a real stylus-server process with\n"
          "tokens on; prints each probe's answer, the server's peak memory over it and\n"
          "its threads, then 'N passed, N failed' (exit 1 if any failed).\n"
          "--baseline starts the server without --admin-tokens, to measure an older\n"
          "server that lacks the flag.");
      return 0;
    }
  }
  const std::string server =
      Flag(argc, argv, "--server", std::string(STYLUS_BINARY_DIR) + "/server/stylus-server");
  const std::string models =
      Flag(argc, argv, "--models", std::string(STYLUS_SOURCE_DIR) + "/models");
  const std::string only = Flag(argc, argv, "--only", "");
  bool baseline = false;
  for (int i = 1; i < argc; ++i) baseline |= std::string(argv[i]) == "--baseline";
  Suite suite(server, models);
  if (!suite.Start(baseline)) {
    std::fprintf(stderr, "hostile: the server did not start (%s)\n", server.c_str());
    return 1;
  }
  const pid_t pid = suite.pid();
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  std::vector<Probe> probes;
  auto run = [&](const std::string& name, const std::string& expect,
                 const std::function<void(Probe*)>& body) {
    if (!only.empty() && only != name) return;
    Probe p;
    p.name = name;
    p.expect = expect;
    body(&p);
    p.threads = StatusField(pid, "Threads");
    probes.push_back(p);
    std::printf("%-26s %-5s %-20s peak %+8.1f MB  threads %3ld  %s\n", p.name.c_str(),
                p.pass ? "ok" : "FAIL", p.got.c_str(), p.peak_mb, p.threads, p.note.c_str());
    std::fflush(stdout);
  };
  const long threads_at_start = StatusField(pid, "Threads");
  // A first real call, so that what LibTorch and gRPC allocate once is not
  // counted against a probe.
  {
    v1::TransferRequest warm;
    wire::ClipToProto(walk, warm.mutable_content());
    wire::ClipToProto(old, warm.mutable_style()->mutable_clip());
    grpc::Status s =
        suite.Unary("/stylus.v1.StyleService/Transfer", warm.SerializeAsString(), kToken);
    if (!s.ok()) std::fprintf(stderr, "hostile: warm-up transfer: %s\n", s.error_message().c_str());
    // And a refused one, a stream and a refused stream: first-use costs.
    (void)suite.Unary("/stylus.v1.StyleService/Transfer", warm.SerializeAsString(), "");
    for (const char* token : {kToken, ""}) {
      OpenStream s;
      if (!s.Open(suite.channel(), token, walk, old)) continue;
      for (int f = 0; f < walk.num_frames; ++f) {
        v1::StreamRequest r;
        wire::FrameToProto(walk, f, f, r.mutable_frame());
        if (!s.stream->Write(r)) break;
      }
      s.stream->WritesDone();
      v1::StreamResponse response;
      while (s.stream->Read(&response)) {
      }
      (void)s.stream->Finish();
    }
  }

  // 16 MiB of empty frames in a Transfer.
  std::string frames;
  const int empty_frames = 8 * 1024 * 1024 - 16;
  frames.reserve(2 * static_cast<size_t>(empty_frames));
  for (int i = 0; i < empty_frames; ++i) frames.append("\x12\x00", 2);
  const std::string big = WireField(2, frames);  // TransferRequest.content = Clip{frames...}
  frames.clear();
  frames.shrink_to_fit();

  run("anon_small_transfer", "UNAUTHENTICATED (the baseline)", [&](Probe* p) {
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Transfer", big.substr(0, 1024), "");
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass = s.error_code() == grpc::UNAUTHENTICATED;
  });
  run("anon_16mib_transfer", "UNAUTHENTICATED, +1 MB at most", [&](Probe* p) {
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Transfer", big, "");
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass = s.error_code() == grpc::UNAUTHENTICATED && p->peak_mb <= 1.0;
    p->note = "wire " + std::to_string(big.size() >> 20) + " MiB";
  });
  run("token_16mib_empty_frames", "refused, at most 4x the wire", [&](Probe* p) {
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Transfer", big, kToken);
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass = s.error_code() == grpc::RESOURCE_EXHAUSTED && p->peak_mb <= 4 * big.size() / kMiB;
    p->note = s.error_message().substr(0, 90);
  });
  run("token_empty_rotations", "refused, at most 4x the wire", [&](Probe* p) {
    // 30 000 frames (within --max-clip-frames), each of 22 empty rotations.
    std::string frame;
    for (int j = 0; j < 22; ++j) frame += WireField(4, "");
    std::string clip;
    for (int f = 0; f < 30000; ++f) clip += WireField(2, frame);
    const std::string request = WireField(2, clip);
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Transfer", request, kToken);
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass =
        s.error_code() == grpc::INVALID_ARGUMENT && p->peak_mb <= 4 * request.size() / kMiB + 1.0;
    p->note = "wire " + std::to_string(request.size() / 1024) + " KiB";
  });
  run("token_transfer_per_1000", "OK; working memory per 1000 frames", [&](Probe* p) {
    motion::Motion content = walk;
    for (int i = 0; i < 24; ++i) {  // 3000 frames.
      content.values.insert(content.values.end(), walk.values.begin(), walk.values.end());
      content.num_frames += walk.num_frames;
    }
    v1::TransferRequest r;
    wire::ClipToProto(content, r.mutable_content());
    wire::ClipToProto(old, r.mutable_style()->mutable_clip());
    const std::string request = r.SerializeAsString();
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Transfer", request, kToken);
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass = s.ok();
    char note[128];
    std::snprintf(note, sizeof(note), "%d frames, wire %.1f MB: %.1f MB per 1000 frames",
                  content.num_frames, request.size() / kMiB,
                  p->peak_mb * 1000 / content.num_frames);
    p->note = note;
  });
  run("interpolate_300k_names", "RESOURCE_EXHAUSTED (--max-styles)", [&](Probe* p) {
    std::string refs;
    const std::string one =
        WireField(3, WireField(2, "a"));  // InterpolateRequest.styles = {name: "a"}
    for (int i = 0; i < 300000; ++i) refs += one;
    PeakMeter meter(pid);
    grpc::Status s = suite.Unary("/stylus.v1.StyleService/Interpolate", refs, kToken);
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(s.error_code());
    p->pass =
        s.error_code() == grpc::RESOURCE_EXHAUSTED && p->peak_mb <= 4 * refs.size() / kMiB + 1;
    p->note = "wire " + std::to_string(refs.size() / 1024) + " KiB";
  });
  run("stream_reads", "OK (the baseline: a client that reads)", [&](Probe* p) {
    PeakMeter meter(pid);
    OpenStream s;
    const bool opened = s.Open(suite.channel(), kToken, walk, old);
    std::thread writer([&] {
      for (int f = 0; opened && f < 4000; ++f) {
        v1::StreamRequest r;
        wire::FrameToProto(walk, f % walk.num_frames, f, r.mutable_frame());
        if (!s.stream->Write(r)) break;
      }
      s.stream->WritesDone();
    });
    v1::StreamResponse response;
    int read = 0;
    while (s.stream->Read(&response)) ++read;
    writer.join();
    const grpc::Status status = s.stream->Finish();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(status.error_code());
    p->pass = status.ok() && read == 4000;
    char note[96];
    std::snprintf(note, sizeof(note), "4000 frames; +%.1f MB after", meter.NowMb());
    p->note = note;
  });
  // Twice: memory that a first stream leaves behind would show in the second.
  for (const char* name : {"stream_never_reads", "stream_never_reads_again"})
    run(name, "bounded, closed, memory back", [&](Probe* p) {
      PeakMeter meter(pid);
      OpenStream s;
      std::atomic<int> sent{0};
      std::atomic<bool> ended{false};
      // A client whose transport takes in no more than 64 KiB it has not read
      // (gRPC's own would take megabytes for it).
      grpc::ChannelArguments args;
      args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
      args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 65536);
      const bool opened = s.Open(
          grpc::CreateCustomChannel(suite.address(), grpc::InsecureChannelCredentials(), args),
          kToken, walk, old);
      std::thread writer([&] {
        for (int f = 0; opened && f < 8000; ++f) {
          v1::StreamRequest r;
          wire::FrameToProto(walk, f % walk.num_frames, f, r.mutable_frame());
          if (!s.stream->Write(r)) break;
          ++sent;
        }
        ended = true;
      });
      // The server stops reading once its backlog is full; then, reading
      // nothing for --stream-idle-timeout-s (3 s), the stream is closed.
      std::this_thread::sleep_for(std::chrono::seconds(2));
      const double held = meter.PeakMb();
      const int sent_when_held = sent.load();
      for (int i = 0; i < 100 && !ended; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      // Ended before its 8000 frames went: the server stopped reading and then
      // closed the stream (a server that reads on takes all 8000).
      const bool closed_by_server = ended.load() && sent.load() < 8000;
      s.ctx.TryCancel();
      writer.join();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      p->peak_mb = meter.PeakMb();
      const double after = meter.NowMb();
      p->got = closed_by_server ? "closed" : sent.load() == 8000 ? "took all 8000" : "still open";
      p->pass = opened && closed_by_server && sent_when_held < 8000 && held <= 16 && after <= 4;
      char note[160];
      std::snprintf(note, sizeof(note),
                    "%d frames taken before it stopped reading; +%.1f MB held, +%.1f MB after",
                    sent_when_held, held, after);
      p->note = note;
    });
  run("style_changes_far_ahead", "capped; too far INVALID_ARGUMENT", [&](Probe* p) {
    PeakMeter meter(pid);
    grpc::StatusCode capped = grpc::OK, far = grpc::OK;
    for (int pass = 0; pass < 2; ++pass) {
      OpenStream s;
      if (!s.Open(suite.channel(), kToken, walk, old)) break;
      v1::StreamRequest r;
      wire::FrameToProto(walk, 0, 0, r.mutable_frame());
      s.stream->Write(r);
      for (int i = 0; i < (pass == 0 ? 100000 : 1); ++i) {
        v1::StreamRequest c;
        c.mutable_change()->set_from_frame(pass == 0 ? 50000 + i : 1000000000000LL);
        c.mutable_change()->set_strength(0.5);
        if (!s.stream->Write(c)) break;
      }
      s.stream->WritesDone();
      v1::StreamResponse response;
      while (s.stream->Read(&response)) {
      }
      (pass == 0 ? capped : far) = s.stream->Finish().error_code();
    }
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(capped) + "/" + CodeName(far);
    p->pass =
        capped == grpc::RESOURCE_EXHAUSTED && far == grpc::INVALID_ARGUMENT && p->peak_mb <= 16;
  });
  // 200 reflection streams held open, without a token: on `server`
  // (reflection off: each ends UNIMPLEMENTED at once), and the threads that
  // cost. Returns the first status; `during` gets the threads while open.
  auto reflection_streams = [&](const std::string& address, pid_t server_pid, long* during) {
    auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
    grpc::GenericStub stub(channel);
    grpc::CompletionQueue cq;
    constexpr int kStreams = 200;
    std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
    std::vector<std::unique_ptr<grpc::GenericClientAsyncReaderWriter>> calls;
    std::vector<grpc::Status> statuses(kStreams);
    for (int i = 0; i < kStreams; ++i) {
      contexts.push_back(std::make_unique<grpc::ClientContext>());
      contexts.back()->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
      calls.push_back(
          stub.PrepareCall(contexts.back().get(),
                           "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &cq));
      calls.back()->StartCall(reinterpret_cast<void*>(static_cast<intptr_t>(i)));
    }
    void* tag;
    bool ok;
    for (int i = 0; i < kStreams; ++i) {
      if (!cq.Next(&tag, &ok)) break;
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    *during = StatusField(server_pid, "Threads");
    for (auto& c : contexts) c->TryCancel();
    for (int i = 0; i < kStreams; ++i) {
      calls[i]->Finish(&statuses[i], reinterpret_cast<void*>(static_cast<intptr_t>(kStreams + i)));
    }
    for (int i = 0; i < kStreams; ++i) {
      if (!cq.Next(&tag, &ok)) break;
    }
    calls.clear();
    contexts.clear();
    cq.Shutdown();
    while (cq.Next(&tag, &ok)) {
    }
    return statuses[0];
  };
  run("reflection_200_streams", "off: UNIMPLEMENTED; no thread per stream", [&](Probe* p) {
    PeakMeter meter(pid);
    const long before = StatusField(pid, "Threads");
    long during = 0;
    const grpc::Status status = reflection_streams(suite.address(), pid, &during);
    // With --reflection: its threads are bounded (gRPC's resource quota).
    ServerProcess with;
    long with_before = -1, with_during = -1;
    if (with.Start(server, {"--models", models, "--reflection"})) {
      with_before = StatusField(with.pid, "Threads");
      (void)reflection_streams(with.address(), with.pid, &with_during);
      with.Stop();
    }
    // One call on its own, to read its status.
    grpc::GenericStub stub(suite.channel());
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    grpc::CompletionQueue cq;
    auto call = stub.PrepareCall(
        &ctx, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &cq);
    void* tag;
    bool ok;
    grpc::Status one;
    call->StartCall(reinterpret_cast<void*>(1));
    cq.Next(&tag, &ok);
    call->WritesDone(reinterpret_cast<void*>(3));
    cq.Next(&tag, &ok);
    call->Finish(&one, reinterpret_cast<void*>(2));
    cq.Next(&tag, &ok);
    call.reset();
    cq.Shutdown();
    while (cq.Next(&tag, &ok)) {
    }
    (void)status;
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(one.error_code());
    // gRPC's pools may grow by a few threads under a burst of calls; a
    // thread per stream would be 200.
    p->pass = one.error_code() == grpc::UNIMPLEMENTED && during - before <= 16 &&
              with_during >= 0 && with_during - with_before <= 16;
    p->note = "threads " + std::to_string(before) + " -> " + std::to_string(during) +
              "; with --reflection " + std::to_string(with_before) + " -> " +
              std::to_string(with_during);
  });
  run("load_unload_rights", "serving token PERMISSION_DENIED; default stays", [&](Probe* p) {
    v1::LoadModelRequest load;
    load.set_model("cyclic/v1");
    v1::UnloadModelRequest unload_default;
    unload_default.set_model("contrastive/v10");
    {
      std::ifstream f(std::string(STYLUS_SOURCE_DIR) + "/models/DEFAULT");
      std::string id;
      for (std::string line; std::getline(f, line);) {
        if (!line.empty() && line[0] != '#') id = line;
      }
      if (!id.empty()) unload_default.set_model(id);
    }
    v1::UnloadModelRequest unload;
    unload.set_model("cyclic/v1");
    PeakMeter meter(pid);
    const grpc::StatusCode serving_unload =
        suite.Unary("/stylus.v1.ModelService/UnloadModel", unload.SerializeAsString(), kToken)
            .error_code();
    const grpc::StatusCode serving_load =
        suite.Unary("/stylus.v1.ModelService/LoadModel", load.SerializeAsString(), kToken)
            .error_code();
    const grpc::StatusCode admin_default =
        suite
            .Unary("/stylus.v1.ModelService/UnloadModel", unload_default.SerializeAsString(),
                   kAdminToken)
            .error_code();
    const grpc::StatusCode admin_unload =
        suite.Unary("/stylus.v1.ModelService/UnloadModel", unload.SerializeAsString(), kAdminToken)
            .error_code();
    const grpc::StatusCode admin_load =
        suite.Unary("/stylus.v1.ModelService/LoadModel", load.SerializeAsString(), kAdminToken)
            .error_code();
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(serving_unload);
    p->pass = serving_unload == grpc::PERMISSION_DENIED &&
              serving_load == grpc::PERMISSION_DENIED &&
              admin_default == grpc::FAILED_PRECONDITION && admin_unload == grpc::OK &&
              admin_load == grpc::OK;
    p->note = "admin: default " + CodeName(admin_default) + ", unload " + CodeName(admin_unload) +
              ", load " + CodeName(admin_load);
  });
  run("log_injection", "one escaped line; 1 MiB id refused", [&](Probe* p) {
    v1::GetModelRequest forged;
    forged.set_model("nope\n[error] forged line");
    v1::GetModelRequest huge;
    huge.set_model(std::string(1 << 20, 'x'));
    PeakMeter meter(pid);
    const grpc::StatusCode a =
        suite.Unary("/stylus.v1.ModelService/GetModel", forged.SerializeAsString(), kToken)
            .error_code();
    const grpc::StatusCode b =
        suite.Unary("/stylus.v1.ModelService/GetModel", huge.SerializeAsString(), kToken)
            .error_code();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    p->peak_mb = meter.PeakMb();
    std::ifstream log(suite.log_path());
    size_t longest = 0;
    bool forged_line = false;
    for (std::string line; std::getline(log, line);) {
      longest = std::max(longest, line.size());
      if (line.rfind("[error] forged", 0) == 0) forged_line = true;
    }
    p->got = CodeName(a) + "/" + CodeName(b);
    p->pass =
        a == grpc::NOT_FOUND && b == grpc::INVALID_ARGUMENT && !forged_line && longest <= 2048;
    p->note = "longest log line " + std::to_string(longest) + " bytes";
  });
  run("metrics_idle_sockets", "a scrape within 1 s", [&](Probe* p) {
    std::vector<int> idle;
    for (int i = 0; i < 3; ++i) {
      const int fd = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in addr{};
      addr.sin_family = AF_INET;
      addr.sin_port = htons(static_cast<uint16_t>(suite.metrics_port()));
      addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) idle.push_back(fd);
    }
    PeakMeter meter(pid);
    const auto t0 = Clock::now();
    const std::string body = HttpGet(suite.metrics_port(), "/metrics");
    const double seconds = Since(t0);
    for (int fd : idle) close(fd);
    p->peak_mb = meter.PeakMb();
    p->got = body.empty() ? "no answer" : "scraped";
    p->pass = !body.empty() && seconds <= 1.0 && idle.size() == 3;
    char note[64];
    std::snprintf(note, sizeof(note), "%.3f s with 3 idle sockets", seconds);
    p->note = note;
  });
  run("anon_stream_when_full", "UNAUTHENTICATED, not a slot", [&](Probe* p) {
    PeakMeter meter(pid);
    std::vector<std::unique_ptr<OpenStream>> held;
    for (int i = 0; i < 4; ++i) {  // --max-streams 4: all slots taken by real streams.
      held.push_back(std::make_unique<OpenStream>());
      held.back()->Open(suite.channel(), kToken, walk, old);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    OpenStream anon;
    anon.Open(suite.channel(), "", walk, old);
    v1::StreamResponse r;
    while (anon.stream->Read(&r)) {
    }
    const grpc::StatusCode code = anon.stream->Finish().error_code();
    for (auto& s : held) s->ctx.TryCancel();
    for (auto& s : held) (void)s->stream->Finish();
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(code);
    p->pass = code == grpc::UNAUTHENTICATED;
  });
  run("token_file_emptied", "old token refused within 3 s, no signal", [&](Probe* p) {
    PeakMeter meter(pid);
    v1::ListModelsRequest list;
    const std::string bytes = list.SerializeAsString();
    const bool before = suite.Unary("/stylus.v1.ModelService/ListModels", bytes, kToken).ok();
    Suite::WriteFile(suite.tokens_path(), "# revoked\n");
    grpc::StatusCode code = grpc::OK;
    const auto t0 = Clock::now();
    while (Since(t0) < 3) {
      code = suite.Unary("/stylus.v1.ModelService/ListModels", bytes, kToken).error_code();
      if (code == grpc::UNAUTHENTICATED) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const double revoked_after = Since(t0);
    Suite::WriteFile(suite.tokens_path(), std::string(kToken) + "\n");
    bool back = false;
    for (int i = 0; i < 30 && !back; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      back = suite.Unary("/stylus.v1.ModelService/ListModels", bytes, kToken).ok();
    }
    p->peak_mb = meter.PeakMb();
    p->got = CodeName(code);
    p->pass = before && code == grpc::UNAUTHENTICATED && back;
    char note[64];
    std::snprintf(note, sizeof(note), "revoked after %.1f s; restored: %s", revoked_after,
                  back ? "yes" : "no");
    p->note = note;
  });

  int passed = 0, failed = 0;
  for (const Probe& p : probes) (p.pass ? passed : failed)++;
  std::printf("threads at start %ld, at the end %ld\n", threads_at_start,
              StatusField(pid, "Threads"));
  // Flags that would overflow or mislead are refused at start-up.
  if (only.empty() || only == "message_size_flag") {
    ServerProcess bad;
    const bool started = bad.Start(server, {"--models", models, "--max-message-mb", "4096"});
    const bool pass = !started;
    std::printf("%-26s %-5s %-20s\n", "message_size_flag", pass ? "ok" : "FAIL",
                started ? "started" : "refused to start");
    (pass ? passed : failed)++;
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
