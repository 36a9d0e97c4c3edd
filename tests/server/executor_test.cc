// server/executor: a fixed pool that runs every accepted task, and none after
// Shutdown.
#include "server/executor.h"

#include <atomic>

#include "absl/synchronization/notification.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace stylus::server {
namespace {

TEST(ExecutorTest, RunsEveryAcceptedTaskOnItsThreads) {
  std::atomic<int> done{0};
  {
    Executor executor(3);
    EXPECT_EQ(executor.threads(), 3);
    for (int i = 0; i < 100; ++i) ASSERT_TRUE(executor.Submit([&done] { ++done; }));
  }  // The destructor runs what was accepted.
  EXPECT_EQ(done.load(), 100);
}

TEST(ExecutorTest, CountsQueuedAndRunningTasks) {
  Executor executor(1);
  absl::Notification release;
  std::atomic<bool> started{false};
  ASSERT_TRUE(executor.Submit([&] {
    started = true;
    release.WaitForNotification();
  }));
  ASSERT_TRUE(executor.Submit([] {}));
  ASSERT_TRUE(testing::WaitFor([&] { return started.load(); }));
  EXPECT_EQ(executor.running(), 1);
  EXPECT_EQ(executor.queued(), 1);
  release.Notify();
  ASSERT_TRUE(testing::WaitFor([&] { return executor.running() == 0 && executor.queued() == 0; }));
}

TEST(ExecutorTest, RefusesTasksAfterShutdownButRunsThoseAccepted) {
  std::atomic<int> done{0};
  Executor executor(1);
  absl::Notification release;
  ASSERT_TRUE(executor.Submit([&] { release.WaitForNotification(); }));
  ASSERT_TRUE(executor.Submit([&done] { ++done; }));
  executor.Shutdown();
  executor.Shutdown();  // Idempotent.
  EXPECT_FALSE(executor.Submit([&done] { done += 100; }));
  release.Notify();
  ASSERT_TRUE(testing::WaitFor([&] { return done.load() == 1; }));
  EXPECT_EQ(done.load(), 1);
}

TEST(ExecutorTest, AtLeastOneThread) {
  Executor executor(0);
  EXPECT_EQ(executor.threads(), 1);
  absl::Notification ran;
  ASSERT_TRUE(executor.Submit([&ran] { ran.Notify(); }));
  EXPECT_TRUE(ran.WaitForNotificationWithTimeout(absl::Seconds(30)));
}

}  // namespace
}  // namespace stylus::server
