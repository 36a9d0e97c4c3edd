#include "server/server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/synchronization/notification.h"
#include "model/runtime.h"
#include "server/services.h"
#include "server/tls.h"
#include "spdlog/spdlog.h"

namespace stylus::server {
namespace {

// gRPC's synchronous threads (only reflection uses them).
constexpr int kMaxSyncThreads = 8;
constexpr int kMaxReadChunk = 256 * 1024;
constexpr int kStreamWindow = 512 * 1024;

// Reflection on one server or off: linking gRPC's reflection library adds
// its plugin to every server a process builds, so it is taken out unless
// asked for.
class ReflectionOption : public grpc::ServerBuilderOption {
 public:
  explicit ReflectionOption(bool on) : on_(on) {}
  void UpdateArguments(grpc::ChannelArguments*) override {}
  void UpdatePlugins(std::vector<std::unique_ptr<grpc::ServerBuilderPlugin>>* plugins) override {
    const std::string name = grpc::reflection::ProtoServerReflectionPlugin().name();
    plugins->erase(std::remove_if(plugins->begin(), plugins->end(),
                                  [&](const auto& p) { return p->name() == name; }),
                   plugins->end());
    if (on_) plugins->push_back(std::make_unique<grpc::reflection::ProtoServerReflectionPlugin>());
  }

 private:
  const bool on_;
};

// A token file read again: what is in force now, loudly when nothing is.
void LogReload(const TokenAuth& auth, const absl::StatusOr<int>& n, const char* why) {
  if (n.ok()) {
    spdlog::info("{} {}: {} token(s) in force", auth.path(), why, *n);
  } else {
    spdlog::error("{} {}: {}; EVERY TOKEN FROM IT IS REVOKED until it holds valid tokens",
                  auth.path(), why, std::string(n.status().message()));
  }
}

}  // namespace

struct StylusServer::Impl {
  std::unique_ptr<ModelRegistry> registry;
  std::unique_ptr<StyleBank> styles;
  // With --metrics-listen; outlives what it reads and what counts into it.
  std::unique_ptr<Metrics> metrics;
  std::unique_ptr<TokenAuth> auth;                   // With auth_tokens.
  std::unique_ptr<TokenAuth> admin_auth;             // With admin_tokens.
  std::unique_ptr<RequestBudget> budget;
  std::unique_ptr<MemoryPool> call_memory;  // With max_memory_mb.
  std::unique_ptr<model::StyleLibrary> style_library;
  // Re-reads the token files when they change (a mounted Secret changes
  // without a signal); stops at shutdown.
  std::thread token_watch;
  absl::Notification stop_watching;
  std::unique_ptr<model::PassBatcher> pass_batcher;  // With max_batch > 0; outlives the executor.
  std::unique_ptr<Executor> executor;
  std::unique_ptr<StepBatcher> batcher;  // With max_batch > 0.
  ServiceContext context;
  std::unique_ptr<ModelServiceImpl> model_service;
  std::unique_ptr<StyleServiceImpl> style_service;
  std::unique_ptr<grpc::Server> server;
  int port = 0;
  absl::Mutex mu;
  bool shut_down ABSL_GUARDED_BY(mu) = false;
  // Set before the executor and batchers go: a scrape reads them no more.
  bool workers_gone ABSL_GUARDED_BY(mu) = false;

  MetricsState State() {
    MetricsState s;
    s.open_streams = context.open_streams.load();
    s.loaded_models = static_cast<int>(registry->List().size());
    absl::MutexLock lock(&mu);
    if (workers_gone) return s;
    s.queued_tasks = executor->queued();
    s.running_tasks = executor->running();
    if (pass_batcher != nullptr) {
      s.unary_batches = pass_batcher->batches();
      s.batched_calls = pass_batcher->calls();
    }
    return s;
  }
  absl::Notification done;

