// The limits that protect the process, each on a real server with the
// repository's models: frames and joints per call, saved styles per model,
// unary calls in flight, stream idle timeout (and shutdown with idle
// alarms set), LoadModel names.
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <thread>
#include <vector>

#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus::testing {
namespace {

motion::Motion Head(const motion::Motion& m, int frames) {
  motion::Motion out = m;
  out.num_frames = frames;
  out.values.resize(static_cast<size_t>(frames) * m.skeleton.num_channels());
  return out;
}

TEST(LimitsTest, ClipsOverTheFrameCapAreRefusedBeforeAnyWork) {
  server::ServerOptions options;
  options.max_clip_frames = 100;
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  ASSERT_GT(walk.num_frames, 100);
  const motion::Motion style = Head(old, 100);

  absl::StatusOr<motion::Motion> out = live->client->Transfer(walk, {&style, ""});
  EXPECT_EQ(out.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(out.status().message().find("content.frames: more than 100"), std::string::npos)
      << out.status();
  EXPECT_NE(out.status().message().find("--max-clip-frames"), std::string::npos);
  // The style clip counts too, and so do EncodeStyle and ComputeMetrics.
  const motion::Motion content = Head(walk, 100);
  EXPECT_EQ(live->client->Transfer(content, {&old, ""}).status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(live->client->EncodeStyle(old).status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(live->client->ComputeMetrics(walk, nullptr, nullptr).status().code(),
            absl::StatusCode::kResourceExhausted);
  // At the cap: served.
  out = live->client->Transfer(content, {&style, ""});
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, 100);
}

TEST(LimitsTest, SkeletonsOverTheJointCapAreRefusedInCallsAndStreams) {
  server::ServerOptions options;
  options.max_joints = 10;
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  ASSERT_GT(walk.skeleton.num_joints(), 10);
  absl::Status s = live->client->Transfer(walk, {&old, ""}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(s.message().find("--max-joints"), std::string::npos) << s;
  s = live->client->Stream(Head(walk, 10), {&old, ""}, 0).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(s.message().find("config."), std::string::npos) << s;
}

TEST(LimitsTest, SavedStylesPerModelAreCapped) {
  server::ServerOptions options;
  options.max_saved_styles = 2;
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion old = Sample("walk_old.bvh");
  ASSERT_TRUE(live->client->EncodeStyle(old, "a").ok());
  ASSERT_TRUE(live->client->EncodeStyle(old, "b").ok());
  absl::Status s = live->client->EncodeStyle(old, "c").status();
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(s.message().find("--max-saved-styles"), std::string::npos) << s;
  EXPECT_TRUE(live->client->EncodeStyle(old, "a").ok());  // Saving over a name is fine.
  CallOptions cyclic;
  cyclic.model = "cyclic";
  EXPECT_TRUE(live->client->EncodeStyle(old, "c", cyclic).ok());  // Another model's own cap.
  // Unsaved codes are not capped.
  EXPECT_TRUE(live->client->EncodeStyle(old).ok());
}

TEST(LimitsTest, UnaryCallsOverTheCapAreRefusedAndTheCountComesBack) {
  server::ServerOptions options;
  options.threads = 1;
  options.max_unary_calls = 2;
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion long_walk = Repeat(Sample("walk_normal.bvh"), 8);
  const motion::Motion old = Sample("walk_old.bvh");
  constexpr int kCalls = 8;
  std::vector<absl::Status> results(kCalls);
  std::vector<std::thread> callers;
  std::atomic<int> ready{0};
  for (int i = 0; i < kCalls; ++i) {
    callers.emplace_back([&, i] {
      ++ready;
      while (ready.load() < kCalls) std::this_thread::yield();
      results[i] = live->client->Transfer(long_walk, {&old, ""}).status();
    });
  }
  for (std::thread& t : callers) t.join();
  int ok = 0, refused = 0;
  for (const absl::Status& s : results) {
    if (s.ok()) ++ok;
    if (s.code() == absl::StatusCode::kResourceExhausted) {
      ++refused;
      EXPECT_NE(s.message().find("--max-unary-calls"), std::string::npos) << s;
    }
  }
  EXPECT_GE(ok, 1);
  EXPECT_GE(refused, 1);
  EXPECT_EQ(ok + refused, kCalls);
  // Every accepted call was answered and un-counted: two at once get in again.
  std::thread second([&] { EXPECT_TRUE(live->client->ListModels().ok()); });
  EXPECT_TRUE(live->client->ListModels().ok());
  second.join();
}

TEST(LimitsTest, AStreamWhoseClientFallsSilentIsClosed) {
  server::ServerOptions options;
  options.stream_idle_timeout_s = 0.5;
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");

  // A config, then nothing: the server ends the stream.
  auto stub = v1::StyleService::NewStub(
      grpc::CreateChannel(live->address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  auto stream = stub->TransferStream(&ctx);
  v1::StreamRequest config;
  config.mutable_config()->set_fps(walk.fps());
  wire::SkeletonToProto(walk.skeleton, config.mutable_config()->mutable_skeleton());
  wire::ClipToProto(old, config.mutable_config()->mutable_style()->mutable_clip());
  ASSERT_TRUE(stream->Write(config));
  const auto t0 = std::chrono::steady_clock::now();
  v1::StreamResponse response;
  while (stream->Read(&response)) {
  }
  const grpc::Status s = stream->Finish();
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(s.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << s.error_message();
  EXPECT_NE(s.error_message().find("--stream-idle-timeout-s"), std::string::npos);
  EXPECT_LT(waited, 20);  // Closed by the server, long before the client's deadline.
  // The session is freed once gRPC is done with it, just after the status.
  for (int i = 0; i < 500 && live->server->load().open_streams > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(live->server->load().open_streams, 0);

  // A client that keeps sending (30 Hz for 2 s, four times the timeout) is not idle.
  absl::StatusOr<StreamResult> streamed = live->client->Stream(Head(walk, 60), {&old, ""}, 30);
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  EXPECT_EQ(streamed->output.num_frames, 60);
}

// A stream with an idle timeout holds an alarm; when its call ends, the
// session lives on until the alarm's cancelled callback has run. Shutdown
// returns only once every session is gone: a session that outlived the
// server would count itself out of freed memory.
TEST(LimitsTest, ShutdownReturnsOnlyOnceEveryStreamSessionIsGone) {
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  v1::StreamRequest config;
  config.mutable_config()->set_fps(walk.fps());
  wire::SkeletonToProto(walk.skeleton, config.mutable_config()->mutable_skeleton());
  wire::ClipToProto(old, config.mutable_config()->mutable_style()->mutable_clip());
  server::ServerOptions options;
  options.stream_idle_timeout_s = 30;
  // The window is short (a callback due at once), so a few servers in turn.
  for (int round = 0; round < 4; ++round) {
    std::unique_ptr<LiveServer> live = LiveServer::Start(options);
    ASSERT_NE(live, nullptr);
    auto stub = v1::StyleService::NewStub(
        grpc::CreateChannel(live->address, grpc::InsecureChannelCredentials()));
    // Streams that end every way a call can: half of them ended by their
    // client, the other half cancelled as the server shuts down.
    constexpr int kStreams = 128;
    std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
    std::vector<
        std::unique_ptr<grpc::ClientReaderWriter<v1::StreamRequest, v1::StreamResponse>>>
        streams;
    for (int i = 0; i < kStreams; ++i) {
      contexts.push_back(std::make_unique<grpc::ClientContext>());
      streams.push_back(stub->TransferStream(contexts.back().get()));
      ASSERT_TRUE(streams.back()->Write(config));
    }
    for (int i = 0; i < kStreams; i += 2) {
      ASSERT_TRUE(streams[i]->WritesDone());
      v1::StreamResponse response;
      while (streams[i]->Read(&response)) {
      }
      EXPECT_TRUE(streams[i]->Finish().ok());
    }
    for (int i = 1; i < kStreams; i += 2) contexts[i]->TryCancel();
    live->server->Shutdown(std::chrono::system_clock::now());
    ASSERT_EQ(live->server->load().open_streams, 0) << "round " << round;
  }
}

TEST(LimitsTest, LoadModelTakesOnlyNamesInsideTheModelDirectory) {
  std::unique_ptr<LiveServer> live = LiveServer::Start();
  ASSERT_NE(live, nullptr);
  for (const std::string name :
       {"../models/contrastive/v8", "contrastive/../../models", "/etc/passwd",
        "contrastive/v8/../v7", "./contrastive/v8", "contrastive\\v8", "contrastive//v8", ""}) {
    const absl::Status s = live->client->LoadModel(name).status();
    EXPECT_TRUE(s.code() == absl::StatusCode::kInvalidArgument ||
                s.code() == absl::StatusCode::kNotFound)
        << "'" << name << "': " << s;
  }
}

}  // namespace
}  // namespace stylus::testing
