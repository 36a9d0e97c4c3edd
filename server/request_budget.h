// What reading a request may cost, checked on its bytes before they are
// parsed: a protobuf parse turns a 2-byte empty entry into an object of tens
// of bytes, so a request of many empty or tiny entries would make the
// server allocate many times its size on the wire. A scan of the wire
// format (no allocation per entry) counts each repeated field's entries per
// message, measures each string, and adds up what the parse would allocate.
//
// Thread-safety: a RequestBudget is immutable once built; Check may be
// called from any thread.
#ifndef STYLUS_SERVER_REQUEST_BUDGET_H_
#define STYLUS_SERVER_REQUEST_BUDGET_H_

#include <google/protobuf/descriptor.h>
#include <grpcpp/support/byte_buffer.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"

namespace stylus::server {

// A cap on the entries of one repeated field per message that holds it.
struct EntryLimit {
  std::string field;  // Full name, e.g. "stylus.v1.Clip.frames".
  int64_t max = 0;
  std::string flag;  // The server flag that sets it, for the error.
};

class RequestBudget {
 public:
  // What parsing may allocate: at most `ratio` times the request's wire
  // size, plus `slack` bytes (small requests' fixed costs). Strings over
  // `max_string` bytes are refused. A limit naming no field is a programming
  // error (the server does not start; see Create).
  struct Options {
    double ratio = 4;
    int64_t slack = 256 * 1024;
    int64_t max_string = 1024;
    std::vector<EntryLimit> entries;
  };
  // INVALID_ARGUMENT when a limit names no field of the generated messages.
  static absl::Status Validate(const Options& options);
  explicit RequestBudget(Options options);

  // OK when `bytes`, parsed as a `type`, stay within the budget.
  // RESOURCE_EXHAUSTED naming the field path ("content.frames"), its count
  // and the flag for a repeated field over its limit; INVALID_ARGUMENT for a
  // string over max_string, for bytes that would take more than the ratio
  // allows, or for bytes that are not a `type`. `what` starts each message.
  // `parse_bytes`, when not null, receives the estimate of what the parse
  // allocates.
  absl::Status Check(const grpc::ByteBuffer& bytes, const google::protobuf::Descriptor* type,
                     const std::string& what, int64_t* parse_bytes = nullptr) const;

  // The bytes a parse of `bytes` as a `type` is estimated to allocate (-1 when
  // they do not parse): for tests and the hostile-client suite.
  int64_t EstimateParse(const grpc::ByteBuffer& bytes,
                        const google::protobuf::Descriptor* type) const;

  const Options& options() const { return options_; }

 private:
  struct Limit {
    int64_t max;
    std::string flag;
  };
  const Options options_;
  absl::flat_hash_map<const google::protobuf::FieldDescriptor*, Limit> limits_;
  absl::flat_hash_map<const google::protobuf::FieldDescriptor*, int64_t> maxima_;
};

// The memory that calls in progress may hold, shared by them: each reserves
// its estimate before it runs and returns it when done (MemoryHold).
class MemoryPool {
 public:
  explicit MemoryPool(int64_t bytes) : capacity_(bytes) {}
  int64_t capacity() const { return capacity_; }
  int64_t in_use() const { return in_use_.load(); }

 private:
  friend class MemoryHold;
  const int64_t capacity_;
  std::atomic<int64_t> in_use_{0};
};

// Bytes of a MemoryPool held for one call, returned when it goes.
class MemoryHold {
 public:
  MemoryHold() = default;
  // Takes `bytes` of `pool` when they fit (ok()); a null pool always fits.
  MemoryHold(MemoryPool* pool, int64_t bytes);
  MemoryHold(MemoryHold&& other) noexcept { *this = std::move(other); }
  MemoryHold& operator=(MemoryHold&& other) noexcept;
  ~MemoryHold();
  bool ok() const { return ok_; }

 private:
  MemoryPool* pool_ = nullptr;
  int64_t bytes_ = 0;
  bool ok_ = true;
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_REQUEST_BUDGET_H_