  // Reloads each token file that changed, once a second, until shutdown.
  void WatchTokens() {
    while (!stop_watching.WaitForNotificationWithTimeout(absl::Seconds(1))) {
      for (TokenAuth* a : {auth.get(), admin_auth.get()}) {
        if (a == nullptr) continue;
        const std::optional<absl::StatusOr<int>> n = a->ReloadIfChanged();
        if (!n.has_value()) continue;
        LogReload(*a, *n, "changed");
      }
    }
  }
};

StylusServer::StylusServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

StylusServer::~StylusServer() {
  Shutdown(std::chrono::system_clock::now());
  Wait();
}

absl::StatusOr<std::unique_ptr<StylusServer>> StylusServer::Start(const ServerOptions& options) {
  if (options.threads < 1 || options.max_streams < 1 || options.max_message_mb < 1 ||
      options.max_stream_frames < 1 || options.max_batch < 0 || options.max_queue_delay_us < 0 ||
      options.max_clip_frames < 1 || options.max_joints < 1 || options.max_unary_calls < 1 ||
      options.max_saved_styles < 1 || !(options.stream_idle_timeout_s >= 0) ||
      options.max_styles < 2 || options.max_stream_backlog < 1 || options.max_memory_mb < 0) {
    return absl::InvalidArgumentError("threads, stream, call and message limits must be positive");
  }
  if (options.max_message_mb > kMaxMessageMb) {
    return absl::InvalidArgumentError(absl::StrCat("--max-message-mb ", options.max_message_mb,
                                                   " is over the largest, ", kMaxMessageMb));
  }
  absl::StatusOr<ServerTransport> transport =
      MakeServerTransport({options.tls_cert, options.tls_key, options.tls_client_ca});
  if (!transport.ok()) return transport.status();
  auto impl = std::make_unique<Impl>();
  if (!options.auth_tokens.empty()) {
    absl::StatusOr<std::unique_ptr<TokenAuth>> auth = TokenAuth::Load(options.auth_tokens);
    if (!auth.ok()) return auth.status();
    impl->auth = *std::move(auth);
    impl->context.auth = impl->auth.get();
  }
  if (!options.admin_tokens.empty()) {
    absl::StatusOr<std::unique_ptr<TokenAuth>> admin = TokenAuth::Load(options.admin_tokens);
    if (!admin.ok()) return admin.status();
    impl->admin_auth = *std::move(admin);
    impl->context.admin_auth = impl->admin_auth.get();
  }
  RequestBudget::Options budget;
  budget.entries = {
      {"stylus.v1.Clip.frames", options.max_clip_frames, "--max-clip-frames"},
      {"stylus.v1.InterpolateRequest.schedule", options.max_clip_frames, "--max-clip-frames"},
      {"stylus.v1.Skeleton.joints", options.max_joints, "--max-joints"},
      {"stylus.v1.Frame.rotations", options.max_joints, "--max-joints"},
      {"stylus.v1.Frame.translations", options.max_joints, "--max-joints"},
      {"stylus.v1.Skeleton.joint_map", 64, "roles in a joint map"},
      {"stylus.v1.Joint.channels", 6, "BVH channels per joint"},
      {"stylus.v1.Joint.end_sites", 16, "end sites per joint"},
      {"stylus.v1.InterpolateRequest.styles", options.max_styles, "--max-styles"},
      {"stylus.v1.Weights.values", options.max_styles, "--max-styles"},
      {"stylus.v1.StyleBlend.styles", options.max_styles, "--max-styles"},
      {"stylus.v1.StyleBlend.weights", options.max_styles, "--max-styles"},
  };
  if (absl::Status s = RequestBudget::Validate(budget); !s.ok()) return s;
  impl->budget = std::make_unique<RequestBudget>(budget);
  impl->context.budget = impl->budget.get();
  if (options.max_memory_mb > 0) {
    impl->call_memory = std::make_unique<MemoryPool>(options.max_memory_mb << 20);
    impl->context.call_memory = impl->call_memory.get();
  }
  model::SetComputeThreads(options.torch_threads);
  absl::StatusOr<std::unique_ptr<ModelRegistry>> registry =
      ModelRegistry::Create(options.models_dir, options.default_model);
  if (!registry.ok()) return registry.status();
  if (!options.style_library.empty()) {
    absl::StatusOr<std::unique_ptr<model::StyleLibrary>> library =
        model::StyleLibrary::Load(options.style_library, options.style_library_labels);
    if (!library.ok()) return library.status();
    impl->style_library = *std::move(library);
    impl->context.style_library = impl->style_library.get();
    for (const std::string& skipped : impl->style_library->skipped()) {
      spdlog::warn("style library: skipped {}", skipped);
    }
    // Read for the default model now, so the first call does not wait for it.
    if (absl::StatusOr<HostedModel> m = (*registry)->Get("");
        m.ok() && m->model->moves_from_examples()) {
      absl::StatusOr<std::shared_ptr<const model::StyleLibrary::Converted>> read =
          impl->style_library->For(*m->model);
      if (!read.ok()) return read.status();
    }
    spdlog::info("style library {}: {} takes of {} styles", options.style_library,
                 impl->style_library->takes().size(), impl->style_library->Styles().size());
  }
  impl->registry = *std::move(registry);
  impl->executor = std::make_unique<Executor>(options.threads);
  impl->context.registry = impl->registry.get();
  impl->styles = std::make_unique<StyleBank>(options.max_saved_styles);
  impl->context.styles = impl->styles.get();
  impl->context.executor = impl->executor.get();
  if (options.max_batch > 0 && options.batch_unary) {
    impl->pass_batcher = std::make_unique<model::PassBatcher>(
        options.max_batch, std::chrono::microseconds(options.max_queue_delay_us));
    impl->context.pass_batcher = impl->pass_batcher.get();
  }
  if (!options.metrics_listen.empty()) {
    Impl* raw = impl.get();
    absl::StatusOr<std::unique_ptr<Metrics>> metrics =
        Metrics::Start(options.metrics_listen, [raw] { return raw->State(); });
    if (!metrics.ok()) return metrics.status();
    impl->metrics = *std::move(metrics);
    impl->context.metrics = impl->metrics.get();
  }
  if (options.max_batch > 0) {
    impl->batcher = std::make_unique<StepBatcher>(
        impl->executor.get(), options.max_batch,
        std::chrono::microseconds(options.max_queue_delay_us), impl->metrics.get());
    impl->context.batcher = impl->batcher.get();
  }
  impl->context.max_streams = options.max_streams;
  impl->context.max_stream_frames = options.max_stream_frames;
  impl->context.limits.max_unary_calls = options.max_unary_calls;
  impl->context.limits.max_styles = options.max_styles;
  impl->context.limits.max_stream_backlog = options.max_stream_backlog;
  impl->context.limits.stream_idle_timeout =
      std::chrono::milliseconds(static_cast<int64_t>(options.stream_idle_timeout_s * 1000));
  impl->model_service = std::make_unique<ModelServiceImpl>(&impl->context);
  impl->style_service = std::make_unique<StyleServiceImpl>(&impl->context);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::ServerBuilder builder;
  builder.SetOption(std::make_unique<ReflectionOption>(options.reflection));
  if (options.max_memory_mb > 0) {
    // gRPC's own buffers (connections, messages being read or written) and
    // its synchronous threads (reflection's) within bounds.
    grpc::ResourceQuota quota("stylus-server");
    quota.Resize(static_cast<size_t>(options.max_memory_mb) << 20);
    quota.SetMaxThreads(kMaxSyncThreads);
    builder.SetResourceQuota(quota);
  }
  builder.AddListeningPort(options.listen, transport->credentials, &impl->port);
  // gRPC's TCP reads grow up to 4 MiB a read; data for a call already
  // refused (no token) is read and dropped, so a smaller read is what such
  // a call costs. Large requests still arrive at full speed on loopback.
  builder.AddChannelArgument(GRPC_ARG_TCP_MAX_READ_CHUNK_SIZE, kMaxReadChunk);
  // Likewise what a client may send ahead of the server's reading (a
  // stream's flow-control window): gRPC's bandwidth probe would grow it to
  // megabytes, all taken in even for a call refused at once.
  builder.AddChannelArgument(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, kStreamWindow);
  builder.SetMaxReceiveMessageSize(options.max_message_mb * 1024 * 1024);
  builder.SetMaxSendMessageSize(options.max_message_mb * 1024 * 1024);
  builder.RegisterService(impl->model_service.get());
  builder.RegisterService(impl->style_service.get());
  impl->server = builder.BuildAndStart();
  if (!impl->server || impl->port == 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen));
  }
  impl->server->GetHealthCheckService()->SetServingStatus(true);
  std::vector<std::string> ids;
  for (const HostedModel& m : impl->registry->List()) ids.push_back(m.id);
  spdlog::info("listening on port {} with {} model(s) [{}], default {}; {} compute thread(s)",
               impl->port, ids.size(), absl::StrJoin(ids, ", "), impl->registry->default_id(),
               options.threads);
  const model::BlasReport blas = model::DescribeBlas();
  spdlog::info("LibTorch: {} thread(s) per forward; BLAS: {} (kernel {}; this CPU's best: {})",
               model::ComputeThreads(), blas.library, blas.kernel.empty() ? "?" : blas.kernel,
               blas.best.empty() ? "?" : blas.best);
  if (!blas.warning.empty()) spdlog::warn("{}", blas.warning);
  spdlog::info("transport: {}", transport->description);
  if (options.tls_cert.empty() && !IsLoopbackAddress(options.listen)) {
    spdlog::warn(
        "{} is reachable from other machines over plain text: give --tls-cert and "
        "--tls-key (docs/service.md \"TLS\")",
        options.listen);
  }
  spdlog::info("access: {}; models loaded and unloaded by {}",
               impl->auth != nullptr ? absl::StrCat("bearer tokens from ", options.auth_tokens)
                                     : std::string("open (no --auth-tokens)"),
               impl->admin_auth != nullptr
                   ? absl::StrCat("admin tokens from ", options.admin_tokens)
               : impl->auth != nullptr ? std::string("nobody (no --admin-tokens)")
                                       : std::string("anyone (no tokens)"));
  if (options.reflection)
    spdlog::info("reflection on (--reflection): the API is described to any caller");
  if (impl->auth != nullptr || impl->admin_auth != nullptr) {
    Impl* raw = impl.get();
    impl->token_watch = std::thread([raw] { raw->WatchTokens(); });
  }
  if (impl->metrics != nullptr) {
    spdlog::info("metrics at http://{}/metrics (port {})", options.metrics_listen,
                 impl->metrics->port());
  }
  return std::unique_ptr<StylusServer>(new StylusServer(std::move(impl)));
}

