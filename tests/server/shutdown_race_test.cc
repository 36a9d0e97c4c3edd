// Shutdown against work in flight, on real in-process servers, repeated:
// a large unary reply being sent when shutdown begins reaches its client
// whole; a grace that expires while live streams' tasks are queued on the
// executor (and reach for the step batcher) ends every stream without
// touching what is gone, and streams refused because shutdown began are
// finished once (the sanitized run of this binary checks that).
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

namespace fs = std::filesystem;

// A models directory with the default package alone (fast to load).
std::string DefaultOnlyModels() {
  // This process's own folder: another checkout's (or an older run's, whose
  // link may point at a package since renamed) is never taken for it.
  const fs::path root =
      fs::temp_directory_path() / ("stylus_shutdown_race_models_" + std::to_string(::getpid()));
  if (!fs::exists(root / DefaultPackage())) {
    fs::remove_all(root);
    fs::create_directories((root / DefaultPackage()).parent_path());
    fs::create_directory_symlink(DefaultPackageDir(), root / DefaultPackage());
    fs::copy_file(SourceDir() + "/models/DEFAULT", root / "DEFAULT",
                  fs::copy_options::overwrite_existing);
  }
  return root.string();
}

TEST(ShutdownRaceTest, ALargeReplyBeingSentAtShutdownArrivesWhole) {
  const motion::Motion content = Repeat(Sample("walk_normal.bvh"), 26);  // 3120 frames.
  ASSERT_EQ(content.num_frames, 3120);
  const motion::Motion style = Sample("walk_old.bvh");
  CallOptions options;
  options.postprocess = v1::POSTPROCESS_NONE;
  constexpr int kRounds = 50;
  int whole = 0;
  for (int round = 0; round < kRounds; ++round) {
    server::ServerOptions o;
    o.models_dir = DefaultOnlyModels();
    std::unique_ptr<LiveServer> live = LiveServer::Start(o);
    ASSERT_NE(live, nullptr);
    absl::StatusOr<motion::Motion> out;
    std::thread caller([&] { out = live->client->Transfer(content, {&style, ""}, options); });
    // Shutdown begins while the call computes or sends its reply.
    for (int i = 0; i < 10000 && live->server->load().running_tasks == 0 &&
                    live->server->load().queued_tasks == 0;
         ++i) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(round % 10 * 20));
    live->server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(30));
    caller.join();
    if (out.ok() && out->num_frames == content.num_frames) {
      ++whole;
    } else {
      ADD_FAILURE() << "round " << round << ": " << out.status();
    }
  }
  EXPECT_EQ(whole, kRounds);
}

TEST(ShutdownRaceTest, GraceExpiringWithStreamTasksQueuedEndsEveryStream) {
  const motion::Motion walk = Repeat(Sample("walk_normal.bvh"), 4);
  const motion::Motion style = Sample("walk_old.bvh");
  for (int round = 0; round < 10; ++round) {
    server::ServerOptions o;
    o.threads = 1;  // Stream tasks queue behind one another.
    std::unique_ptr<LiveServer> live = LiveServer::Start(o);
    ASSERT_NE(live, nullptr);
    constexpr int kStreams = 8;
    std::vector<std::thread> streams;
    std::atomic<int> started{0}, ended{0};
    for (int i = 0; i < kStreams; ++i) {
      streams.emplace_back([&] {
        ClientOptions c;
        c.address = live->address;
        Client client(c);
        CallOptions call;
        call.model = "live";
        ++started;
        (void)client.Stream(walk, {&style, ""}, 0, call);
        ++ended;
      });
    }
    for (int i = 0; i < 20000 && live->server->load().queued_tasks < 2; ++i) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    // No grace: what is queued meets a server already going.
    live->server->Shutdown(std::chrono::system_clock::now());
    for (std::thread& t : streams) t.join();
    EXPECT_EQ(ended.load(), kStreams);
    EXPECT_EQ(live->server->load().open_streams, 0);
  }
}

}  // namespace
}  // namespace stylus::testing
