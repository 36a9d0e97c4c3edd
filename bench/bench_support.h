// Shared by the benchmarks that drive a real stylus-server process: start it
// on a free port, read its resident memory and CPU time from /proc,
// percentiles.
#ifndef STYLUS_BENCH_BENCH_SUPPORT_H_
#define STYLUS_BENCH_BENCH_SUPPORT_H_

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace stylus::bench {

using Clock = std::chrono::steady_clock;

inline double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

inline double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

inline long RssKb(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// User + system CPU seconds the process has used.
inline double CpuSeconds(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(stat.substr(close + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; rest >> field; ++i) {  // Fields 14 and 15: utime, stime (clock ticks).
    if (i == 14) utime = std::stod(field);
    if (i == 15) {
      stime = std::stod(field);
      break;
    }
  }
  return (utime + stime) / sysconf(_SC_CLK_TCK);
}

// A stylus-server child process on a free port (its stderr to /dev/null).
// A TCP port free on this machine now (0 if none could be had).
inline int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(addr);
  int port = 0;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  close(fd);
  return port;
}

// The body of GET http://127.0.0.1:port/path ("" on any failure).
inline std::string HttpGet(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
    const std::string request = "GET " + path + " HTTP/1.0\r\n\r\n";
    if (write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size())) {
      char buf[65536];
      for (ssize_t n; (n = read(fd, buf, sizeof(buf))) > 0;) out.append(buf, n);
    }
  }
  close(fd);
  const size_t body = out.find("\r\n\r\n");
  return body == std::string::npos ? "" : out.substr(body + 4);
}

// A protobuf length-delimited field on the wire: its tag, the varint
// length, the bytes (for requests crafted by hand).
inline std::string WireField(int number, const std::string& body) {
  std::string out;
  for (uint64_t v :
       {(static_cast<uint64_t>(number) << 3) | 2, static_cast<uint64_t>(body.size())}) {
    while (v >= 0x80) {
      out.push_back(static_cast<char>(v | 0x80));
      v >>= 7;
    }
    out.push_back(static_cast<char>(v));
  }
  return out + body;
}

struct ServerProcess {
  pid_t pid = -1;
  int port = 0;

  // Starts `binary` with `args` after --listen/--port-file; false if it did
  // not come up within 30 s.
  bool Start(const std::string& binary, std::vector<std::string> args) {
    const std::string port_file =
        "/tmp/stylus_bench." + std::to_string(getpid()) + "." + std::to_string(++starts_) + ".port";
    std::remove(port_file.c_str());
    args.insert(args.begin(), {binary, "--listen", "localhost:0", "--port-file", port_file});
    std::vector<char*> cargs;
    for (auto& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    // The server's log goes to $STYLUS_SERVER_LOG when set (appended), else nowhere.
    const char* log = std::getenv("STYLUS_SERVER_LOG");
    posix_spawn_file_actions_addopen(&actions, 2, log != nullptr ? log : "/dev/null",
                                     log != nullptr ? O_WRONLY | O_CREAT | O_APPEND : O_WRONLY,
                                     0644);
    const int spawned = posix_spawn(&pid, binary.c_str(), &actions, nullptr, cargs.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) {
      pid = -1;
      return false;
    }
    for (int i = 0; i < 300 && port == 0; ++i) {
      std::ifstream f(port_file);
      if (!(f >> port)) port = 0;
      if (port != 0) break;
      if (waitpid(pid, nullptr, WNOHANG) == pid) {  // It exited: it will not come up.
        pid = -1;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::remove(port_file.c_str());
    if (port == 0) Kill();
    return port != 0;
  }
  std::string address() const { return "localhost:" + std::to_string(port); }
  // SIGTERM and wait; the exit code (-1 if it did not exit normally).
  int Stop() {
    Signal(SIGTERM);
    return Wait();
  }
  void Signal(int sig) const {
    if (pid > 0) kill(pid, sig);
  }
  // Waits for the process to exit; its exit code (-1 if it did not exit normally).
  int Wait() {
    if (pid < 0) return -1;
    int status = 0;
    waitpid(pid, &status, 0);
    pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  void Kill() {
    if (pid < 0) return;
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    pid = -1;
  }
  ~ServerProcess() { Kill(); }

 private:
  int starts_ = 0;
};

}  // namespace stylus::bench

#endif  // STYLUS_BENCH_BENCH_SUPPORT_H_
