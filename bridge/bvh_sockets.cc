// stylus-bridge's BVH broadcast sockets (bridge/bvh_broadcast.h has the
// format): the text form read from the capture software, the binary form on
// a UDP port, the text form served to engines, the binary form sent on.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bridge/bridge.h"
#include "spdlog/spdlog.h"

namespace stylus::bridge {

namespace {

// A TCP connection to "host:port", or -1.
int ConnectTcp(const std::string& host, const std::string& port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0) return -1;
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd >= 0 && connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      close(fd);
      fd = -1;
    }
  }
  freeaddrinfo(found);
  if (fd >= 0) {
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  }
  return fd;
}

// A socket bound to `port` on every interface (SOCK_DGRAM or SOCK_STREAM,
// listening), or -1; `bound` gets the port (for port 0).
int Bind(int type, int port, int* bound) {
  const int fd = socket(AF_INET, type, 0);
  if (fd < 0) return -1;
  int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  a.sin_port = htons(static_cast<uint16_t>(port));
  socklen_t len = sizeof a;
  if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      (type == SOCK_STREAM && listen(fd, 16) != 0) ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    close(fd);
    return -1;
  }
  *bound = ntohs(a.sin_port);
  return fd;
}

}  // namespace

absl::Status Bridge::StartBvh() {
  std::string host, port;
  if (!options_.bvh_in.empty() && !SplitHostPort(options_.bvh_in, &host, &port)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--bvh-in ", options_.bvh_in, ": expected HOST:PORT"));
  }
  if (!options_.bvh_out_udp.empty()) {
    if (!SplitHostPort(options_.bvh_out_udp, &host, &port)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--bvh-out-udp ", options_.bvh_out_udp, ": expected HOST:PORT"));
    }
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    addrinfo* found = nullptr;
    if (getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0 || found == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("--bvh-out-udp ", options_.bvh_out_udp, ": cannot resolve ", host));
    }
    const auto* addr = reinterpret_cast<const unsigned char*>(found->ai_addr);
    bvh_send_addr_.assign(addr, addr + found->ai_addrlen);
    freeaddrinfo(found);
    bvh_send_fd_ = socket(AF_INET, SOCK_DGRAM, 0);
  }
  if (options_.bvh_in_udp >= 0) {
    bvh_udp_fd_ = Bind(SOCK_DGRAM, options_.bvh_in_udp, &bvh_udp_port_);
    if (bvh_udp_fd_ < 0) {
      return absl::UnavailableError(absl::StrCat("--bvh-in-udp ", options_.bvh_in_udp,
                                                 ": cannot bind the UDP port (in use?)"));
    }
  }
  if (options_.bvh_out_port >= 0) {
    bvh_listen_fd_ = Bind(SOCK_STREAM, options_.bvh_out_port, &bvh_out_port_);
    if (bvh_listen_fd_ < 0) {
      return absl::UnavailableError(absl::StrCat("--bvh-out ", options_.bvh_out_port,
                                                 ": cannot listen on the TCP port (in use?)"));
    }
    bvh_threads_.emplace_back([this] { BvhOutLoop(); });
  }
  if (!options_.bvh_in.empty()) bvh_threads_.emplace_back([this] { BvhTextLoop(); });
  if (bvh_udp_fd_ >= 0) bvh_threads_.emplace_back([this] { BvhUdpLoop(); });
  return absl::OkStatus();
}

