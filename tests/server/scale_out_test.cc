// Scale-out: one client target naming three real servers on three loopback
// addresses; calls go round-robin over them, and go on when one shuts down.
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

// ListModels calls the server at `metrics_port` has answered OK.
int ListModelsServed(int metrics_port) {
  const std::string text = bench::HttpGet(metrics_port, "/metrics");
  int n = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    if (!absl::StartsWith(line, "grpc_server_handled_total{") ||
        !absl::StrContains(line, "grpc_method=\"ListModels\"") ||
        !absl::StrContains(line, "grpc_code=\"OK\"")) {
      continue;
    }
    double value = 0;
    if (absl::SimpleAtod(line.substr(line.rfind(' ') + 1), &value)) n += static_cast<int>(value);
  }
  return n;
}

TEST(ScaleOutTest, CallsSpreadOverEveryAddressAndSurviveAServerShuttingDown) {
  std::vector<std::unique_ptr<server::StylusServer>> servers;
  std::vector<std::string> addresses;
  for (int i = 1; i <= 3; ++i) {
    server::ServerOptions options;
    options.models_dir = SourceDir() + "/models";
    options.listen = "127.0.0." + std::to_string(i) + ":0";
    options.metrics_listen = "127.0.0.1:0";
    absl::StatusOr<std::unique_ptr<server::StylusServer>> s = server::StylusServer::Start(options);
    ASSERT_TRUE(s.ok()) << s.status();
    addresses.push_back("127.0.0." + std::to_string(i) + ":" + std::to_string((*s)->port()));
    servers.push_back(*std::move(s));
  }
  ClientOptions options;
  options.address = "ipv4:" + addresses[0] + "," + addresses[1] + "," + addresses[2];
  Client client(options);

  for (int i = 0; i < 30; ++i) ASSERT_TRUE(client.ListModels().ok()) << "call " << i;
  std::vector<int> served;
  for (const auto& s : servers) served.push_back(ListModelsServed(s->metrics_port()));
  EXPECT_EQ(served[0] + served[1] + served[2], 30);
  for (int n : served)
    EXPECT_GE(n, 5) << "round-robin left a server idle: " << served[0] << ", " << served[1] << ", "
                    << served[2];
  // Real work too: a transfer through the shared target.
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  ASSERT_TRUE(client.Transfer(walk, {&old, ""}).ok());

  // One server goes; every call still succeeds, on the other two.
  servers[1]->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
  servers[1]->Wait();
  const int before0 = ListModelsServed(servers[0]->metrics_port());
  const int before2 = ListModelsServed(servers[2]->metrics_port());
  for (int i = 0; i < 30; ++i) ASSERT_TRUE(client.ListModels().ok()) << "call " << i << " after";
  const int after0 = ListModelsServed(servers[0]->metrics_port()) - before0;
  const int after2 = ListModelsServed(servers[2]->metrics_port()) - before2;
  EXPECT_EQ(after0 + after2, 30);
  EXPECT_GE(after0, 5);
  EXPECT_GE(after2, 5);
}

}  // namespace
}  // namespace stylus::testing
