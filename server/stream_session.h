// One TransferStream call: a bidirectional reactor that never blocks gRPC's
// threads. Each request is handled on the executor, one at a time per stream
// (the next read starts when the previous request is done, which also paces
// a client that sends faster than the model runs); stylized frames are
// written as they become final, one write in flight at a time.
//
// Protocol: the first request must be `config`; every later one a `frame`
// whose index is one more than the previous frame's (the first may start
// anywhere). When the client half-closes, the remaining frames are flushed
// and the call ends OK. Errors end the call with the status of the first
// problem (INVALID_ARGUMENT, NOT_FOUND, RESOURCE_EXHAUSTED, ...); a message
// whose bytes do not parse as a StreamRequest is INVALID_ARGUMENT.
#ifndef STYLUS_SERVER_STREAM_SESSION_H_
#define STYLUS_SERVER_STREAM_SESSION_H_

#include <grpcpp/grpcpp.h>

#include "server/service_context.h"
#include "stylus/v1/stylus.grpc.pb.h"

namespace stylus::server {

// Starts a session for `ctx`; it deletes itself when the call is done.
grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* StartStreamSession(
    ServiceContext* service, grpc::CallbackServerContext* ctx);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_STREAM_SESSION_H_
