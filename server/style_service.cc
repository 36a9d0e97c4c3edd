#include <chrono>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "motion/metrics.h"
#include "server/postprocess_option.h"
#include "server/services.h"
#include "server/stream_session.h"
#include "wire/wire.h"

namespace stylus::server {
namespace {

double MsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// What Transfer and Interpolate both start from.
struct ContentCall {
  HostedModel model;
  motion::PostProcessMode post = motion::PostProcessMode::kFull;
  motion::Motion content;
  motion::JointMap joint_map;  // The content clip's, for another rig than the model's.
};

// Resolves the model (recording its id in `out`), the post-processing mode
// and the content clip.
absl::StatusOr<ContentCall> StartContentCall(const ServiceContext& service,
                                             const std::string& model_id, v1::PostProcess post,
                                             const v1::Clip& content, CallOutcome* out) {
  ContentCall call;
  absl::StatusOr<HostedModel> m = service.registry->Get(model_id);
  if (!m.ok()) return m.status();
  call.model = *std::move(m);
  out->model = call.model.id;
  absl::StatusOr<motion::PostProcessMode> mode = ToPostProcessMode(post);
  if (!mode.ok()) return mode.status();
  call.post = *mode;
  absl::StatusOr<motion::Motion> clip = wire::ClipFromProto(content, "content clip");
  if (!clip.ok()) return clip.status();
  call.content = *std::move(clip);
  absl::StatusOr<motion::JointMap> map =
      wire::JointMapFromProto(content.skeleton(), "content clip");
  if (!map.ok()) return map.status();
  call.joint_map = *std::move(map);
  return call;
}

// What a model's content guard did, in the response and the call's log line.
void NoteGuard(const model::TransferNote& note, v1::TransferResponse* response, CallOutcome* out) {
  if (!note.guarded) return;
  v1::ContentGuardNote* g = response->mutable_content_guard();
  g->set_backed_off(note.backed_off);
  g->set_residual_strength(note.residual_strength);
  out->note = note.backed_off ? absl::StrCat("guard=residual:", note.residual_strength)
                              : "guard=configured";
  out->guard_backoff = note.backed_off;
}

void NoteMovement(const model::MovementNote& note, const model::StyleModel& model,
                  v1::TransferResponse* response, CallOutcome* out) {
  if (!model.moves_from_examples()) return;
  v1::MovementNote* m = response->mutable_movement();
  m->set_applied(note.applied);
  m->set_example(note.example);
  m->set_kind(note.kind);
  m->set_fit(note.cost);
  m->set_reason(note.reason);
  absl::StrAppend(&out->note, out->note.empty() ? "" : " ",
                  note.applied ? absl::StrCat("movement=", note.kind) : "movement=network");
}

void NoteContacts(const std::optional<model::TransferResult::Contacts>& contacts,
                  v1::TransferResponse* response) {
  if (!contacts) return;
  static const char* kJoints[4] = {"left_ankle", "left_toe", "right_ankle", "right_toe"};
  for (int k = 0; k < 4; ++k) {
    for (const motion::ContactSpan& s : (*contacts)[k]) {
      v1::FootContact* c = response->add_contacts();
      c->set_joint(kJoints[k]);
      c->set_begin(s.begin);
      c->set_end(s.end);
    }
  }
}

}  // namespace

model::MovementRequest MovementFor(const ServiceContext& service, const v1::StyleRef& ref) {
  model::MovementRequest r;
  r.library = service.style_library;
  if (r.library != nullptr && ref.source_case() == v1::StyleRef::kName) {
    for (const std::string& s : r.library->Styles()) {
      if (s == ref.name()) r.style_label = s;
    }
  }
  return r;
}

absl::StatusOr<model::StyleCode> ResolveStyle(const ServiceContext& service,
                                              const HostedModel& model, const v1::StyleRef& ref,
                                              const std::string& what) {
  switch (ref.source_case()) {
    case v1::StyleRef::kName:
      return service.styles->Get(model.id, ref.name());
    case v1::StyleRef::kClip: {
      absl::StatusOr<motion::Motion> clip = wire::ClipFromProto(ref.clip(), what);
      if (!clip.ok()) return clip.status();
      absl::StatusOr<motion::JointMap> map = wire::JointMapFromProto(ref.clip().skeleton(), what);
      if (!map.ok()) return map.status();
      return model.model->EncodeStyle(*clip, *map);
    }
    default:
      return absl::InvalidArgumentError(absl::StrCat(what, ": give a clip or a saved style name"));
  }
}

UnaryMethod StyleServiceImpl::Transfer() {
  return MakeUnaryMethod<v1::TransferRequest, v1::TransferResponse>(
      service_, kStyleService, "Transfer", Access::kServe,
      [this](const v1::TransferRequest& request, v1::TransferResponse* response) {
        const auto t0 = std::chrono::steady_clock::now();
        CallOutcome out{absl::OkStatus(), request.model(), request.content().frames_size()};
        absl::StatusOr<ContentCall> call = StartContentCall(
            *service_, request.model(), request.postprocess(), request.content(), &out);
        if (!call.ok()) return out.status = call.status(), out;
        absl::StatusOr<model::StyleCode> style =
            ResolveStyle(*service_, call->model, request.style(), "style clip");
        if (!style.ok()) return out.status = style.status(), out;
        model::TransferOptions options(call->post);
        options.batcher = service_->pass_batcher;
        options.joint_map = call->joint_map;
        options.movement = MovementFor(*service_, request.style());
        options.fit_frames = request.fit_frames();
        if (request.fit_frames() < 0) {
          return out.status = absl::InvalidArgumentError(
                     absl::StrCat("fit_frames ", request.fit_frames(), " is negative")),
                 out;
        }
        switch (request.timing()) {
          case v1::TIMING_CONTENT:
            break;
          case v1::TIMING_STYLE:
            options.timing = model::Timing::kStyle;
            break;
          default:
            return out.status = absl::InvalidArgumentError(
                       absl::StrCat("timing: unknown value ", request.timing(),
                                    " (TIMING_CONTENT or TIMING_STYLE)")),
                   out;
        }
        absl::StatusOr<model::TransferResult> result =
            call->model.model->Transfer(call->content, *style, options);
        if (!result.ok()) return out.status = result.status(), out;
        NoteGuard(result->note, response, &out);
        NoteMovement(result->movement, *call->model.model, response, &out);
        NoteContacts(result->contacts, response);
        if (options.timing == model::Timing::kStyle || options.fit_frames > 0) {
          const model::TimeWarpNote& warp = result->warp;
          v1::TimeWarp* w = response->mutable_time_warp();
          w->set_applied(warp.applied);
          w->set_ratio(warp.ratio);
          w->set_content_period_s(warp.content_period_s);
          w->set_style_period_s(warp.style_period_s);
          w->set_reason(warp.reason);
          w->mutable_content_time_s()->Add(warp.content_time_s.begin(), warp.content_time_s.end());
        }
        wire::ClipToProto(result->motion, response->mutable_output());
        response->set_model(call->model.id);
        response->set_compute_ms(MsSince(t0));
        out.model_seconds = response->compute_ms() / 1000;
        return out;
      });
}

UnaryMethod StyleServiceImpl::EncodeStyle() {
  return MakeUnaryMethod<v1::EncodeStyleRequest, v1::EncodeStyleResponse>(
      service_, kStyleService, "EncodeStyle", Access::kServe,
      [this](const v1::EncodeStyleRequest& request, v1::EncodeStyleResponse* response) {
        CallOutcome out{absl::OkStatus(), request.model(), request.clip().frames_size()};
        absl::StatusOr<HostedModel> m = service_->registry->Get(request.model());
        if (!m.ok()) return out.status = m.status(), out;
        out.model = m->id;
        absl::StatusOr<motion::Motion> clip = wire::ClipFromProto(request.clip(), "style clip");
        if (!clip.ok()) return out.status = clip.status(), out;
        absl::StatusOr<motion::JointMap> map =
            wire::JointMapFromProto(request.clip().skeleton(), "style clip");
        if (!map.ok()) return out.status = map.status(), out;
        absl::StatusOr<model::StyleCode> code = m->model->EncodeStyle(*clip, *map);
        if (!code.ok()) return out.status = code.status(), out;
        if (!request.save_as().empty()) {
          out.status = service_->styles->Save(m->id, request.save_as(), *code);
          if (!out.status.ok()) return out;
          response->set_name(request.save_as());
        }
        response->mutable_code()->Add(code->values.begin(), code->values.end());
        response->set_model(m->id);
        return out;
      });
}

UnaryMethod StyleServiceImpl::Interpolate() {
  return MakeUnaryMethod<v1::InterpolateRequest, v1::TransferResponse>(
      service_, kStyleService, "Interpolate", Access::kServe,
      [this](const v1::InterpolateRequest& request, v1::TransferResponse* response) {
        const auto t0 = std::chrono::steady_clock::now();
        CallOutcome out{absl::OkStatus(), request.model(), request.content().frames_size()};
        absl::StatusOr<ContentCall> call = StartContentCall(
            *service_, request.model(), request.postprocess(), request.content(), &out);
        if (!call.ok()) return out.status = call.status(), out;
        if (request.styles_size() < 2) {
          out.status = absl::InvalidArgumentError(
              absl::StrCat("Interpolate needs two or more styles, got ", request.styles_size()));
          return out;
        }
        std::vector<model::StyleCode> styles;
        for (int i = 0; i < request.styles_size(); ++i) {
          absl::StatusOr<model::StyleCode> s =
              ResolveStyle(*service_, call->model, request.styles(i), absl::StrCat("style ", i));
          if (!s.ok()) return out.status = s.status(), out;
          styles.push_back(*std::move(s));
        }
        model::StyleWeights weights;
        if (request.schedule_size() > 0) {
          for (const v1::Weights& row : request.schedule())
            weights.per_frame.emplace_back(row.values().begin(), row.values().end());
        } else {
          weights.fixed.assign(request.weights().values().begin(),
                               request.weights().values().end());
        }
        model::TransferOptions options(call->post);
        options.batcher = service_->pass_batcher;
        options.joint_map = call->joint_map;
        // The movement is the dominant style's (model/movement.h).
        size_t main = 0;
        const std::vector<double>& w = weights.fixed;
        for (size_t k = 1; k < w.size(); ++k) main = w[k] > w[main] ? k : main;
        options.movement = MovementFor(*service_, request.styles(static_cast<int>(main)));
        absl::StatusOr<model::TransferResult> result =
            call->model.model->Interpolate(call->content, styles, weights, options);
        if (!result.ok()) return out.status = result.status(), out;
        NoteGuard(result->note, response, &out);
        NoteMovement(result->movement, *call->model.model, response, &out);
        NoteContacts(result->contacts, response);
        wire::ClipToProto(result->motion, response->mutable_output());
        response->set_model(call->model.id);
        response->set_compute_ms(MsSince(t0));
        out.model_seconds = response->compute_ms() / 1000;
        return out;
      });
}

UnaryMethod StyleServiceImpl::ComputeMetrics() {
  return MakeUnaryMethod<v1::MetricsRequest, v1::MetricsResponse>(
      service_, kStyleService, "ComputeMetrics", Access::kServe,
      [this](const v1::MetricsRequest& request, v1::MetricsResponse* response) {
        CallOutcome out{absl::OkStatus(), "", request.output().frames_size()};
        absl::StatusOr<motion::Motion> output =
            wire::ClipFromProto(request.output(), "output clip");
        if (!output.ok()) return out.status = output.status(), out;
        std::optional<motion::Motion> content;
        if (request.has_content()) {
          absl::StatusOr<motion::Motion> c = wire::ClipFromProto(request.content(), "content clip");
          if (!c.ok()) return out.status = c.status(), out;
          content = *std::move(c);
        }
        absl::StatusOr<std::map<std::string, double>> metrics =
            motion::ComputeMetrics(*output, content ? &*content : nullptr);
        if (!metrics.ok()) return out.status = metrics.status(), out;
        for (const auto& [k, v] : *metrics) (*response->mutable_metrics())[k] = v;
        // The same kinematic measures of the inputs, as baselines for the output's.
        for (const auto& [prefix, clip] : std::vector<std::pair<std::string, const v1::Clip*>>{
                 {"content_", request.has_content() ? &request.content() : nullptr},
                 {"style_", request.has_style() ? &request.style() : nullptr}}) {
          if (clip == nullptr) continue;
          absl::StatusOr<motion::Motion> m = wire::ClipFromProto(*clip, prefix + "clip");
          if (!m.ok()) return out.status = m.status(), out;
          absl::StatusOr<std::map<std::string, double>> own = motion::ComputeMetrics(*m, nullptr);
          if (!own.ok()) return out.status = own.status(), out;
          for (const char* k : {"foot_skating", "jitter", "bone_length_error"})
            (*response->mutable_metrics())[prefix + k] = own->at(k);
        }
        return out;
      });
}

StyleServiceImpl::StyleServiceImpl(ServiceContext* service)
    : CallbackService(service, kStyleService) {
  ServeUnary(Transfer());
  ServeUnary(EncodeStyle());
  ServeUnary(Interpolate());
  ServeUnary(ComputeMetrics());
  ServeStream("TransferStream", [service](grpc::CallbackServerContext* ctx) {
    return StartStreamSession(service, ctx);
  });
}

}  // namespace stylus::server
