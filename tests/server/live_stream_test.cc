// Live streams through a real server on localhost with the shipped live
// package: GetModel reports the lookahead, frames come back one to one at
// any capture rate, and steps batched across concurrent streams give the
// same frames as each stream stepping alone.
#include <grpcpp/grpcpp.h>

#include <future>
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "motion/kinematics.h"
#include "motion/resample.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus {
namespace {

using testing::Frames;
using testing::LiveServer;
using testing::Sample;

CallOptions Live(v1::PostProcess post = v1::POSTPROCESS_FULL) {
  CallOptions o;
  o.model = "live";
  o.postprocess = post;
  return o;
}

TEST(LiveStreamServerTest, GetModelReportsTheLookahead) {
  auto live = LiveServer::Start();
  ASSERT_NE(live, nullptr);
  auto info = live->client->GetModel("live");
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_EQ(info->id(), "live/v3");
  EXPECT_TRUE(info->live());
  EXPECT_EQ(info->lookahead(), 2);
  auto offline = live->client->GetModel("contrastive");
  ASSERT_TRUE(offline.ok());
  EXPECT_FALSE(offline->live());
  EXPECT_EQ(offline->lookahead(), 0);
}

// Streams `clips` concurrently (one thread each) and returns their outputs.
std::vector<motion::Motion> StreamAll(LiveServer* server, const std::vector<motion::Motion>& clips,
                                      const motion::Motion& style) {
  std::vector<std::future<absl::StatusOr<StreamResult>>> pending;
  for (const motion::Motion& c : clips) {
    pending.push_back(std::async(std::launch::async, [&server, &c, &style] {
      return server->client->Stream(c, {&style, ""}, 0, Live());
    }));
  }
  std::vector<motion::Motion> out;
  for (auto& p : pending) {
    absl::StatusOr<StreamResult> r = p.get();
    EXPECT_TRUE(r.ok()) << r.status();
    if (!r.ok()) return {};
    for (size_t i = 0; i < r->indices.size(); ++i)
      EXPECT_EQ(r->indices[i], static_cast<int64_t>(i));
    out.push_back(r->output);
  }
  return out;
}

TEST(LiveStreamServerTest, BatchedStepsGiveTheFramesOfStreamsSteppedAlone) {
  const motion::Motion style = Sample("walk_old.bvh");
  std::vector<motion::Motion> clips;
  for (int i = 0; i < 6; ++i) clips.push_back(Sample(i % 2 ? "run.bvh" : "walk_normal.bvh"));
  server::ServerOptions alone;
  alone.max_batch = 0;
  auto unbatched = LiveServer::Start(alone);
  ASSERT_NE(unbatched, nullptr);
  const std::vector<motion::Motion> a = StreamAll(unbatched.get(), clips, style);
  server::ServerOptions batched;
  batched.max_batch = 64;
  batched.max_queue_delay_us = 2000;
  auto with_batches = LiveServer::Start(batched);
  ASSERT_NE(with_batches, nullptr);
  const std::vector<motion::Motion> b = StreamAll(with_batches.get(), clips, style);
  ASSERT_EQ(a.size(), clips.size());
  ASSERT_EQ(b.size(), clips.size());
  for (size_t i = 0; i < clips.size(); ++i) {
    ASSERT_EQ(a[i].num_frames, clips[i].num_frames);
    ASSERT_EQ(b[i].num_frames, clips[i].num_frames);
    EXPECT_LT(motion::MaxPositionDifference(a[i], b[i]), 1e-2) << "stream " << i;
  }
  const server::ServerLoad load = with_batches->server->load();
  EXPECT_GT(load.batched_steps, load.batches) << "some batches held several streams' steps";
  std::printf("%lld steps in %lld batches\n", static_cast<long long>(load.batched_steps),
              static_cast<long long>(load.batches));
  EXPECT_EQ(unbatched->server->load().batches, 0);
}

TEST(LiveStreamServerTest, AHundredAndTwentyHertzStreamComesBackOneToOne) {
  auto live = LiveServer::Start();
  ASSERT_NE(live, nullptr);
  const motion::Motion style = Sample("walk_old.bvh");
  const motion::Motion content = motion::Resample(Sample("walk_normal.bvh"), 1.0 / 120);
  auto r = live->client->Stream(content, {&style, ""}, 0, Live());
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->output.num_frames, content.num_frames);
  EXPECT_NEAR(r->output.frame_time, 1.0 / 120, 1e-9);
  // The same motion as the clip streamed at 30 Hz, at the shared instants.
  auto at30 = live->client->Stream(Sample("walk_normal.bvh"), {&style, ""}, 0, Live());
  ASSERT_TRUE(at30.ok()) << at30.status();
  const motion::Motion back = motion::Resample(r->output, 1.0 / 30, at30->output.num_frames);
  const double gap = motion::MaxPositionDifference(back, at30->output);
  std::printf("120 Hz stream vs 30 Hz stream: max joint gap %.2f units\n", gap);
  EXPECT_LT(gap, 10.0);
}

}  // namespace
}  // namespace stylus

