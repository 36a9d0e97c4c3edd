// Requests arrive as bytes and are parsed here, not by gRPC's generated
// handlers: those answer a request whose bytes do not parse with
// UNIMPLEMENTED (which tells a client the method does not exist) and end a
// stream as if the client had half-closed. Parsed here, such bytes end the
// call INVALID_ARGUMENT, naming the message expected.
#ifndef STYLUS_SERVER_RAW_MESSAGE_H_
#define STYLUS_SERVER_RAW_MESSAGE_H_

#include <google/protobuf/message.h>
#include <grpcpp/support/byte_buffer.h>

#include <string>

#include "absl/status/status.h"

namespace stylus::server {

// Parses `bytes` into `message` (cleared first). INVALID_ARGUMENT naming
// `what` and the message type when the bytes are not a serialized message of
// that type.
absl::Status ParseMessage(const grpc::ByteBuffer& bytes, const std::string& what,
                          google::protobuf::Message* message);

// Serializes `message` into `bytes`. INTERNAL only if protobuf refuses (a
// message over 2 GB).
absl::Status SerializeMessage(const google::protobuf::Message& message, grpc::ByteBuffer* bytes);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_RAW_MESSAGE_H_
