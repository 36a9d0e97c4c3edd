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

namespace stylus {
namespace {

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
  EXPECT_EQ(info->id(), "live/v1");
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
    for (size_t i = 0; i < r->indices.size(); ++i) EXPECT_EQ(r->indices[i], static_cast<int64_t>(i));
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
