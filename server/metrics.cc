#include "server/metrics.h"

#include <prometheus/client_metric.h>
#include <prometheus/collectable.h>
#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/metric_family.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>
#include <unistd.h>

#include <exception>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "server/http_endpoint.h"

namespace stylus::server {
namespace {

using prometheus::Labels;

// Latency buckets from 1 ms to ~30 s.
prometheus::Histogram::BucketBoundaries SecondsBuckets() {
  return {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30};
}

long ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

prometheus::MetricFamily Gauge(const std::string& name, const std::string& help, double value) {
  prometheus::MetricFamily f;
  f.name = name;
  f.help = help;
  f.type = prometheus::MetricType::Gauge;
  prometheus::ClientMetric m;
  m.gauge.value = value;
  f.metric.push_back(m);
  return f;
}

// The series read at scrape time.
class StateCollectable : public prometheus::Collectable {
 public:
  explicit StateCollectable(std::function<MetricsState()> state) : state_(std::move(state)) {}
  std::vector<prometheus::MetricFamily> Collect() const override {
    const MetricsState s = state_();
    return {
        Gauge("stylus_open_streams", "TransferStream calls open now.", s.open_streams),
        Gauge("stylus_executor_queued_tasks", "Compute work accepted and waiting for a thread.",
              s.queued_tasks),
        Gauge("stylus_executor_running_tasks", "Compute work running now.", s.running_tasks),
        Gauge("stylus_loaded_models", "Model packages loaded.", s.loaded_models),
        Gauge("stylus_unary_batches", "Unary network passes run for several calls (--batch-unary).",
              static_cast<double>(s.unary_batches)),
        Gauge("stylus_unary_batched_calls", "Calls those batched passes held.",
              static_cast<double>(s.batched_calls)),
        Gauge("process_resident_memory_bytes", "Resident memory of the server process.",
              static_cast<double>(ResidentBytes())),
    };
  }

 private:
  std::function<MetricsState()> state_;
};

}  // namespace

struct Metrics::Impl {
  std::shared_ptr<prometheus::Registry> registry = std::make_shared<prometheus::Registry>();
  std::shared_ptr<StateCollectable> state;
  std::unique_ptr<HttpEndpoint> endpoint;
  prometheus::Family<prometheus::Counter>& started = prometheus::BuildCounter()
                                                         .Name("grpc_server_started_total")
                                                         .Help("RPCs started on the server.")
                                                         .Register(*registry);
  prometheus::Family<prometheus::Counter>& handled =
      prometheus::BuildCounter()
          .Name("grpc_server_handled_total")
          .Help("RPCs completed on the server, by status code.")
          .Register(*registry);
  prometheus::Family<prometheus::Counter>& received = prometheus::BuildCounter()
                                                          .Name("grpc_server_msg_received_total")
                                                          .Help("Messages received from clients.")
                                                          .Register(*registry);
  prometheus::Family<prometheus::Counter>& sent = prometheus::BuildCounter()
                                                      .Name("grpc_server_msg_sent_total")
                                                      .Help("Messages sent to clients.")
                                                      .Register(*registry);
  prometheus::Family<prometheus::Histogram>& handling =
      prometheus::BuildHistogram()
          .Name("grpc_server_handling_seconds")
          .Help("Seconds from an RPC's start to its end.")
          .Register(*registry);
  prometheus::Family<prometheus::Histogram>& model_seconds =
      prometheus::BuildHistogram()
          .Name("stylus_model_seconds")
          .Help("Compute seconds of a unary call's model work or of a batch of live steps.")
          .Register(*registry);
  prometheus::Family<prometheus::Counter>& frames =
      prometheus::BuildCounter()
          .Name("stylus_frames_total")
          .Help("Frames transferred (unary: the content's; stream: frames received).")
          .Register(*registry);
  prometheus::Histogram& stream_frame_seconds =
      prometheus::BuildHistogram()
          .Name("stylus_stream_frame_seconds")
          .Help("Seconds from reading the frame that made an output frame final to queueing it.")
          .Register(*registry)
          .Add({}, SecondsBuckets());
  prometheus::Family<prometheus::Counter>& guard_backoffs =
      prometheus::BuildCounter()
          .Name("stylus_guard_backoffs_total")
          .Help("Transfers whose content guard chose a weaker form than the configured one.")
          .Register(*registry);
  prometheus::Histogram& step_batch =
      prometheus::BuildHistogram()
          .Name("stylus_step_batch_streams")
          .Help("Live streams' steps in one batched forward pass.")
          .Register(*registry)
          .Add({}, prometheus::Histogram::BucketBoundaries{1, 2, 4, 8, 16, 32, 64, 128, 256, 512});

