#include "client/live_stream.h"

#include <utility>
#include <vector>

#include "wire/wire.h"

namespace stylus {

absl::StatusOr<std::unique_ptr<LiveStream>> Client::OpenStream(const LiveStreamConfig& config,
                                                               LiveStream::FrameCallback on_frame) {
  std::unique_ptr<LiveStream> s(new LiveStream());
  v1::StreamRequest request;
  v1::StreamConfig* c = request.mutable_config();
  c->set_model(config.model);
  c->set_postprocess(config.postprocess);
  c->set_fps(config.fps);
  wire::SkeletonToProto(config.skeleton, c->mutable_skeleton());
  wire::JointMapToProto(config.joint_map, c->mutable_skeleton());
  if (absl::Status st = SetStyle(config.style, c->mutable_style()); !st.ok()) return st;
  // A live stream has no deadline: it lasts as long as the show.
  s->context_ = std::make_unique<grpc::ClientContext>();
  if (!options_.token.empty()) {
    s->context_->AddMetadata("authorization", "Bearer " + options_.token);
  }
  s->set_style_ = [this](const Style& style, v1::StyleRef* out) { return SetStyle(style, out); };
  s->one_ = motion::RestMotion(config.skeleton, 1, 1.0 / config.fps);
  s->on_frame_ = std::move(on_frame);
  s->stream_ = styles_->TransferStream(s->context_.get());
  if (!s->stream_->Write(request)) {
    // Refused before it began (no server there): Close finishes the call
    // once, and says why.
    s->alive_.store(false);
    absl::Status st = s->Close();
    return st.ok() ? absl::UnavailableError("the stream ended before it began") : st;
  }
  LiveStream* raw = s.get();
  s->reader_ = std::thread([raw] { raw->ReadLoop(); });
  return s;
}

LiveStream::~LiveStream() { Close().IgnoreError(); }

bool LiveStream::Push(const double* values, int64_t index) {
  if (!alive_.load()) return false;
  std::copy(values, values + one_.skeleton.num_channels(), one_.values.begin());
  v1::StreamRequest r;
  wire::FrameToProto(one_, 0, index, r.mutable_frame());
  absl::MutexLock lock(&write_mu_);
  if (writes_done_ || !stream_->Write(r)) {
    alive_.store(false);
    return false;
  }
  return true;
}

bool LiveStream::Change(const StreamChange& change) {
  if (!alive_.load()) return false;
  v1::StreamRequest r;
  v1::StyleChange* c = r.mutable_change();
  c->set_from_frame(change.frame);
  c->set_fade_frames(change.fade_frames);
  if (change.strength) c->set_strength(*change.strength);
  if (change.style.clip != nullptr || !change.style.name.empty()) {
    if (!set_style_(change.style, c->mutable_style()).ok()) return false;
  }
  absl::MutexLock lock(&write_mu_);
  if (writes_done_ || !stream_->Write(r)) {
    alive_.store(false);
    return false;
  }
  return true;
}

void LiveStream::ReadLoop() {
  v1::StreamResponse response;
  motion::Motion out = motion::RestMotion(one_.skeleton, 0, one_.frame_time);
  std::vector<motion::Vec3> prev(one_.skeleton.num_joints());
  while (stream_->Read(&response)) {
    out.num_frames = 0;
    out.values.clear();
    if (!wire::AppendFrame(response.frame(), "server's output", &prev, &out).ok()) continue;
    on_frame_(response.frame().index(), out.frame(0));
  }
  alive_.store(false);
}

absl::Status LiveStream::Close() {
  {
    absl::MutexLock lock(&status_mu_);
    if (closed_) return status_;
    closed_ = true;
  }
  {
    absl::MutexLock lock(&write_mu_);
    if (!writes_done_) {
      writes_done_ = true;
      stream_->WritesDone();
    }
  }
  if (reader_.joinable()) reader_.join();
  absl::Status status = FromGrpcStatus(stream_->Finish());
  absl::MutexLock lock(&status_mu_);
  status_ = status;
  return status_;
}

}  // namespace stylus
