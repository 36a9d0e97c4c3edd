// stylus-server: hosts the models of a directory over gRPC.
#include <csignal>
#include <cstdio>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "server/call_log.h"
#include "server/server.h"
#include "spdlog/spdlog.h"

namespace {

constexpr char kHelp[] =
    "usage: stylus-server [--models DIR] [--default-model NAME/VERSION]\n"
    "                     [--listen ADDR] [--threads N] [--torch-threads N]\n"
    "                     [--max-streams N] [--max-message-mb N] [--max-stream-frames N]\n"
    "                     [--max-batch N] [--max-queue-delay-us N] [--batch-unary]\n"
    "                     [--metrics-listen ADDR] [--auth-tokens FILE]\n"
    "                     [--admin-tokens FILE] [--reflection]\n"
    "                     [--tls-cert FILE --tls-key FILE [--tls-client-ca FILE]]\n"
    "                     [--max-clip-frames N] [--max-joints N] [--max-unary-calls N]\n"
    "                     [--max-saved-styles N] [--stream-idle-timeout-s S]\n"
    "                     [--max-styles N] [--max-stream-backlog N] [--max-memory-mb N]\n"
    "                     [--style-library DIR [--style-library-labels CSV]]\n"
    "                     [--shutdown-grace-s S] [--port-file FILE] [--log-format F]\n\n"
    "Serves style transfer (stylus.v1.ModelService, stylus.v1.StyleService)\n"
    "and grpc.health.v1. Loads every model package under\n"
    "--models (default: models) at start-up.\n\n"
    "  --listen ADDR          default localhost:50051; port 0 picks a free port\n"
    "  --threads N            compute threads (default 2)\n"
    "  --torch-threads N      LibTorch threads per forward pass (default 1)\n"
    "  --max-streams N        concurrent TransferStream calls (default 1024)\n"
    "  --max-batch N          live streams' steps (and with --batch-unary,\n"
    "                         concurrent unary transfers' windows) run\n"
    "                         together, up to N per forward pass (default 256;\n"
    "                         0: each call alone)\n"
    "  --max-queue-delay-us N how long a step or pass may wait for others to\n"
    "                         batch with (default 500)\n"
    "  --batch-unary          batch unary Transfer/Interpolate passes too (off:\n"
    "                         on a CPU, parallel calls are faster; docs/service.md)\n"
    "  --auth-tokens FILE     calls need 'authorization: Bearer TOKEN' with a token\n"
    "                         from FILE (one per line; re-read on SIGHUP and when\n"
    "                         it changes; a file with no valid token revokes\n"
    "                         all); health checks stay open\n"
    "  --admin-tokens FILE    LoadModel/UnloadModel need a token from FILE (which\n"
    "                         also serves); with --auth-tokens and without this,\n"
    "                         nobody loads models after start-up\n"
    "  --reflection           serve grpc.reflection (the API's description, to\n"
    "                         any caller; off by default)\n"
    "  --tls-cert FILE        serve TLS with this PEM certificate (chain)...\n"
    "  --tls-key FILE         ...and its PEM private key (default: plain text,\n"
    "                         for localhost or a trusted network only)\n"
    "  --tls-client-ca FILE   mutual TLS: clients must present a certificate\n"
    "                         signed by a CA in this PEM file\n"
    "  --metrics-listen ADDR  serve Prometheus metrics at http://ADDR/metrics\n"
    "                         (e.g. 0.0.0.0:9464; off by default)\n"
    "  --style-library DIR    takes of styles (BVH, any rig) that packages with\n"
    "                         movement from examples draw their legs', pelvis's\n"
    "                         and arms' movement from (docs/movement.md); labels\n"
    "                         from dataset-N_{action}_{style}_{take}.bvh names...\n"
    "  --style-library-labels CSV  ...or a clip,action,style CSV\n"
    "  --max-message-mb N     largest request or response (default 32, at most\n"
    "                         1024)\n"
    "  --max-stream-frames N  frames per stream (default 108000, 1 h at 30 fps)\n"
    "  --max-clip-frames N    frames per clip in a unary call (default 36000)\n"
    "  --max-joints N         joints per skeleton (default 256)\n"
    "  --max-unary-calls N    unary calls waiting or running; more are refused\n"
    "                         RESOURCE_EXHAUSTED (default 64)\n"
    "  --max-saved-styles N   style names saved per model (default 1000)\n"
    "  --max-styles N         styles in one Interpolate call or blend (default 16)\n"
    "  --max-stream-backlog N output frames a stream holds for a client that does\n"
    "                         not read them; past this it stops reading the\n"
    "                         client's frames until it reads (default 128)\n"
    "  --max-memory-mb N      memory for gRPC's buffers, and for the requests and\n"
    "                         working data of unary calls in progress; a call\n"
    "                         that does not fit is refused RESOURCE_EXHAUSTED\n"
    "                         (default 2048; 0: unbounded)\n"
    "  --stream-idle-timeout-s S\n"
    "                         close a stream whose client sends nothing, or reads\n"
    "                         nothing it is sent, for S seconds (default 120; 0:\n"
    "                         never)\n"
    "  --shutdown-grace-s S   on SIGINT/SIGTERM, how long in-flight calls may\n"
    "                         run on (default 10)\n"
    "  --port-file FILE       write the bound port there once serving\n"
    "  --log-format text|json text for people (default) or one JSON object per\n"
    "                         line; a call's line has its request id (the\n"
    "                         client's x-request-id, else one made) and peer\n";

int Usage(const std::string& error) {
  std::fprintf(stderr, "stylus-server: %s\n\n%s", error.c_str(), kHelp);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // Debian's Abseil is built to check every mutex acquisition for lock-order
  // cycles (a graph update per lock, about 1% of a loaded server's CPU); the
  // tests keep the check, the server does without it.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  stylus::server::ServerOptions options;
  double grace_s = 10;
  std::string port_file;
  stylus::server::LogFormat log_format = stylus::server::LogFormat::kText;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (arg == "--batch-unary") {
      options.batch_unary = true;
      continue;
    }
    if (arg == "--reflection") {
      options.reflection = true;
      continue;
    }
    if (i + 1 >= argc) return Usage(arg + " needs a value");
    const std::string value = argv[++i];
    auto to_int = [&](int* out) { return absl::SimpleAtoi(value, out) && *out > 0; };
    bool ok = true;
    if (arg == "--models") {
      options.models_dir = value;
    } else if (arg == "--default-model") {
      options.default_model = value;
    } else if (arg == "--listen") {
      options.listen = value;
    } else if (arg == "--threads") {
      ok = to_int(&options.threads);
    } else if (arg == "--torch-threads") {
      ok = to_int(&options.torch_threads);
    } else if (arg == "--max-streams") {
      ok = to_int(&options.max_streams);
    } else if (arg == "--max-batch") {
      ok = absl::SimpleAtoi(value, &options.max_batch) && options.max_batch >= 0;
    } else if (arg == "--max-queue-delay-us") {
      ok = absl::SimpleAtoi(value, &options.max_queue_delay_us) && options.max_queue_delay_us >= 0;
    } else if (arg == "--auth-tokens") {
      options.auth_tokens = value;
    } else if (arg == "--admin-tokens") {
      options.admin_tokens = value;
    } else if (arg == "--max-styles") {
      ok = absl::SimpleAtoi(value, &options.max_styles) && options.max_styles >= 2;
    } else if (arg == "--max-stream-backlog") {
      ok = to_int(&options.max_stream_backlog);
    } else if (arg == "--max-memory-mb") {
      ok = absl::SimpleAtoi(value, &options.max_memory_mb) && options.max_memory_mb >= 0;
    } else if (arg == "--style-library") {
      options.style_library = value;
    } else if (arg == "--style-library-labels") {
      options.style_library_labels = value;
    } else if (arg == "--tls-cert") {
      options.tls_cert = value;
    } else if (arg == "--tls-key") {
      options.tls_key = value;
    } else if (arg == "--tls-client-ca") {
      options.tls_client_ca = value;
    } else if (arg == "--metrics-listen") {
      options.metrics_listen = value;
    } else if (arg == "--max-message-mb") {
      ok = to_int(&options.max_message_mb);
      if (ok && options.max_message_mb > stylus::server::kMaxMessageMb) {
        return Usage(absl::StrCat("--max-message-mb: ", value, " is over the largest, ",
                                  stylus::server::kMaxMessageMb));
      }
    } else if (arg == "--max-stream-frames") {
      ok = absl::SimpleAtoi(value, &options.max_stream_frames) && options.max_stream_frames > 0;
    } else if (arg == "--max-clip-frames") {
      ok = absl::SimpleAtoi(value, &options.max_clip_frames) && options.max_clip_frames > 0;
    } else if (arg == "--max-joints") {
      ok = to_int(&options.max_joints);
    } else if (arg == "--max-unary-calls") {
      ok = to_int(&options.max_unary_calls);
    } else if (arg == "--max-saved-styles") {
      ok = to_int(&options.max_saved_styles);
    } else if (arg == "--stream-idle-timeout-s") {
      ok = absl::SimpleAtod(value, &options.stream_idle_timeout_s) &&
           options.stream_idle_timeout_s >= 0;
    } else if (arg == "--shutdown-grace-s") {
      ok = absl::SimpleAtod(value, &grace_s) && grace_s >= 0;
    } else if (arg == "--log-format") {
      absl::StatusOr<stylus::server::LogFormat> f = stylus::server::ParseLogFormat(value);
      if (!f.ok()) return Usage(std::string(f.status().message()));
      log_format = *f;
    } else if (arg == "--port-file") {
      port_file = value;
    } else {
      return Usage("unknown option " + arg);
    }
    if (!ok) return Usage(absl::StrCat(arg, ": '", value, "' is not a valid value"));
  }

