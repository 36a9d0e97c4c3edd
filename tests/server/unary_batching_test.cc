// Concurrent unary transfers on a real server, their network passes batched
// (--max-batch), against the same calls on a server that runs each alone.
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "motion/kinematics.h"
#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

TEST(UnaryBatchingServerTest, ConcurrentTransfersBatchedEqualTransfersRunAlone) {
  const motion::Motion style = Sample("walk_old.bvh");
  const std::vector<motion::Motion> contents = {Sample("walk_normal.bvh"), Sample("run.bvh"),
                                                Sample("walk_normal.bvh"), Sample("run.bvh")};
  server::ServerOptions alone;
  alone.threads = 4;
  alone.max_batch = 0;
  auto unbatched = LiveServer::Start(alone);
  ASSERT_NE(unbatched, nullptr);
  std::vector<motion::Motion> a;
  for (const motion::Motion& c : contents) {
    absl::StatusOr<motion::Motion> r = unbatched->client->Transfer(c, {&style, ""});
    ASSERT_TRUE(r.ok()) << r.status();
    a.push_back(*r);
  }
  EXPECT_EQ(unbatched->server->load().unary_batches, 0);

  server::ServerOptions batched;
  batched.threads = 4;
  batched.max_batch = 256;
  batched.batch_unary = true;
  batched.max_queue_delay_us = 300000;  // Long: the four calls' passes meet.
  auto with_batches = LiveServer::Start(batched);
  ASSERT_NE(with_batches, nullptr);
  std::vector<motion::Motion> b(contents.size());
  std::vector<std::thread> callers;
  for (size_t i = 0; i < contents.size(); ++i) {
    callers.emplace_back([&, i] {
      ClientOptions options;
      options.address = with_batches->address;
      Client client(options);
      absl::StatusOr<motion::Motion> r = client.Transfer(contents[i], {&style, ""});
      ASSERT_TRUE(r.ok()) << r.status();
      b[i] = *r;
    });
  }
  for (auto& t : callers) t.join();
  for (size_t i = 0; i < contents.size(); ++i) {
    ASSERT_EQ(b[i].num_frames, a[i].num_frames);
    EXPECT_LT(motion::MaxPositionDifference(a[i], b[i]), 1e-2) << "call " << i;
  }
  const server::ServerLoad load = with_batches->server->load();
  EXPECT_GT(load.unary_batches, 0);
  EXPECT_GT(load.batched_calls, load.unary_batches) << "batches held several calls";
  std::printf("%lld calls' passes in %lld batches\n", static_cast<long long>(load.batched_calls),
              static_cast<long long>(load.unary_batches));
}

}  // namespace
}  // namespace stylus::testing
