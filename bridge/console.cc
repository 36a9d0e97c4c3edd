#include "bridge/console.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "bridge/bridge.h"

namespace stylus::bridge {

extern const char kConsolePage[];  // console.html, compiled in by CMake.

namespace {

constexpr size_t kMaxRequest = 16 * 1024;

void Reply(int fd, const std::string& status, const std::string& type, const std::string& body) {
  std::string out = absl::StrCat("HTTP/1.1 ", status, "\r\nContent-Type: ", type,
                                 "\r\nContent-Length: ", body.size(),
                                 "\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n", body);
  size_t sent = 0;
  while (sent < out.size()) {
    ssize_t n = ::send(fd, out.data() + sent, out.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;
    sent += static_cast<size_t>(n);
  }
}

std::string UrlDecode(absl::string_view in) {
  std::string out;
  for (size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '+') {
      out += ' ';
    } else if (in[i] == '%' && i + 2 < in.size()) {
      int v = 0;
      if (absl::SimpleHexAtoi(in.substr(i + 1, 2), &v)) {
        out += static_cast<char>(v);
        i += 2;
      } else {
        out += in[i];
      }
    } else {
      out += in[i];
    }
  }
  return out;
}

}  // namespace

absl::Status Console::Start(const std::string& address) {
  if (!std::ifstream(three_js_).good()) {
    return absl::FailedPreconditionError(absl::StrCat(
        three_js_,
        " not found: the console needs three.js (Debian's libjs-three), or --three-js PATH"));
  }
  std::vector<std::string> parts = absl::StrSplit(address, absl::MaxSplits(':', 1));
  int port = -1;
  if (parts.size() != 2 || !absl::SimpleAtoi(parts[1], &port) || port < 0 || port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("--console ", address, ": expected HOST:PORT"));
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, parts[0] == "localhost" ? "127.0.0.1" : parts[0].c_str(),
                &addr.sin_addr) != 1) {
    return absl::InvalidArgumentError(absl::StrCat("--console ", address, ": not an IPv4 address"));
  }
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
  int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listen_fd_, 16) != 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    return absl::UnavailableError(absl::StrCat("--console ", address, ": cannot listen (in use?)"));
  }
  socklen_t len = sizeof(addr);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  thread_ = std::thread([this] { Serve(); });
  return absl::OkStatus();
}

void Console::Stop() {
  if (stop_.exchange(true)) return;
  if (thread_.joinable()) thread_.join();
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

void Console::Serve() {
  while (!stop_.load()) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int fd = ::accept(listen_fd_, nullptr, nullptr);
    if (fd < 0) continue;
    timeval timeout{2, 0};  // A slow or silent client cannot hold the console.
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    Handle(fd);
    ::close(fd);
  }
}

void Console::Handle(int fd) {
  std::string request;
  char buffer[4096];
  size_t header_end = std::string::npos;
  size_t content_length = 0;
  while (request.size() < kMaxRequest) {
    ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    request.append(buffer, static_cast<size_t>(n));
    if (header_end == std::string::npos) {
      header_end = request.find("\r\n\r\n");
      if (header_end != std::string::npos) {
        for (absl::string_view line : absl::StrSplit(request.substr(0, header_end), "\r\n")) {
          if (line.size() > 15 && strncasecmp(line.data(), "content-length:", 15) == 0) {
            size_t v = 0;
            if (absl::SimpleAtoi(absl::StripAsciiWhitespace(line.substr(15)), &v))
              content_length = v;
          }
        }
      }
    }
    if (header_end != std::string::npos && request.size() >= header_end + 4 + content_length) break;
  }
  if (header_end == std::string::npos || content_length > kMaxRequest) {
    Reply(fd, "400 Bad Request", "text/plain", "bad request\n");
    return;
  }
  const std::string line = request.substr(0, request.find("\r\n"));
  const std::string body = request.substr(header_end + 4, content_length);
  if (absl::StartsWith(line, "GET / ") || absl::StartsWith(line, "GET /index.html ")) {
    Reply(fd, "200 OK", "text/html; charset=utf-8", kConsolePage);
  } else if (absl::StartsWith(line, "GET /three.min.js ")) {
    std::ifstream in(three_js_);
    std::stringstream js;
    js << in.rdbuf();
    Reply(fd, "200 OK", "application/javascript", js.str());
  } else if (absl::StartsWith(line, "GET /state ")) {
    Reply(fd, "200 OK", "application/json", bridge_->StateJson());
  } else if (absl::StartsWith(line, "POST /control ")) {
    std::string reply = "ok\n";
    for (absl::string_view pair : absl::StrSplit(body, '&', absl::SkipEmpty())) {
      std::vector<std::string> kv = absl::StrSplit(pair, absl::MaxSplits('=', 1));
      if (kv.size() != 2) continue;
      const std::string value = UrlDecode(kv[1]);
      double k;
      if (kv[0] == "style" && !value.empty()) {
        bridge_->ChangeStyle(value);
      } else if (kv[0] == "strength" && absl::SimpleAtod(value, &k) && k >= 0 && k <= 1) {
        bridge_->ChangeStrength(k);
      } else {
        reply = "expected style=NAME or strength=0..1\n";
      }
    }
    Reply(fd, reply == "ok\n" ? "200 OK" : "400 Bad Request", "text/plain", reply);
  } else {
    Reply(fd, "404 Not Found", "text/plain", "not found\n");
  }
}

}  // namespace stylus::bridge
