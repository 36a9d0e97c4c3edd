// The gRPC services: ModelService and StyleService (proto/stylus/v1). Each
// handler validates and converts the request, runs the model work on the
// executor, converts the result back and maps errors to a status in one place
// (server/status.h). No math here.
#ifndef STYLUS_SERVER_SERVICES_H_
#define STYLUS_SERVER_SERVICES_H_

#include "server/service_context.h"
#include "stylus/v1/stylus.grpc.pb.h"

namespace stylus::server {

class ModelServiceImpl final : public v1::ModelService::CallbackService {
 public:
  explicit ModelServiceImpl(ServiceContext* service) : service_(service) {}

  grpc::ServerUnaryReactor* ListModels(grpc::CallbackServerContext* ctx,
                                       const v1::ListModelsRequest* request,
                                       v1::ListModelsResponse* response) override;
  grpc::ServerUnaryReactor* GetModel(grpc::CallbackServerContext* ctx,
                                     const v1::GetModelRequest* request,
                                     v1::ModelInfo* response) override;
  grpc::ServerUnaryReactor* LoadModel(grpc::CallbackServerContext* ctx,
                                      const v1::LoadModelRequest* request,
                                      v1::ModelInfo* response) override;
  grpc::ServerUnaryReactor* UnloadModel(grpc::CallbackServerContext* ctx,
                                        const v1::UnloadModelRequest* request,
                                        v1::UnloadModelResponse* response) override;

 private:
  ServiceContext* service_;
};

class StyleServiceImpl final : public v1::StyleService::CallbackService {
 public:
  explicit StyleServiceImpl(ServiceContext* service) : service_(service) {}

  grpc::ServerUnaryReactor* Transfer(grpc::CallbackServerContext* ctx,
                                     const v1::TransferRequest* request,
                                     v1::TransferResponse* response) override;
  grpc::ServerUnaryReactor* EncodeStyle(grpc::CallbackServerContext* ctx,
                                        const v1::EncodeStyleRequest* request,
                                        v1::EncodeStyleResponse* response) override;
  grpc::ServerUnaryReactor* Interpolate(grpc::CallbackServerContext* ctx,
                                        const v1::InterpolateRequest* request,
                                        v1::TransferResponse* response) override;
  grpc::ServerBidiReactor<v1::StreamRequest, v1::StreamResponse>* TransferStream(
      grpc::CallbackServerContext* ctx) override;
  grpc::ServerUnaryReactor* ComputeMetrics(grpc::CallbackServerContext* ctx,
                                           const v1::MetricsRequest* request,
                                           v1::MetricsResponse* response) override;

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
