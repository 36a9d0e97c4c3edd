// The stage console: a small HTTP server in the bridge for a browser on the
// stage's network. GET / is the page (console.html: the performer's input
// and stylized skeletons side by side in three.js, the style, strength,
// latency and counters, a style picker and a strength slider); GET
// /three.min.js is Debian's libjs-three; GET /state is the live state as
// JSON; POST /control (style=NAME or strength=K, form-encoded) becomes the
// streams' live change, as the OSC messages do.
#ifndef STYLUS_BRIDGE_CONSOLE_H_
#define STYLUS_BRIDGE_CONSOLE_H_

#include <atomic>
#include <functional>
#include <string>
#include <thread>

#include "absl/status/status.h"

namespace stylus::bridge {

class Bridge;

class Console {
 public:
  // `three_js`: the path of three.min.js (Debian: /usr/share/javascript/three).
  Console(Bridge* bridge, std::string three_js) : bridge_(bridge), three_js_(std::move(three_js)) {}
  ~Console() { Stop(); }

  // Listens on `address` ("HOST:PORT"; port 0 picks one). UNAVAILABLE when
  // it cannot bind, FAILED_PRECONDITION when three.min.js is not there.
  absl::Status Start(const std::string& address);
  void Stop();
  int port() const { return port_; }

 private:
  void Serve();
  void Handle(int fd);

  Bridge* bridge_;
  std::string three_js_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace stylus::bridge

#endif  // STYLUS_BRIDGE_CONSOLE_H_
