// A TransferStream kept open for as long as a stage sends frames: frames go
// in one at a time as they are captured, and the stylized frames come back,
// in order, to a callback on the stream's own reader thread. Built for
// bridges (bridge/), where the clip is not known in advance.
#ifndef STYLUS_CLIENT_LIVE_STREAM_H_
#define STYLUS_CLIENT_LIVE_STREAM_H_

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "client/client.h"

namespace stylus {

struct LiveStreamConfig {
  std::string model;  // Empty: the server's default.
  Style style;
  motion::Skeleton skeleton;  // Of the frames pushed.
  double fps = 30;
  v1::PostProcess postprocess = v1::POSTPROCESS_DEFAULT;
  motion::JointMap joint_map;
};

class LiveStream {
 public:
  // Called for each stylized frame: the index of the input frame it
  // replaces, and its channel values on the config's skeleton.
  using FrameCallback = std::function<void(int64_t index, const double* values)>;

  ~LiveStream();  // Closes (see Close).
  LiveStream(const LiveStream&) = delete;
  LiveStream& operator=(const LiveStream&) = delete;

  // One input frame (skeleton.num_channels() values). False once the
  // stream has ended (the server went away or refused it: Close says why).
  bool Push(const double* values, int64_t index);
  // A live style change; false once the stream has ended.
  bool Change(const StreamChange& change);
  // False once the stream has ended, from either side.
  bool alive() const { return alive_.load(); }
  // Ends the stream (what was pushed is still returned first) and gives its
  // final status. Safe to call more than once.
  absl::Status Close();

 private:
  friend class Client;
  LiveStream() = default;
  void ReadLoop();

  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::StreamRequest, v1::StreamResponse>> stream_;
  motion::Motion one_;  // The skeleton and one frame: conversions.
  FrameCallback on_frame_;
  std::thread reader_;
  std::atomic<bool> alive_{true};
  absl::Mutex write_mu_;
  bool writes_done_ ABSL_GUARDED_BY(write_mu_) = false;
  absl::Mutex status_mu_;
  bool closed_ ABSL_GUARDED_BY(status_mu_) = false;
  absl::Status status_ ABSL_GUARDED_BY(status_mu_);
  std::function<absl::Status(const Style&, v1::StyleRef*)> set_style_;
};

}  // namespace stylus

#endif  // STYLUS_CLIENT_LIVE_STREAM_H_
