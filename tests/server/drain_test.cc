// SIGTERM while streams are open, on a real stylus-server process: every
// frame the server took before the signal comes back, in order, before each
// stream ends UNAVAILABLE; the server then exits 0, long before its grace.
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <csignal>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus::testing {
namespace {

struct StreamRun {
  std::string model;
  std::vector<int64_t> indices;  // The input index each output frame carries.
  std::atomic<int> outputs{0};
  grpc::Status status;
  int64_t server_took = -1;  // Trailing metadata stylus-frames-received.
  int sent = 0;
};

// Streams `content` at 30 Hz on `model` until the server ends the call.
void RunStream(const std::string& address, const motion::Motion& content,
               const motion::Motion& style, StreamRun* run) {
  auto stub =
      v1::StyleService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  auto stream = stub->TransferStream(&ctx);
  std::thread writer([&] {
    v1::StreamRequest config;
    config.mutable_config()->set_model(run->model);
    config.mutable_config()->set_fps(content.fps());
    wire::SkeletonToProto(content.skeleton, config.mutable_config()->mutable_skeleton());
    wire::ClipToProto(style, config.mutable_config()->mutable_style()->mutable_clip());
    if (!stream->Write(config)) return;
    const auto start = std::chrono::steady_clock::now();
    for (int f = 0; f < content.num_frames; ++f) {
      std::this_thread::sleep_until(start + std::chrono::microseconds(f * 33333));
      v1::StreamRequest r;
      wire::FrameToProto(content, f, f, r.mutable_frame());
      if (!stream->Write(r)) return;
      run->sent = f + 1;
    }
    stream->WritesDone();
  });
  v1::StreamResponse response;
  while (stream->Read(&response)) {
    run->indices.push_back(response.frame().index());
    ++run->outputs;
  }
  writer.join();
  run->status = stream->Finish();
  const auto& trailing = ctx.GetServerTrailingMetadata();
  const auto it = trailing.find("stylus-frames-received");
  if (it != trailing.end()) {
    (void)absl::SimpleAtoi(absl::string_view(it->second.data(), it->second.size()),
                           &run->server_took);
  }
}

TEST(DrainTest, SigtermReturnsEveryFrameTheServerTookBeforeStreamsEnd) {
  bench::ServerProcess server;
  ASSERT_TRUE(server.Start(std::string(STYLUS_BINARY_DIR) + "/server/stylus-server",
                           {"--models", SourceDir() + "/models", "--shutdown-grace-s", "30"}));
  motion::Motion content = Sample("walk_normal.bvh");
  const motion::Motion one = content;
  for (int i = 0; i < 3; ++i) {  // 480 frames: 16 s at 30 Hz, far longer than the test.
    content.values.insert(content.values.end(), one.values.begin(), one.values.end());
    content.num_frames += one.num_frames;
  }
  const motion::Motion style = Sample("walk_old.bvh");

  // The live model (two frames of lookahead) and an offline one (a window
  // of 32 frames held back): a drain must flush both.
  std::vector<std::unique_ptr<StreamRun>> runs;
  for (const char* model : {"live", "live", "live", "contrastive", "contrastive", "contrastive"}) {
    runs.push_back(std::make_unique<StreamRun>());
    runs.back()->model = model;
  }
  std::vector<std::thread> threads;
  for (auto& run : runs) {
    threads.emplace_back(RunStream, server.address(), std::cref(content), std::cref(style),
                         run.get());
  }
  // Every stream is flowing (the offline ones have returned a window).
  for (int i = 0; i < 300; ++i) {
    bool flowing = true;
    for (auto& run : runs) flowing = flowing && run->outputs.load() >= 40;
    if (flowing) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const auto signalled = std::chrono::steady_clock::now();
  server.Signal(SIGTERM);
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(server.Wait(), 0);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
  EXPECT_LT(seconds, 15) << "the drain took the grace period: streams were not ended";

  for (const auto& run : runs) {
    SCOPED_TRACE(run->model);
    EXPECT_EQ(run->status.error_code(), grpc::StatusCode::UNAVAILABLE)
        << run->status.error_message();
    EXPECT_NE(run->status.error_message().find("shutting down"), std::string::npos)
        << run->status.error_message();
    ASSERT_GT(run->server_took, 0);
    EXPECT_LT(run->server_took, content.num_frames) << "the stream was not cut";
    EXPECT_LE(run->server_took, run->sent);
    // Every frame taken came back, once and in order.
    ASSERT_EQ(static_cast<int64_t>(run->indices.size()), run->server_took);
    for (size_t i = 0; i < run->indices.size(); ++i) ASSERT_EQ(run->indices[i], int64_t(i));
  }
}

}  // namespace
}  // namespace stylus::testing
