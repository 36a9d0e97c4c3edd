// The gRPC services: ModelService and StyleService (proto/stylus/v1). Each
// handler validates and converts the request, runs the model work on the
// executor, converts the result back and maps errors to a status in one place
// (server/status.h). No math here.
#ifndef STYLUS_SERVER_SERVICES_H_
#define STYLUS_SERVER_SERVICES_H_

#include "server/service_context.h"
#include "stylus/v1/stylus.grpc.pb.h"

namespace stylus::server {

// Every method takes its request as bytes (server/raw_message.h).
using ModelServiceBase = v1::ModelService::WithRawCallbackMethod_ListModels<
    v1::ModelService::WithRawCallbackMethod_GetModel<
        v1::ModelService::WithRawCallbackMethod_LoadModel<
            v1::ModelService::WithRawCallbackMethod_UnloadModel<v1::ModelService::Service>>>>;
using StyleServiceBase = v1::StyleService::WithRawCallbackMethod_Transfer<
    v1::StyleService::WithRawCallbackMethod_EncodeStyle<
        v1::StyleService::WithRawCallbackMethod_Interpolate<
            v1::StyleService::WithRawCallbackMethod_TransferStream<
                v1::StyleService::WithRawCallbackMethod_ComputeMetrics<
                    v1::StyleService::Service>>>>>;

class ModelServiceImpl final : public ModelServiceBase {
 public:
  explicit ModelServiceImpl(ServiceContext* service) : service_(service) {}

  grpc::ServerUnaryReactor* ListModels(grpc::CallbackServerContext* ctx,
                                       const grpc::ByteBuffer* request,
                                       grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* GetModel(grpc::CallbackServerContext* ctx,
                                     const grpc::ByteBuffer* request,
                                     grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* LoadModel(grpc::CallbackServerContext* ctx,
                                      const grpc::ByteBuffer* request,
                                      grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* UnloadModel(grpc::CallbackServerContext* ctx,
                                        const grpc::ByteBuffer* request,
                                        grpc::ByteBuffer* response) override;

 private:
  ServiceContext* service_;
};

class StyleServiceImpl final : public StyleServiceBase {
 public:
  explicit StyleServiceImpl(ServiceContext* service) : service_(service) {}

  grpc::ServerUnaryReactor* Transfer(grpc::CallbackServerContext* ctx,
                                     const grpc::ByteBuffer* request,
                                     grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* EncodeStyle(grpc::CallbackServerContext* ctx,
                                        const grpc::ByteBuffer* request,
                                        grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* Interpolate(grpc::CallbackServerContext* ctx,
                                        const grpc::ByteBuffer* request,
                                        grpc::ByteBuffer* response) override;
  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* TransferStream(
      grpc::CallbackServerContext* ctx) override;
  grpc::ServerUnaryReactor* ComputeMetrics(grpc::CallbackServerContext* ctx,
                                           const grpc::ByteBuffer* request,
                                           grpc::ByteBuffer* response) override;

 private:
  ServiceContext* service_;
};

// The style a StyleRef names, as a code of `model`: a clip is encoded, a name
// is looked up in the bank. INVALID_ARGUMENT for an empty ref, NOT_FOUND for an
// unknown name.
absl::StatusOr<model::StyleCode> ResolveStyle(const ServiceContext& service,
                                              const HostedModel& model, const v1::StyleRef& ref,
                                              const std::string& what);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_SERVICES_H_
