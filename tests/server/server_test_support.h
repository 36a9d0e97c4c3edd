// A real Stylus server on localhost:0 (in this process) with the repository's
// models, and a client connected to it.
#ifndef STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
#define STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <string>

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

// The body of GET http://127.0.0.1:port/path ("" when it cannot connect).
inline std::string HttpGetBody(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
    const std::string request = "GET " + path + " HTTP/1.0\r\nHost: localhost\r\n\r\n";
    if (write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size())) {
      char buf[65536];
      for (ssize_t n; (n = read(fd, buf, sizeof(buf))) > 0;) out.append(buf, n);
    }
  }
  close(fd);
  const size_t body = out.find("\r\n\r\n");
  return body == std::string::npos ? "" : out.substr(body + 4);
}

inline motion::Motion Sample(const std::string& name) {
  return *motion::ReadBvhFile(SourceDir() + "/samples/" + name);
}

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_SERVER_SERVER_TEST_SUPPORT_H_
