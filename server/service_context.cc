#include "server/service_context.h"

#include <chrono>
#include <string>

#include "absl/strings/str_cat.h"
#include "server/status.h"
#include "spdlog/spdlog.h"
#include "wire/wire.h"

namespace stylus::server {

void MarkAnswered(ServiceContext* service) {
  service->last_answer_ns.store(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                    std::chrono::steady_clock::now().time_since_epoch())
                                    .count());
}

namespace {

absl::string_view Authorization(const grpc::CallbackServerContext* ctx, bool* present) {
  const auto& metadata = ctx->client_metadata();
  const auto it = metadata.find("authorization");
  *present = it != metadata.end();
  return *present ? absl::string_view(it->second.data(), it->second.size()) : absl::string_view();
}

}  // namespace

absl::Status CheckAccess(const ServiceContext& service, const grpc::CallbackServerContext* ctx,
                         Access access) {
  if (service.auth == nullptr && service.admin_auth == nullptr) return absl::OkStatus();
  bool present = false;
  const absl::string_view value = Authorization(ctx, &present);
  const bool admin = service.admin_auth != nullptr && service.admin_auth->Allows(value);
  if (admin) return absl::OkStatus();
  const bool serving = service.auth == nullptr || service.auth->Allows(value);
  if (access == Access::kServe && serving) return absl::OkStatus();
  if (access == Access::kAdmin && present && service.auth != nullptr && serving) {
    return absl::PermissionDeniedError(
        service.admin_auth != nullptr
            ? "loading and unloading models needs an admin token (--admin-tokens); this token "
              "may only serve"
            : "loading and unloading models needs an admin token, and this server has none "
              "(start it with --admin-tokens FILE); its models are the ones it started with");
  }
  if (!present) {
    return absl::UnauthenticatedError(
        "this server needs a token: send the metadata 'authorization: Bearer TOKEN' "
        "(stylus --token, $STYLUS_TOKEN)");
  }
  return absl::UnauthenticatedError("the token is not one this server accepts");
}

absl::Status CheckRequestBudget(const ServiceContext& service, const grpc::ByteBuffer& bytes,
                                const google::protobuf::Descriptor* type, const std::string& what) {
  if (service.budget == nullptr) return absl::OkStatus();
  return service.budget->Check(bytes, type, what);
}

absl::StatusOr<MemoryHold> ReserveCall(const ServiceContext& service, const grpc::ByteBuffer& bytes,
                                       const google::protobuf::Descriptor* type) {
  int64_t parse = 0;
  if (service.budget != nullptr) {
    if (absl::Status s = service.budget->Check(bytes, type, "the request", &parse); !s.ok())
      return s;
  }
  const int64_t need =
      parse + static_cast<int64_t>(bytes.Length()) * (1 + kWorkingBytesPerRequestByte);
  if (service.call_memory != nullptr && need > service.call_memory->capacity()) {
    return absl::ResourceExhaustedError(absl::StrCat("this call would need about ", need >> 20,
                                                     " MB to serve, more than this server gives "
                                                     "all calls together (--max-memory-mb ",
                                                     service.call_memory->capacity() >> 20,
                                                     "): send a shorter clip, or stream it"));
  }
  MemoryHold hold(service.call_memory, need);
  if (!hold.ok()) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the server's memory for calls in progress is in use (--max-memory-mb ",
                     service.call_memory->capacity() >> 20, "; this call needs about ", need >> 20,
                     " MB): retry with backoff, or send a shorter clip"));
  }
  return hold;
}

}  // namespace stylus::server
