// Requests arrive as bytes and are parsed here, not by gRPC's generated
// handlers: those answer a request whose bytes do not parse with
// UNIMPLEMENTED (which tells a client the method does not exist) and end a
// stream as if the client had half-closed. Parsed here, such bytes end the
// call INVALID_ARGUMENT, naming the message expected.
#ifndef STYLUS_SERVER_RAW_MESSAGE_H_
#define STYLUS_SERVER_RAW_MESSAGE_H_

#include <google/protobuf/arena.h>
#include <google/protobuf/message.h>
#include <grpcpp/support/byte_buffer.h>

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

namespace stylus::server {

// Parses `bytes` into `message` (cleared first). INVALID_ARGUMENT naming
// `what` and the message type when the bytes are not a serialized message of
// that type.
absl::Status ParseMessage(const grpc::ByteBuffer& bytes, const std::string& what,
                          google::protobuf::Message* message);

// Parses `bytes` into `message` (cleared first); INVALID_ARGUMENT saying why
// it does not parse, without naming the request.
absl::Status ParseInto(const grpc::ByteBuffer& bytes, google::protobuf::Message* message);

// A stream's requests, parsed one at a time into a message on an arena that
// is reset before each parse: the message and its many small parts (a frame's
// joints) take no heap allocation per request once the arena's first block
// holds one request.
//
// Thread-safety: one parse at a time; the message lives until the next one.
template <typename Message>
class StreamRequests {
 public:
  StreamRequests() : arena_(Options(block_, sizeof(block_))) {}
  // The request in `bytes`, or INVALID_ARGUMENT as ParseMessage says, naming
  // the request "`what` `index`" (a name built only on an error). `check`,
  // when given, vets the bytes first (the request budget) and is told the
  // same name.
  absl::StatusOr<const Message*> Parse(
      const grpc::ByteBuffer& bytes, int64_t index, const char* what,
      const std::function<absl::Status(const grpc::ByteBuffer&, const std::string&)>& check =
          nullptr) {
    if (check) {
      absl::Status s = check(bytes, absl::StrCat(what, " ", index));
      if (!s.ok()) return s;
    }
    arena_.Reset();
    Message* m = google::protobuf::Arena::CreateMessage<Message>(&arena_);
    absl::Status s = ParseInto(bytes, m);
    if (!s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(what, " ", index, ": ", s.message()));
    }
    return m;
  }

 private:
  static google::protobuf::ArenaOptions Options(char* block, size_t size) {
    google::protobuf::ArenaOptions o;
    o.initial_block = block;
    o.initial_block_size = size;
    return o;
  }
  alignas(8) char block_[16384];
  google::protobuf::Arena arena_;
};

// Serializes `message` into `bytes`. INTERNAL only if protobuf refuses (a
// message over 2 GB).
absl::Status SerializeMessage(const google::protobuf::Message& message, grpc::ByteBuffer* bytes);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_RAW_MESSAGE_H_
