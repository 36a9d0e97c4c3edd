// Service figures against a real stylus-server process:
//   - unary Transfer latency of a 300-frame clip (median of N), and as a ratio
//     to the baseline measured in the same run: the same transfer in-process,
//     without gRPC (so the ratio is the cost of the service around the model);
//   - TransferStream per-frame latency p50/p99 when frames are sent at 30 fps
//     (and the floor the windowing sets: a frame waits for the window after it);
//   - the server's resident memory idle and after 1000 Transfer calls;
//   - the same unary latency on a second server with --metrics-listen,
//     scraped every 100 ms meanwhile (Prometheus scrapes every 15 s or so),
//     calls alternating between the two servers: the metrics' overhead.
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
#include "model/package.h"
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
  auto model = stylus::model::LoadStyleModel(models + "/" + stylus::model::ReadDefaultPackage(models).value());
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

  // The metrics' overhead: a server with them on, alternating with the first.
  const int metrics_port = stylus::bench::FreePort();
  stylus::bench::ServerProcess with_metrics;
  if (metrics_port == 0 ||
      !with_metrics.Start(server_bin, {"--models", models, "--threads", "2", "--metrics-listen",
                                       "127.0.0.1:" + std::to_string(metrics_port)})) {
    std::fprintf(stderr, "server_bench: cannot start %s with metrics\n", server_bin.c_str());
    return 1;
  }
  stylus::ClientOptions metrics_options;
  metrics_options.address = with_metrics.address();
  stylus::Client metrics_client(metrics_options);
  (void)metrics_client.EncodeStyle(style, "bench");
  std::atomic<bool> scraping{true};
  std::atomic<int> scrapes{0}, empty_scrapes{0};
  std::thread scraper([&] {
    while (scraping) {
      const std::string text = stylus::bench::HttpGet(metrics_port, "/metrics");
      ++(text.find("grpc_server_handled_total") != std::string::npos ? scrapes : empty_scrapes);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  std::vector<double> plain, metered;
  for (int r = 0; r < 3 * reps; ++r) {
    auto t = Clock::now();
    const bool a = client.Transfer(content, {nullptr, "bench"}).ok();
    plain.push_back(Since(t));
    t = Clock::now();
    const bool b = metrics_client.Transfer(content, {nullptr, "bench"}).ok();
    metered.push_back(Since(t));
    if (!a || !b) ++failures;
  }
  scraping = false;
  scraper.join();
  const double pm = Percentile(plain, 0.5), mm = Percentile(metered, 0.5);
  std::printf(
      "metrics overhead: unary Transfer median %.1f ms without, %.1f ms with metrics scraped "
      "every 100 ms (%d scrapes, %d without the series); ratio %.3f\n",
      1000 * pm, 1000 * mm, scrapes.load(), empty_scrapes.load(), mm / pm);
  std::printf("server with metrics exit on SIGTERM: %d\n", with_metrics.Stop());
  std::printf("server exit on SIGTERM: %d\n", server.Stop());
  return 0;
}