  // Logs go to stderr: start-up, one line per call, shutdown.
  stylus::server::SetUpLogging(log_format);

  // Signals are taken by one thread with sigwait; block them everywhere else
  // (gRPC's and LibTorch's threads inherit this mask).
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  absl::StatusOr<std::unique_ptr<stylus::server::StylusServer>> server =
      stylus::server::StylusServer::Start(options);
  if (!server.ok()) {
    spdlog::error("cannot start: {}", server.status().ToString());
    return 1;
  }
  if (!port_file.empty()) {
    FILE* f = std::fopen((port_file + ".tmp").c_str(), "w");
    if (f == nullptr || std::fprintf(f, "%d\n", (*server)->port()) < 0 || std::fclose(f) != 0 ||
        std::rename((port_file + ".tmp").c_str(), port_file.c_str()) != 0) {
      spdlog::error("cannot write the port to {}", port_file);
      return 1;
    }
  }
  std::thread waiter([&] {
    int sig = 0;
    while (sigwait(&signals, &sig) == 0 && sig == SIGHUP) {
      const absl::StatusOr<int> n = (*server)->ReloadTokens();  // Logs what is in force.
      spdlog::info("received SIGHUP: {}", n.status().code() == absl::StatusCode::kFailedPrecondition
                                              ? "no token files to read (no --auth-tokens)"
                                              : "the token files were read again");
    }
    spdlog::info("received {}; finishing in-flight calls (up to {} s)",
                 sig == SIGINT ? "SIGINT" : "SIGTERM", grace_s);
    (*server)->Shutdown(std::chrono::system_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(grace_s * 1000)));
  });
  (*server)->Wait();
  waiter.join();
  return 0;
}
