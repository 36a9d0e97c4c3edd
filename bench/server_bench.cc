// Service figures against a real stylus-server process:
//   - unary Transfer latency of a 300-frame clip (median of N), and as a ratio
//     to the baseline measured in the same run: the same transfer in-process,
//     without gRPC (so the ratio is the cost of the service around the model);
//   - TransferStream per-frame latency p50/p99 when frames are sent at 30 fps
//     (and the floor the windowing sets: a frame waits for the window after it);
//   - the server's resident memory idle and after 1000 Transfer calls.
// Usage: server_bench [--server-bin PATH] [--calls 1000] [--reps 20]
#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_support.h"
#include "client/client.h"
#include "model/family_registry.h"
#include "model/runtime.h"
#include "motion/synth.h"

using stylus::bench::Clock;
using stylus::bench::Percentile;
using stylus::bench::RssKb;
using stylus::bench::Since;

int main(int argc, char** argv) {
  std::string server_bin = std::string(STYLUS_BINARY_DIR) + "/server/stylus-server";
  int calls = 1000, reps = 20;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help")) {
      std::printf("usage: server_bench [--server-bin PATH] [--calls 1000] [--reps 20]\n");
      return 0;
    }
    if (i + 1 >= argc) break;
    if (!std::strcmp(argv[i], "--server-bin")) server_bin = argv[++i];
    if (!std::strcmp(argv[i], "--calls")) calls = std::atoi(argv[++i]);
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[++i]);
  }
  const std::string models = std::string(STYLUS_SOURCE_DIR) + "/models";
  stylus::bench::ServerProcess server;
  if (!server.Start(server_bin, {"--models", models, "--threads", "2"})) {
    std::fprintf(stderr, "server_bench: cannot start %s\n", server_bin.c_str());
    return 1;
  }
  const pid_t pid = server.pid;
  stylus::ClientOptions options;
  options.address = server.address();
  stylus::Client client(options);

  const auto content =
      *stylus::motion::Synthesize(*stylus::motion::ParseSynthStyle("normal,frames=300"));
  const auto style =
      *stylus::motion::Synthesize(*stylus::motion::ParseSynthStyle("old,frames=120"));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const long rss_idle = RssKb(pid);

  // Baseline: the same transfer in this process, 1 LibTorch thread (as the server runs it).
  stylus::model::SetComputeThreads(1);
  auto model = stylus::model::LoadStyleModel(models + "/contrastive/v5");
  const auto code = *(*model)->EncodeStyle(style);
  std::vector<double> local, unary;
  for (int r = 0; r < reps; ++r) {
    auto t = Clock::now();
    (void)(*model)->Transfer(content, code);
    local.push_back(Since(t));
    (void)client.EncodeStyle(style, "bench");
    t = Clock::now();
    auto out = client.Transfer(content, {nullptr, "bench"});
    unary.push_back(Since(t));
    if (!out.ok()) {
      std::fprintf(stderr, "server_bench: %s\n", out.status().ToString().c_str());
      return 1;
    }
  }
  const double lm = Percentile(local, 0.5), um = Percentile(unary, 0.5);
  std::printf(
      "unary Transfer, 300 frames (saved style): median %.1f ms; in-process baseline %.1f ms;"
      " ratio %.2f\n",
      1000 * um, 1000 * lm, um / lm);

  auto streamed = client.Stream(content, {&style, ""}, 30);
  if (!streamed.ok()) {
    std::fprintf(stderr, "server_bench: stream: %s\n", streamed.status().ToString().c_str());
    return 1;
  }
  const absl::StatusOr<stylus::v1::ModelInfo> info = client.GetModel("");
  if (!info.ok()) {
    std::fprintf(stderr, "server_bench: %s\n", info.status().ToString().c_str());
    return 1;
  }
  // Frame f leaves once input reaches the start of the window after it plus
  // a window and one frame: on average (hop-1)/2 + window + 1 frames later.
  const double floor_ms = 1000.0 * ((info->hop() - 1) / 2.0 + info->window() + 1) / 30.0;
  std::printf(
      "TransferStream at 30 fps, 300 frames: per-frame latency p50 %.0f ms, p99 %.0f ms; "
      "windowing floor (mean wait for the next window) %.0f ms; p50/floor %.2f\n",
      1000 * Percentile(streamed->latency_s, 0.5), 1000 * Percentile(streamed->latency_s, 0.99),
      floor_ms, 1000 * Percentile(streamed->latency_s, 0.5) / floor_ms);

  const long rss_before = RssKb(pid);
  const auto t_calls = Clock::now();
  std::vector<std::thread> workers;
  std::atomic<int> failures{0};
  for (int w = 0; w < 2; ++w) {
    workers.emplace_back([&, w] {
      for (int i = w; i < calls; i += 2) {
        if (!client.Transfer(content, {nullptr, "bench"}).ok()) ++failures;
      }
    });
  }
  for (auto& t : workers) t.join();
  const double secs = Since(t_calls);
  const long rss_after = RssKb(pid);
  std::printf(
      "server RSS: idle %.1f MB; before the calls %.1f MB; after %d Transfer calls (%.1f s, "
      "%.1f calls/s, %d failed) %.1f MB; after/before %.2f\n",
      rss_idle / 1024.0, rss_before / 1024.0, calls, secs, calls / secs, failures.load(),
      rss_after / 1024.0, static_cast<double>(rss_after) / rss_before);
  std::printf("server exit on SIGTERM: %d\n", server.Stop());
  return 0;
}
