// A real Stylus server on localhost:0 (in this process) with the repository's
// models, and a client connected to it.
#ifndef STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
#define STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_

#include <memory>
#include <string>

#include "bench/bench_support.h"
#include "client/client.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "server/server.h"
#include "tests/test_support.h"

namespace stylus::testing {

struct LiveServer {
  std::unique_ptr<server::StylusServer> server;
  std::unique_ptr<Client> client;
  std::string address;

  static std::unique_ptr<LiveServer> Start(server::ServerOptions options = {}) {
    if (options.models_dir == "models") options.models_dir = SourceDir() + "/models";
    options.listen = "localhost:0";
    auto s = std::make_unique<LiveServer>();
    absl::StatusOr<std::unique_ptr<server::StylusServer>> started =
        server::StylusServer::Start(options);
    EXPECT_TRUE(started.ok()) << started.status();
    if (!started.ok()) return nullptr;
    s->server = *std::move(started);
    s->address = "localhost:" + std::to_string(s->server->port());
    ClientOptions c;
    c.address = s->address;
    s->client = std::make_unique<Client>(c);
    return s;
  }
};

inline motion::Motion Sample(const std::string& name) {
  return *motion::ReadBvhFile(SourceDir() + "/samples/" + name);
}

// `m` played `times` times over (positions jump back at each repeat: fine
// for load, not for looks).
inline motion::Motion Repeat(const motion::Motion& m, int times) {
  motion::Motion out = m;
  out.num_frames = m.num_frames * times;
  out.values.clear();
  for (int i = 0; i < times; ++i)
    out.values.insert(out.values.end(), m.values.begin(), m.values.end());
  return out;
}

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