  absl::Mutex mu;
  std::map<std::string, std::unique_ptr<Metrics::Rpc>> rpcs ABSL_GUARDED_BY(mu);
};

absl::StatusOr<std::unique_ptr<Metrics>> Metrics::Start(const std::string& listen,
                                                        std::function<MetricsState()> state) {
  auto impl = std::make_unique<Impl>();
  impl->state = std::make_shared<StateCollectable>(std::move(state));
  Impl* raw = impl.get();
  absl::StatusOr<std::unique_ptr<HttpEndpoint>> endpoint =
      HttpEndpoint::Start(listen, "/metrics", [raw] {
        std::vector<prometheus::MetricFamily> families = raw->registry->Collect();
        for (prometheus::MetricFamily& f : raw->state->Collect()) families.push_back(std::move(f));
        return prometheus::TextSerializer().Serialize(families);
      });
  if (!endpoint.ok()) {
    return absl::Status(endpoint.status().code(),
                        absl::StrCat("metrics: ", endpoint.status().message()));
  }
  impl->endpoint = *std::move(endpoint);
  return std::unique_ptr<Metrics>(new Metrics(std::move(impl)));
}

Metrics::Metrics(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Metrics::~Metrics() = default;

int Metrics::port() const { return impl_->endpoint->port(); }

struct Metrics::Rpc {
  Labels labels;
  prometheus::Counter* started;
  prometheus::Counter* received;
  prometheus::Counter* sent;
  prometheus::Histogram* handling;
};

const Metrics::Rpc* Metrics::Series(const std::string& service, const std::string& method,
                                    const char* type) {
  const std::string key = absl::StrCat(service, "/", method, "/", type);
  absl::MutexLock lock(&impl_->mu);
  std::unique_ptr<Rpc>& rpc = impl_->rpcs[key];
  if (rpc == nullptr) {
    const Labels labels = {{"grpc_service", service}, {"grpc_method", method}, {"grpc_type", type}};
    rpc = std::make_unique<Rpc>(Rpc{labels, &impl_->started.Add(labels),
                                    &impl_->received.Add(labels), &impl_->sent.Add(labels),
                                    &impl_->handling.Add(labels, SecondsBuckets())});
  }
  return rpc.get();
}

void Metrics::CallStarted(const Rpc* rpc) { rpc->started->Increment(); }

void Metrics::CallHandled(const Rpc* rpc, absl::StatusCode code, double seconds) {
  rpc->handling->Observe(seconds);
  Labels labels = rpc->labels;
  labels["grpc_code"] = absl::StatusCodeToString(code);
  impl_->handled.Add(labels).Increment();
}

void Metrics::MessageReceived(const Rpc* rpc) { rpc->received->Increment(); }

void Metrics::MessageSent(const Rpc* rpc) { rpc->sent->Increment(); }

void Metrics::ModelSeconds(const std::string& model, double seconds) {
  impl_->model_seconds.Add({{"model", model}}, SecondsBuckets()).Observe(seconds);
}

void Metrics::Frames(const std::string& model, const char* kind, int64_t frames) {
  impl_->frames.Add({{"model", model}, {"kind", kind}}).Increment(static_cast<double>(frames));
}

void Metrics::StreamFrameSeconds(double seconds) { impl_->stream_frame_seconds.Observe(seconds); }

void Metrics::GuardBackoff(const std::string& model) {
  impl_->guard_backoffs.Add({{"model", model}}).Increment();
}

void Metrics::StepBatch(int64_t streams) {
  impl_->step_batch.Observe(static_cast<double>(streams));
}

}  // namespace stylus::server
