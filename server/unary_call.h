// The unary call pattern of every ModelService/StyleService method, with the
// caller checked before any of its request is read.
//
// gRPC reads a unary method's whole request before its handler runs, so a
// server that checks tokens in the handler has already taken in whatever an
// anonymous caller sent. These methods are registered with gRPC as
// streams of one request and one response (the same bytes on the wire, so
// every unary client works unchanged): the call is let in (token, rights,
// shutdown, the --max-unary-calls cap) before its request is read; the
// request is then read, checked against the request budget
// (server/request_budget.h) and parsed on the executor; the call counts as
// answered only once gRPC is done with it (its reply handed to the
// transport), which shutdown waits for.
#ifndef STYLUS_SERVER_UNARY_CALL_H_
#define STYLUS_SERVER_UNARY_CALL_H_

#include <google/protobuf/arena.h>
#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <string>

#include "server/call_log.h"
#include "server/raw_message.h"
#include "server/service_context.h"

namespace stylus::server {

// One unary method: its names, who may call it, and its work on the
// request's bytes (run on the executor; fills `response` when OK).
struct UnaryMethod {
  const char* grpc_service = nullptr;
  std::string rpc;
  Access access = Access::kServe;
  std::function<CallOutcome(const grpc::ByteBuffer& request, grpc::ByteBuffer* response)> run;
};

// The reactor of one call of `method` (owned by itself; deleted when gRPC is
// done with the call). Counted in the metrics (when on) under the method's
// service and name.
grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* StartUnaryCall(
    ServiceContext* service, grpc::CallbackServerContext* ctx, const UnaryMethod* method);

// A method whose request is a Request and whose reply is a Response: checks
// the request's bytes against the service's budget, parses them (on an
// arena, freed with the call's work), runs `work` and serializes its
// response.
template <class Request, class Response>
UnaryMethod MakeUnaryMethod(
    ServiceContext* service, const char* grpc_service, const std::string& rpc, Access access,
    std::function<CallOutcome(const Request& request, Response* response)> work) {
  UnaryMethod m;
  m.grpc_service = grpc_service;
  m.rpc = rpc;
  m.access = access;
  m.run = [service, work = std::move(work)](const grpc::ByteBuffer& bytes,
                                            grpc::ByteBuffer* raw_response) {
    CallOutcome out;
    absl::StatusOr<MemoryHold> hold = ReserveCall(*service, bytes, Request::descriptor());
    if (!hold.ok()) return out.status = hold.status(), out;
    google::protobuf::Arena arena;
    Request* request = google::protobuf::Arena::CreateMessage<Request>(&arena);
    out.status = ParseMessage(bytes, "the request", request);
    if (!out.status.ok()) return out;
    Response* response = google::protobuf::Arena::CreateMessage<Response>(&arena);
    out = work(*request, response);
    if (out.status.ok()) out.status = SerializeMessage(*response, raw_response);
    return out;
  };
  return m;
}

}  // namespace stylus::server

#endif  // STYLUS_SERVER_UNARY_CALL_H_