int StylusServer::port() const { return impl_->port; }

absl::StatusOr<int> StylusServer::ReloadTokens() {
  if (impl_->auth == nullptr) {
    return absl::FailedPreconditionError("the server was started without --auth-tokens");
  }
  absl::StatusOr<int> n = impl_->auth->Reload();
  LogReload(*impl_->auth, n, "re-read");
  if (impl_->admin_auth != nullptr)
    LogReload(*impl_->admin_auth, impl_->admin_auth->Reload(), "re-read");
  return n;
}

int StylusServer::metrics_port() const {
  return impl_->metrics != nullptr ? impl_->metrics->port() : 0;
}

ServerLoad StylusServer::load() const {
  ServerLoad load;
  load.open_streams = impl_->context.open_streams.load();
  if (impl_->executor != nullptr) {
    load.queued_tasks = impl_->executor->queued();
    load.running_tasks = impl_->executor->running();
  }
  if (impl_->batcher != nullptr) {
    load.batches = impl_->batcher->batches();
    load.batched_steps = impl_->batcher->steps();
  }
  if (impl_->pass_batcher != nullptr) {
    load.unary_batches = impl_->pass_batcher->batches();
    load.batched_calls = impl_->pass_batcher->calls();
  }
  return load;
}

namespace {

// Waits, until `deadline` at the latest, for every accepted unary call to be
// answered and every drained stream to end, and then for the last answer to
// be a moment old. gRPC closes a connection as soon as its last call is over;
// closing a socket that still holds part of a large reply, or that still
// receives a stream's frames (its client sends on until it reads the end),
// resets the connection, and the client loses what it had not read yet: a
// 3000-frame Transfer answered just before shutdown, a drained stream's last
// frames and trailers.
void WaitForAnswers(const ServiceContext& context,
                    std::chrono::system_clock::time_point deadline) {
  constexpr auto kPoll = std::chrono::milliseconds(5);
  constexpr auto kLinger = std::chrono::milliseconds(300);
  while (std::chrono::system_clock::now() < deadline &&
         (context.unary_calls.load() > 0 || context.open_streams.load() > 0)) {
    std::this_thread::sleep_for(kPoll);
  }
  const auto last_answer = std::chrono::steady_clock::time_point(
      std::chrono::nanoseconds(context.last_answer_ns.load()));
  const auto linger_until = last_answer + kLinger;
  while (std::chrono::system_clock::now() < deadline &&
         std::chrono::steady_clock::now() < linger_until) {
    std::this_thread::sleep_for(kPoll);
  }
}

// A stream's session can outlive its call: one with an idle alarm set lives
// until the alarm's callback (cancelled when the call ends) has run on a
// gRPC thread, and then counts itself out of `context`. The context must
// outlive every session, so shutdown waits for the last one; the callbacks
// are due at once, so this wait is short.
void WaitForSessionsGone(const ServiceContext& context) {
  constexpr auto kPoll = std::chrono::milliseconds(1);
  constexpr auto kWarnEvery = std::chrono::seconds(5);
  auto warn_at = std::chrono::steady_clock::now() + kWarnEvery;
  while (context.open_streams.load() > 0) {
    if (std::chrono::steady_clock::now() >= warn_at) {
      spdlog::warn("shutting down: waiting for {} stream session(s) to end",
                   context.open_streams.load());
      warn_at += kWarnEvery;
    }
    std::this_thread::sleep_for(kPoll);
  }
}

}  // namespace