namespace stylus {
namespace {

using testing::Frames;
using testing::LiveServer;
using testing::Sample;

// A stream of `content` on `model` with `change` sent before frame `at`;
// returns the call's status and the frames received.
grpc::Status StreamWithChange(const std::string& address, const std::string& model,
                              const motion::Motion& content, const motion::Motion& style,
                              const v1::StyleChange& change, int at, motion::Motion* out) {
  auto stub =
      v1::StyleService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  auto stream = stub->TransferStream(&ctx);
  v1::StreamRequest config;
  config.mutable_config()->set_model(model);
  config.mutable_config()->set_fps(content.fps());
  wire::SkeletonToProto(content.skeleton, config.mutable_config()->mutable_skeleton());
  wire::ClipToProto(style, config.mutable_config()->mutable_style()->mutable_clip());
  std::thread writer([&] {
    if (!stream->Write(config)) return;
    for (int f = 0; f < content.num_frames; ++f) {
      if (f == at) {
        v1::StreamRequest r;
        *r.mutable_change() = change;
        if (!stream->Write(r)) return;
      }
      v1::StreamRequest r;
      wire::FrameToProto(content, f, f, r.mutable_frame());
      if (!stream->Write(r)) return;
    }
    stream->WritesDone();
  });
  *out = motion::RestMotion(content.skeleton, 0, content.frame_time);
  std::vector<motion::Vec3> prev(content.skeleton.num_joints());
  v1::StreamResponse r;
  while (stream->Read(&r)) EXPECT_TRUE(wire::AppendFrame(r.frame(), "out", &prev, out).ok());
  writer.join();
  return stream->Finish();
}

TEST(LiveControlServerTest, StyleChangesInAStreamAndTheirErrors) {
  auto live = LiveServer::Start();
  ASSERT_NE(live, nullptr);
  const motion::Motion content = Sample("walk_normal.bvh");
  const motion::Motion style = Sample("walk_old.bvh");
  ASSERT_TRUE(live->client->EncodeStyle(Sample("run.bvh"), "run", Live()).ok());
  v1::StyleChange change;
  change.set_from_frame(40);
  change.mutable_style()->set_name("run");
  change.set_fade_frames(10);
  motion::Motion changed, plain;
  grpc::Status s = StreamWithChange(live->address, "live", content, style, change, 40, &changed);
  ASSERT_TRUE(s.ok()) << s.error_message();
  ASSERT_EQ(changed.num_frames, content.num_frames);
  v1::StyleChange nothing;
  nothing.set_from_frame(200);  // Past the clip: never applies.
  nothing.set_strength(1);
  ASSERT_TRUE(StreamWithChange(live->address, "live", content, style, nothing, 1, &plain).ok());
  EXPECT_LT(motion::MaxPositionDifference(Frames(plain, 0, 40), Frames(changed, 0, 40)), 1e-3);
  EXPECT_GT(motion::MaxPositionDifference(Frames(plain, 60, 110), Frames(changed, 60, 110)), 1.0);

  // A blend over saved styles, and a strength.
  v1::StyleChange blend;
  blend.set_from_frame(20);
  blend.mutable_blend()->add_styles()->set_name("run");
  blend.mutable_blend()->add_styles()->mutable_clip();
  wire::ClipToProto(style, blend.mutable_blend()->mutable_styles(1)->mutable_clip());
  blend.mutable_blend()->add_weights(0.5);
  blend.mutable_blend()->add_weights(0.5);
  blend.set_strength(0.5);
  motion::Motion blended;
  EXPECT_TRUE(StreamWithChange(live->address, "live", content, style, blend, 20, &blended).ok());

  change.mutable_style()->set_name("nope");
  s = StreamWithChange(live->address, "live", content, style, change, 40, &changed);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND) << s.error_message();
  blend.mutable_blend()->add_weights(1);  // Three weights, two styles.
  s = StreamWithChange(live->address, "live", content, style, blend, 20, &changed);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << s.error_message();
  v1::StyleChange strong;
  strong.set_strength(2);
  s = StreamWithChange(live->address, "live", content, style, strong, 5, &changed);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << s.error_message();
  s = StreamWithChange(live->address, "contrastive", content, style, nothing, 5, &changed);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << s.error_message();
}

}  // namespace
}  // namespace stylus