// Reads the capture software's text stream; while it is away (not started
// yet, restarted) tries again every half second.
void Bridge::BvhTextLoop() {
  std::string host, port;
  SplitHostPort(options_.bvh_in, &host, &port);
  bool said_away = false;
  while (!stop_.load()) {
    const int fd = ConnectTcp(host, port);
    if (fd < 0) {
      if (!said_away)
        spdlog::warn("BVH broadcast {}: not reachable; trying every 0.5 s", options_.bvh_in);
      said_away = true;
      for (int i = 0; i < 25 && !stop_.load(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    spdlog::info("BVH broadcast {}: connected", options_.bvh_in);
    said_away = false;
    BroadcastTextReader reader;
    char buf[16384];
    while (!stop_.load()) {
      pollfd pfd{fd, POLLIN, 0};
      if (poll(&pfd, 1, 20) <= 0) continue;
      const ssize_t n = recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      const int64_t bad = reader.malformed();
      for (BroadcastFrame& f : reader.Feed(absl::string_view(buf, static_cast<size_t>(n)))) {
        OnBroadcast(std::move(f));
      }
      if (reader.malformed() != bad) {
        absl::MutexLock lock(&mu_);
        stats_.malformed += reader.malformed() - bad;
      }
    }
    close(fd);
    if (!stop_.load())
      spdlog::warn("BVH broadcast {}: connection closed; reconnecting", options_.bvh_in);
  }
}

void Bridge::BvhUdpLoop() {
  std::vector<char> buf(65536);
  while (!stop_.load()) {
    pollfd pfd{bvh_udp_fd_, POLLIN, 0};
    if (poll(&pfd, 1, 20) <= 0) continue;
    const ssize_t n = recv(bvh_udp_fd_, buf.data(), buf.size(), 0);
    if (n <= 0) continue;
    absl::StatusOr<BroadcastFrame> frame =
        ParseBroadcastBinary(absl::string_view(buf.data(), static_cast<size_t>(n)));
    if (!frame.ok()) {
      absl::MutexLock lock(&mu_);
      if (stats_.malformed++ < 3)
        spdlog::warn("BVH broadcast (UDP): {}", std::string(frame.status().message()));
      continue;
    }
    OnBroadcast(*std::move(frame));
  }
}

// Takes engines' connections for the text form. What they send is never
// read; one that has closed is dropped at its next send (SendBroadcast).
void Bridge::BvhOutLoop() {
  while (!stop_.load()) {
    pollfd pfd{bvh_listen_fd_, POLLIN, 0};
    if (poll(&pfd, 1, 20) <= 0) continue;
    const int fd = accept(bvh_listen_fd_, nullptr, nullptr);
    if (fd < 0) continue;
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    absl::MutexLock lock(&out_mu_);
    if (engines_.size() >= 64) {
      close(fd);
      continue;
    }
    engines_.push_back({fd, ""});
    spdlog::info("BVH broadcast out: an engine connected ({} now)", engines_.size());
  }
}

// To every engine: what each has not yet taken first, never blocking. An
// engine 1 MB behind is closed (it can connect again).
void Bridge::SendBroadcast(const BroadcastFrame& frame) {
  if (bvh_send_fd_ >= 0) {
    const std::string datagram = FormatBroadcastBinary(frame, false);
    sendto(bvh_send_fd_, datagram.data(), datagram.size(), MSG_DONTWAIT,
           reinterpret_cast<const sockaddr*>(bvh_send_addr_.data()),
           static_cast<socklen_t>(bvh_send_addr_.size()));
  }
  if (bvh_listen_fd_ < 0) return;
  int64_t dropped = 0;
  {
    absl::MutexLock lock(&out_mu_);
    if (engines_.empty()) return;  // No one to format it for.
    const std::string text = FormatBroadcastText(frame);
    for (auto it = engines_.begin(); it != engines_.end();) {
      it->unsent += text;
      const ssize_t n =
          send(it->fd, it->unsent.data(), it->unsent.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
      if (n > 0) it->unsent.erase(0, static_cast<size_t>(n));
      const bool gone = n < 0 && errno != EAGAIN && errno != EWOULDBLOCK;
      if (gone || it->unsent.size() > (1 << 20)) {
        if (!gone) {
          ++dropped;
          spdlog::warn("BVH broadcast out: an engine takes no frames (1 MB behind); closing it");
        }
        close(it->fd);
        it = engines_.erase(it);
      } else {
        ++it;
      }
    }
  }
  if (dropped) {
    absl::MutexLock lock(&mu_);
    stats_.engine_drops += dropped;
  }
}

}  // namespace stylus::bridge
