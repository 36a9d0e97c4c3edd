#include "client/client.h"

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "wire/pem.h"
#include "wire/wire.h"

namespace stylus {

absl::Status FromGrpcStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

namespace {

constexpr char kServiceConfig[] = R"({
  "loadBalancingConfig": [{"round_robin": {}}],
  "methodConfig": [{
    "name": [{"service": "stylus.v1.StyleService"}, {"service": "stylus.v1.ModelService"}],
    "retryPolicy": {
      "maxAttempts": 3,
      "initialBackoff": "0.1s",
      "maxBackoff": "1s",
      "backoffMultiplier": 2,
      "retryableStatusCodes": ["UNAVAILABLE"]
    }
  }]
})";

}  // namespace

absl::StatusOr<TlsOptions> ReadTlsFiles(const std::string& ca_file, const std::string& cert_file,
                                        const std::string& key_file) {
  TlsOptions tls;
  if (cert_file.empty() != key_file.empty()) {
    return absl::InvalidArgumentError(
        "a client certificate needs its key: give both --tls-cert and --tls-key");
  }
  if (!ca_file.empty()) {
    absl::StatusOr<std::string> ca =
        wire::ReadPem(ca_file, wire::PemKind::kCertificate, "--tls-ca");
    if (!ca.ok()) return ca.status();
    tls.ca_pem = *std::move(ca);
  }
  if (!cert_file.empty()) {
    absl::StatusOr<std::string> cert =
        wire::ReadPem(cert_file, wire::PemKind::kCertificate, "--tls-cert");
    if (!cert.ok()) return cert.status();
    absl::StatusOr<std::string> key =
        wire::ReadPem(key_file, wire::PemKind::kPrivateKey, "--tls-key");
    if (!key.ok()) return key.status();
    tls.cert_pem = *std::move(cert);
    tls.key_pem = *std::move(key);
  }
  tls.enabled = !ca_file.empty() || !cert_file.empty();
  return tls;
}

absl::StatusOr<v1::PostProcess> ParsePostProcess(const std::string& name) {
  if (name == "default") return v1::POSTPROCESS_DEFAULT;
  if (name == "none") return v1::POSTPROCESS_NONE;
  if (name == "feet") return v1::POSTPROCESS_FEET;
  if (name == "full") return v1::POSTPROCESS_FULL;
  return absl::InvalidArgumentError("--postprocess must be default, none, feet or full");
}

Client::Client(const ClientOptions& options) : options_(options) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(options.max_message_mb * 1024 * 1024);
  args.SetMaxSendMessageSize(options.max_message_mb * 1024 * 1024);
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (options.tls.enabled) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = options.tls.ca_pem;
    ssl.pem_cert_chain = options.tls.cert_pem;
    ssl.pem_private_key = options.tls.key_pem;
    credentials = grpc::SslCredentials(ssl);
    if (!options.tls.server_name.empty()) {
      args.SetSslTargetNameOverride(options.tls.server_name);
    }
  }
  // Every address the target resolves to (dns:///name:port, or
  // ipv4:a:p,b:q) gets calls in turn; a call refused UNAVAILABLE (a server
  // shutting down, or gone before it answered) is tried again on another.
  args.SetServiceConfigJSON(kServiceConfig);
  if (options.max_reconnect_backoff_ms > 0) {
    args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS,
                std::min(100, options.max_reconnect_backoff_ms));
    args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, std::min(100, options.max_reconnect_backoff_ms));
    args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, options.max_reconnect_backoff_ms);
  }
  channel_ = grpc::CreateCustomChannel(options.address, credentials, args);
  models_ = v1::ModelService::NewStub(channel_);
  styles_ = v1::StyleService::NewStub(channel_);
}

std::unique_ptr<grpc::ClientContext> Client::Context(double deadline_scale) const {
  auto ctx = std::make_unique<grpc::ClientContext>();
  ctx->set_deadline(
      std::chrono::system_clock::now() +
      std::chrono::duration_cast<std::chrono::milliseconds>(options_.deadline * deadline_scale));
  if (!options_.token.empty()) ctx->AddMetadata("authorization", "Bearer " + options_.token);
  return ctx;
}

absl::Status Client::SetStyle(const Style& style, v1::StyleRef* out) const {
  if (style.clip != nullptr) {
    if (absl::Status s = wire::CheckFinite(*style.clip, "style clip"); !s.ok()) return s;
    wire::ClipToProto(*style.clip, out->mutable_clip());
    wire::JointMapToProto(style.joint_map, out->mutable_clip()->mutable_skeleton());
  } else if (!style.name.empty()) {
    out->set_name(style.name);
  } else {
    return absl::InvalidArgumentError("no style: give a clip or a saved style name");
  }
  return absl::OkStatus();
}