void StylusServer::Shutdown(std::chrono::system_clock::time_point deadline) {
  {
    absl::MutexLock lock(&impl_->mu);
    if (impl_->shut_down) return;
    impl_->shut_down = true;
  }
  impl_->server->GetHealthCheckService()->SetServingStatus(false);
  impl_->stop_watching.Notify();
  if (impl_->token_watch.joinable()) impl_->token_watch.join();
  ServiceContext& context = impl_->context;
  context.refusing_calls = true;
  // Streams stop taking frames, return the ones they took and end; unary
  // calls run to their end. Both until `deadline`, then they are cancelled.
  const int drained = context.streams.DrainAll();
  spdlog::info("shutting down: no new calls; {} open stream(s) drained, in-flight calls may finish",
               drained);
  WaitForAnswers(context, deadline);
  impl_->server->Shutdown(deadline);
  // Calls are over; the batcher runs the steps it holds, the executor what
  // it accepted; then both stop.
  {
    absl::MutexLock lock(&impl_->mu);
    impl_->workers_gone = true;
  }
  // The batcher takes no more steps (a queued stream task that submits
  // one is refused and ends its stream) and runs what it holds; then the
  // executor runs what it accepted; only then do both go, since those
  // tasks still reach the batcher through the context.
  if (impl_->batcher != nullptr) impl_->batcher->Stop();
  impl_->executor->Shutdown();
  impl_->executor.reset();
  context.batcher = nullptr;
  impl_->batcher.reset();
  WaitForSessionsGone(context);
  spdlog::info("shut down");
  impl_->done.Notify();
}

void StylusServer::Wait() { impl_->done.WaitForNotification(); }

}  // namespace stylus::server
