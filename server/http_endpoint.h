// A minimal HTTP/1.x endpoint for Prometheus scrapes: one thread accepts
// connections on "host:port" (port 0 picks a free one), answers GET of one
// path with what `body` returns (text/plain), 404 for any other path, 405
// for other methods, and closes each connection after its answer.
// Connections are served concurrently from one poll loop: a client that sends
// no complete request head within 1 s, or one over 8 KiB, is dropped, and
// idle connections never delay another's scrape; past 64 open connections
// the oldest is dropped. (prometheus-cpp's own HTTP server cannot start
// threads once LibTorch is loaded in the process.)
//
// Thread-safety: the body callback runs on the endpoint's thread.
#ifndef STYLUS_SERVER_HTTP_ENDPOINT_H_
#define STYLUS_SERVER_HTTP_ENDPOINT_H_

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "absl/status/statusor.h"

namespace stylus::server {

class HttpEndpoint {
 public:
  // UNAVAILABLE when `listen` cannot be bound; INVALID_ARGUMENT when it is
  // not host:port with an IPv4 address or "localhost".
  static absl::StatusOr<std::unique_ptr<HttpEndpoint>> Start(const std::string& listen,
                                                             const std::string& path,
                                                             std::function<std::string()> body);
  // Stops accepting and joins the thread.
  ~HttpEndpoint();
  int port() const { return port_; }

 private:
  HttpEndpoint(int fd, int port, std::string path, std::function<std::string()> body);
  void Loop();
  void Answer(int client, const std::string& request);

  const int fd_;
  const int port_;
  const std::string path_;
  const std::function<std::string()> body_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_HTTP_ENDPOINT_H_