absl::StatusOr<bool> Client::Serving() {
  // grpc.health.v1 has no generated C++ stubs in Debian: the request is an
  // empty HealthCheckRequest (service ""), the response's field 1 the status
  // (1 SERVING, 2 NOT_SERVING), both read and written as bytes here.
  grpc::GenericStub stub(channel_);
  auto ctx = Context();
  grpc::CompletionQueue cq;
  grpc::Slice empty(std::string{});  // A message of zero bytes, not none.
  grpc::ByteBuffer request(&empty, 1), response;
  auto call = stub.PrepareUnaryCall(ctx.get(), "/grpc.health.v1.Health/Check", request, &cq);
  call->StartCall();
  grpc::Status status;
  call->Finish(&response, &status, nullptr);
  void* tag = nullptr;
  bool ok = false;
  cq.Next(&tag, &ok);
  if (!status.ok()) return FromGrpcStatus(status);
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (response.Dump(&slices).ok()) {
    for (const grpc::Slice& s : slices)
      bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  }
  // Field 1, varint: 0x08 then the value (an empty message means UNKNOWN, 0).
  const int value = bytes.size() >= 2 && bytes[0] == 0x08 ? bytes[1] : 0;
  if (value != 1 && value != 2) {
    return absl::InternalError(absl::StrCat("health check: unexpected status ", value));
  }
  return value == 1;
}

absl::StatusOr<std::vector<v1::ModelInfo>> Client::ListModels() {
  v1::ListModelsResponse response;
  const grpc::Status s = models_->ListModels(Context().get(), {}, &response);
  if (!s.ok()) return FromGrpcStatus(s);
  return std::vector<v1::ModelInfo>(response.models().begin(), response.models().end());
}

absl::StatusOr<v1::ModelInfo> Client::GetModel(const std::string& model) {
  v1::GetModelRequest request;
  request.set_model(model);
  v1::ModelInfo info;
  const grpc::Status s = models_->GetModel(Context().get(), request, &info);
  if (!s.ok()) return FromGrpcStatus(s);
  return info;
}

absl::StatusOr<v1::ModelInfo> Client::LoadModel(const std::string& model) {
  v1::LoadModelRequest request;
  request.set_model(model);
  v1::ModelInfo info;
  const grpc::Status s = models_->LoadModel(Context().get(), request, &info);
  if (!s.ok()) return FromGrpcStatus(s);
  return info;
}

absl::Status Client::UnloadModel(const std::string& model) {
  v1::UnloadModelRequest request;
  request.set_model(model);
  v1::UnloadModelResponse response;
  return FromGrpcStatus(models_->UnloadModel(Context().get(), request, &response));
}

absl::StatusOr<motion::Motion> Client::Transfer(const motion::Motion& content, const Style& style,
                                                const CallOptions& options) {
  if (absl::Status s = wire::CheckFinite(content, "content clip"); !s.ok()) return s;
  v1::TransferRequest request;
  request.set_model(options.model);
  request.set_postprocess(options.postprocess);
  request.set_timing(options.timing);
  request.set_fit_frames(options.fit_frames);
  wire::ClipToProto(content, request.mutable_content());
  wire::JointMapToProto(options.joint_map, request.mutable_content()->mutable_skeleton());
  if (absl::Status s = SetStyle(style, request.mutable_style()); !s.ok()) return s;
  v1::TransferResponse response;
  const grpc::Status s = styles_->Transfer(Context().get(), request, &response);
  if (!s.ok()) return FromGrpcStatus(s);
  if (options.content_guard != nullptr) *options.content_guard = response.content_guard();
  if (options.time_warp != nullptr) *options.time_warp = response.time_warp();
  if (options.movement != nullptr) *options.movement = response.movement();
  if (options.contacts != nullptr) {
    options.contacts->assign(response.contacts().begin(), response.contacts().end());
  }
  return wire::ClipFromProto(response.output(), "server's output");
}

absl::StatusOr<std::vector<float>> Client::EncodeStyle(const motion::Motion& clip,
                                                       const std::string& save_as,
                                                       const CallOptions& options) {
  if (absl::Status s = wire::CheckFinite(clip, "style clip"); !s.ok()) return s;
  v1::EncodeStyleRequest request;
  request.set_model(options.model);
  request.set_save_as(save_as);
  wire::ClipToProto(clip, request.mutable_clip());
  wire::JointMapToProto(options.joint_map, request.mutable_clip()->mutable_skeleton());
  v1::EncodeStyleResponse response;
  const grpc::Status s = styles_->EncodeStyle(Context().get(), request, &response);
  if (!s.ok()) return FromGrpcStatus(s);
  return std::vector<float>(response.code().begin(), response.code().end());
}

absl::StatusOr<motion::Motion> Client::Interpolate(const motion::Motion& content,
                                                   const std::vector<Style>& styles,
                                                   const std::vector<double>& weights,
                                                   const std::vector<std::vector<double>>& schedule,
                                                   const CallOptions& options) {
  if (absl::Status s = wire::CheckFinite(content, "content clip"); !s.ok()) return s;
  v1::InterpolateRequest request;
  request.set_model(options.model);
  request.set_postprocess(options.postprocess);
  wire::ClipToProto(content, request.mutable_content());
  wire::JointMapToProto(options.joint_map, request.mutable_content()->mutable_skeleton());
  for (const Style& style : styles) {
    if (absl::Status s = SetStyle(style, request.add_styles()); !s.ok()) return s;
  }
  request.mutable_weights()->mutable_values()->Add(weights.begin(), weights.end());
  for (const auto& row : schedule)
    request.add_schedule()->mutable_values()->Add(row.begin(), row.end());
  v1::TransferResponse response;
  const grpc::Status s = styles_->Interpolate(Context().get(), request, &response);
  if (!s.ok()) return FromGrpcStatus(s);
  if (options.content_guard != nullptr) *options.content_guard = response.content_guard();
  return wire::ClipFromProto(response.output(), "server's output");
}

