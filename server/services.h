// The gRPC services: ModelService and StyleService (proto/stylus/v1). Each
// method checks its caller, then validates and converts the request, runs
// the model work on the executor, converts the result back and maps errors
// to a status in one place (server/status.h). No math here.
#ifndef STYLUS_SERVER_SERVICES_H_
#define STYLUS_SERVER_SERVICES_H_

#include <google/protobuf/descriptor.h>
#include <grpc/support/log.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "server/service_context.h"
#include "server/unary_call.h"
#include "stylus/v1/stylus.grpc.pb.h"

namespace stylus::server {

// A generated service whose methods are all served by callback reactors
// that take bytes (server/raw_message.h): unary methods through
// server/unary_call.h (registered as streams, so that nothing of a request
// is read before its caller is let in), TransferStream as a stream session.
// No method is left to gRPC's synchronous thread pool.
template <class Base>
class CallbackService : public Base {
 protected:
  using Reactor = grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>;
  using Factory = std::function<Reactor*(grpc::CallbackServerContext*)>;
  using Handler = grpc::internal::CallbackBidiHandler<grpc::ByteBuffer, grpc::ByteBuffer>;

  CallbackService(ServiceContext* service, const char* name) : service_(service), name_(name) {}

  void ServeUnary(UnaryMethod method) {
    const int index = MethodIndex(method.rpc);
    methods_.push_back(std::make_unique<UnaryMethod>(std::move(method)));
    const UnaryMethod* m = methods_.back().get();
    ServiceContext* service = service_;
    const Factory factory = [service, m](grpc::CallbackServerContext* ctx) {
      return StartUnaryCall(service, ctx, m);
    };
    // First a stream on the wire (gRPC then reads no request before the
    // handler asks), then served by callback (this replaces the handler).
    this->MarkMethodStreamed(index, new Handler(factory));
    this->MarkMethodRawCallback(index, new Handler(factory));
  }
  void ServeStream(const std::string& rpc, Factory factory) {
    this->MarkMethodRawCallback(MethodIndex(rpc), new Handler(std::move(factory)));
  }

  ServiceContext* const service_;

 private:
  // Generated services number their methods in the .proto's order.
  int MethodIndex(const std::string& rpc) const {
    const google::protobuf::ServiceDescriptor* d =
        google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(name_);
    const google::protobuf::MethodDescriptor* m = d != nullptr ? d->FindMethodByName(rpc) : nullptr;
    GPR_ASSERT(m != nullptr);
    return m->index();
  }
  const char* const name_;
  std::vector<std::unique_ptr<UnaryMethod>> methods_;
};

class ModelServiceImpl final : public CallbackService<v1::ModelService::Service> {
 public:
  explicit ModelServiceImpl(ServiceContext* service);
};

class StyleServiceImpl final : public CallbackService<v1::StyleService::Service> {
 public:
  explicit StyleServiceImpl(ServiceContext* service);

 private:
  UnaryMethod Transfer();
  UnaryMethod EncodeStyle();
  UnaryMethod Interpolate();
  UnaryMethod ComputeMetrics();
};

// The style a StyleRef names, as a code of `model`: a clip is encoded, a name
// is looked up in the bank. INVALID_ARGUMENT for an empty ref, NOT_FOUND for an
// unknown name.
absl::StatusOr<model::StyleCode> ResolveStyle(const ServiceContext& service,
                                              const HostedModel& model, const v1::StyleRef& ref,
                                              const std::string& what);

// What movement from examples may draw on for a style: the server's style
// library, and the style's label there when `ref` names a saved style whose
// name is one of the library's styles (else the nearest by code).
model::MovementRequest MovementFor(const ServiceContext& service, const v1::StyleRef& ref);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVICES_H_
