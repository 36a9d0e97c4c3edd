#include "server/services.h"
#include "wire/wire.h"

namespace stylus::server {
namespace {

void Describe(const HostedModel& m, const std::string& default_id, const StyleBank* styles,
              v1::ModelInfo* out) {
  const model::DataFiles& p = m.model->data();
  const model::ModelSummary summary = m.model->summary();
  out->set_id(m.id);
  out->set_family(summary.family);
  out->set_version(m.id.substr(m.id.find('/') + 1));
  wire::SkeletonToProto(p.skeleton, out->mutable_skeleton());
  out->set_fps(1.0 / p.frame_time);
  out->set_window(summary.window);
  out->set_hop(summary.hop);
  out->set_trained_iterations(summary.trained_iterations);
  out->set_is_default(m.id == default_id);
  out->set_live(summary.live);
  out->set_lookahead(summary.lookahead);
  if (styles != nullptr) {
    for (const std::string& name : styles->Names(m.id)) out->add_saved_styles(name);
  }
}

}  // namespace

ModelServiceImpl::ModelServiceImpl(ServiceContext* service)
    : CallbackService(service, kModelService) {
  ServeUnary(MakeUnaryMethod<v1::ListModelsRequest, v1::ListModelsResponse>(
      service_, kModelService, "ListModels", Access::kServe,
      [this](const v1::ListModelsRequest&, v1::ListModelsResponse* response) {
        const std::string def = service_->registry->default_id();
        for (const HostedModel& m : service_->registry->List())
          Describe(m, def, service_->styles, response->add_models());
        return CallOutcome{absl::OkStatus(), "", 0};
      }));
  ServeUnary(MakeUnaryMethod<v1::GetModelRequest, v1::ModelInfo>(
      service_, kModelService, "GetModel", Access::kServe,
      [this](const v1::GetModelRequest& request, v1::ModelInfo* response) {
        absl::StatusOr<HostedModel> m = service_->registry->Get(request.model());
        if (!m.ok()) return CallOutcome{m.status(), request.model(), 0};
        Describe(*m, service_->registry->default_id(), service_->styles, response);
        return CallOutcome{absl::OkStatus(), m->id, 0};
      }));
  ServeUnary(MakeUnaryMethod<v1::LoadModelRequest, v1::ModelInfo>(
      service_, kModelService, "LoadModel", Access::kAdmin,
      [this](const v1::LoadModelRequest& request, v1::ModelInfo* response) {
        absl::StatusOr<HostedModel> m = service_->registry->Load(request.model());
        if (!m.ok()) return CallOutcome{m.status(), request.model(), 0};
        Describe(*m, service_->registry->default_id(), service_->styles, response);
        return CallOutcome{absl::OkStatus(), m->id, 0};
      }));
  ServeUnary(MakeUnaryMethod<v1::UnloadModelRequest, v1::UnloadModelResponse>(
      service_, kModelService, "UnloadModel", Access::kAdmin,
      [this](const v1::UnloadModelRequest& request, v1::UnloadModelResponse*) {
        return CallOutcome{service_->registry->Unload(request.model()), request.model(), 0};
      }));
}

}  // namespace stylus::server