absl::StatusOr<StreamResult> Client::Stream(const motion::Motion& content, const Style& style,
                                            double rate, const CallOptions& options,
                                            const std::vector<StreamChange>& changes) {
  using Clock = std::chrono::steady_clock;
  if (absl::Status s = wire::CheckFinite(content, "content clip"); !s.ok()) return s;
  v1::StreamRequest config;
  config.mutable_config()->set_model(options.model);
  config.mutable_config()->set_postprocess(options.postprocess);
  config.mutable_config()->set_fps(content.fps());
  wire::SkeletonToProto(content.skeleton, config.mutable_config()->mutable_skeleton());
  wire::JointMapToProto(options.joint_map, config.mutable_config()->mutable_skeleton());
  if (absl::Status s = SetStyle(style, config.mutable_config()->mutable_style()); !s.ok()) {
    return s;
  }
  std::vector<v1::StreamRequest> change_requests;
  for (size_t i = 0; i < changes.size(); ++i) {
    const StreamChange& c = changes[i];
    if (i > 0 && c.frame < changes[i - 1].frame) {
      return absl::InvalidArgumentError("style changes must be in frame order");
    }
    if (c.frame < 0 || c.frame >= content.num_frames) {
      return absl::InvalidArgumentError(absl::StrCat("style change at frame ", c.frame,
                                                     ": the clip has frames 0 to ",
                                                     content.num_frames - 1));
    }
    v1::StreamRequest r;
    v1::StyleChange* change = r.mutable_change();
    change->set_from_frame(c.frame);
    change->set_fade_frames(c.fade_frames);
    if (c.strength) change->set_strength(*c.strength);
    if (c.style.clip != nullptr || !c.style.name.empty()) {
      if (absl::Status s = SetStyle(c.style, change->mutable_style()); !s.ok()) return s;
    }
    change_requests.push_back(std::move(r));
  }
  auto ctx = Context(10);
  auto stream = styles_->TransferStream(ctx.get());
  std::vector<Clock::time_point> sent(content.num_frames);
  absl::Mutex mu;
  std::thread writer([&] {
    if (!stream->Write(config)) return;
    const Clock::time_point start = Clock::now();
    size_t next_change = 0;
    for (int f = 0; f < content.num_frames; ++f) {
      while (next_change < changes.size() && changes[next_change].frame == f) {
        if (!stream->Write(change_requests[next_change++])) return;
      }
      if (rate > 0)
        std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(f / rate)));
      v1::StreamRequest r;
      wire::FrameToProto(content, f, f, r.mutable_frame());
      {
        absl::MutexLock lock(&mu);
        sent[f] = Clock::now();
      }
      if (!stream->Write(r)) return;  // The server ended the call; Finish says why.
    }
    stream->WritesDone();
  });
  StreamResult result;
  result.output = motion::RestMotion(content.skeleton, 0, content.frame_time);
  std::vector<motion::Vec3> prev(content.skeleton.num_joints());
  v1::StreamResponse response;
  absl::Status problem;
  while (stream->Read(&response)) {
    const Clock::time_point now = Clock::now();
    const int64_t i = response.frame().index();
    if (problem.ok()) {
      problem = wire::AppendFrame(response.frame(), "server's output", &prev, &result.output);
    }
    result.indices.push_back(i);
    absl::MutexLock lock(&mu);
    if (i >= 0 && i < content.num_frames) {
      result.latency_s.push_back(std::chrono::duration<double>(now - sent[i]).count());
    }
  }
  writer.join();
  const grpc::Status s = stream->Finish();
  if (!s.ok()) return FromGrpcStatus(s);
  if (!problem.ok()) return problem;
  return result;
}

absl::StatusOr<std::map<std::string, double>> Client::ComputeMetrics(const motion::Motion& output,
                                                                     const motion::Motion* content,
                                                                     const motion::Motion* style) {
  for (const auto& [clip, what] :
       {std::pair{&output, "output clip"}, std::pair{content, "content clip"},
        std::pair{style, "style clip"}}) {
    if (clip == nullptr) continue;
    if (absl::Status s = wire::CheckFinite(*clip, what); !s.ok()) return s;
  }
  v1::MetricsRequest request;
  wire::ClipToProto(output, request.mutable_output());
  if (content) wire::ClipToProto(*content, request.mutable_content());
  if (style) wire::ClipToProto(*style, request.mutable_style());
  v1::MetricsResponse response;
  const grpc::Status s = styles_->ComputeMetrics(Context().get(), request, &response);
  if (!s.ok()) return FromGrpcStatus(s);
  return std::map<std::string, double>(response.metrics().begin(), response.metrics().end());
}

}  // namespace stylus
