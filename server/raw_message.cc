#include "server/raw_message.h"

#include <grpcpp/impl/codegen/proto_utils.h>
#include <grpcpp/support/proto_buffer_reader.h>
#include <grpcpp/support/proto_buffer_writer.h>

#include "absl/strings/str_cat.h"

namespace stylus::server {

absl::Status ParseInto(const grpc::ByteBuffer& bytes, google::protobuf::Message* message) {
  message->Clear();
  // The reader consumes its buffer; a copy shares the slices (no byte copy).
  grpc::ByteBuffer copy(bytes);
  grpc::ProtoBufferReader reader(&copy);
  if (reader.status().ok() && message->ParseFromZeroCopyStream(&reader)) {
    return absl::OkStatus();
  }
  message->Clear();
  return absl::InvalidArgumentError(absl::StrCat("its ", bytes.Length(), " bytes do not parse as ",
                                                 message->GetTypeName(),
                                                 " (truncated, or not this message)"));
}

absl::Status ParseMessage(const grpc::ByteBuffer& bytes, const std::string& what,
                          google::protobuf::Message* message) {
  absl::Status s = ParseInto(bytes, message);
  if (s.ok()) return s;
  return absl::InvalidArgumentError(absl::StrCat(what, ": ", s.message()));
}

absl::Status SerializeMessage(const google::protobuf::Message& message, grpc::ByteBuffer* bytes) {
  bytes->Clear();  // The writer fills an empty buffer (a write's is reused).
  bool own_buffer = false;
  const grpc::Status s = grpc::GenericSerialize<grpc::ProtoBufferWriter, google::protobuf::Message>(
      message, bytes, &own_buffer);
  if (s.ok()) return absl::OkStatus();
  return absl::InternalError(
      absl::StrCat("cannot serialize the ", message.GetTypeName(), ": ", s.error_message()));
}

}  // namespace stylus::server
