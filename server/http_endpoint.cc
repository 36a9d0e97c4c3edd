#include "server/http_endpoint.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace stylus::server {
namespace {

constexpr size_t kMaxRequest = 8192;
constexpr int kRequestTimeoutMs = 1000;
constexpr size_t kMaxClients = 64;
constexpr int kSendTimeoutMs = 1000;

// Sends `data` on a non-blocking socket, giving up after kSendTimeoutMs (a
// client that does not read its answer).
void SendAll(int fd, const std::string& data) {
  size_t sent = 0;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(kSendTimeoutMs);
  while (sent < data.size()) {
    const ssize_t n = send(fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      sent += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return;
    const int left = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                          deadline - std::chrono::steady_clock::now())
                                          .count());
    pollfd p{fd, POLLOUT, 0};
    if (left <= 0 || poll(&p, 1, left) <= 0) return;
  }
}

std::string Response(int code, const char* reason, const std::string& body) {
  return absl::StrCat("HTTP/1.1 ", code, " ", reason,
                      "\r\nContent-Type: text/plain; version=0.0.4; charset=utf-8\r\n"
                      "Content-Length: ",
                      body.size(), "\r\nConnection: close\r\n\r\n", body);
}

}  // namespace

absl::StatusOr<std::unique_ptr<HttpEndpoint>> HttpEndpoint::Start(
    const std::string& listen, const std::string& path, std::function<std::string()> body) {
  const size_t colon = listen.rfind(':');
  int port = -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  std::string host = colon == std::string::npos ? "" : listen.substr(0, colon);
  if (host == "localhost") host = "127.0.0.1";
  if (host.empty()) host = "0.0.0.0";
  if (colon == std::string::npos || !absl::SimpleAtoi(listen.substr(colon + 1), &port) ||
      port < 0 || port > 65535 || inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("'", listen, "' is not HOST:PORT (an IPv4 address or localhost)"));
  }
  addr.sin_port = htons(static_cast<uint16_t>(port));
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return absl::UnavailableError(absl::StrCat("socket: ", std::strerror(errno)));
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  socklen_t len = sizeof(addr);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 || ::listen(fd, 16) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    const std::string error = std::strerror(errno);
    close(fd);
    return absl::UnavailableError(absl::StrCat("cannot listen on ", listen, ": ", error));
  }
  return std::unique_ptr<HttpEndpoint>(
      new HttpEndpoint(fd, ntohs(addr.sin_port), path, std::move(body)));
}

HttpEndpoint::HttpEndpoint(int fd, int port, std::string path, std::function<std::string()> body)
    : fd_(fd), port_(port), path_(std::move(path)), body_(std::move(body)) {
  thread_ = std::thread([this] { Loop(); });
}

HttpEndpoint::~HttpEndpoint() {
  stopping_ = true;
  thread_.join();
  close(fd_);
}

void HttpEndpoint::Loop() {
  // Every connection is served from this one loop, none waited for: a
  // client that sends nothing (or half a request) holds only its slot until
  // its deadline, and never delays another's scrape.
  struct Client {
    int fd;
    std::string request;
    std::chrono::steady_clock::time_point deadline;
  };
  std::vector<Client> clients;
  while (!stopping_) {
    std::vector<pollfd> polled;
    polled.push_back({fd_, POLLIN, 0});
    for (const Client& c : clients) polled.push_back({c.fd, POLLIN, 0});
    const int n =
        poll(polled.data(), polled.size(), 50);  // Wakes to check stopping_ and deadlines.
    const auto now = std::chrono::steady_clock::now();
    std::vector<Client> open;
    for (size_t i = 0; i < clients.size(); ++i) {
      Client& c = clients[i];
      bool keep = now < c.deadline;
      if (keep && n > 0 && (polled[i + 1].revents & (POLLIN | POLLHUP | POLLERR))) {
        char buf[2048];
        const ssize_t got = recv(c.fd, buf, sizeof(buf), MSG_DONTWAIT);
        if (got <= 0) {
          keep = false;
        } else {
          c.request.append(buf, static_cast<size_t>(got));
          if (c.request.find("\r\n\r\n") != std::string::npos) {
            Answer(c.fd, c.request);
            keep = false;
          } else if (c.request.size() > kMaxRequest) {
            keep = false;
          }
        }
      }
      if (keep) {
        open.push_back(std::move(c));
      } else {
        close(c.fd);
      }
    }
    clients = std::move(open);
    if (n > 0 && (polled[0].revents & POLLIN)) {
      const int client = accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (client >= 0) {
        if (clients.size() >= kMaxClients) {  // The oldest goes.
          close(clients.front().fd);
          clients.erase(clients.begin());
        }
        clients.push_back({client, "", now + std::chrono::milliseconds(kRequestTimeoutMs)});
      }
    }
  }
  for (const Client& c : clients) close(c.fd);
}

void HttpEndpoint::Answer(int client, const std::string& request) {
  const size_t line_end = request.find("\r\n");
  const std::string line = request.substr(0, line_end);
  const size_t sp1 = line.find(' '), sp2 = line.find(' ', sp1 + 1);
  if (sp1 == std::string::npos || sp2 == std::string::npos) {
    SendAll(client, Response(400, "Bad Request", "bad request line\n"));
    return;
  }
  const std::string method = line.substr(0, sp1), target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  if (method != "GET") {
    SendAll(client, Response(405, "Method Not Allowed", "only GET\n"));
  } else if (target != path_ && target.rfind(path_ + "?", 0) != 0) {
    SendAll(client, Response(404, "Not Found", absl::StrCat("metrics are at ", path_, "\n")));
  } else {
    SendAll(client, Response(200, "OK", body_()));
  }
}

}  // namespace stylus::server
