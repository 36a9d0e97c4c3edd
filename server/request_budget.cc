#include "server/request_budget.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/message.h>
#include <google/protobuf/wire_format_lite.h>
#include <grpcpp/support/proto_buffer_reader.h>

#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace stylus::server {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::internal::WireFormatLite;
using google::protobuf::io::CodedInputStream;

// Requests are parsed on an arena (server/unary_call.h): a message costs
// its object's size, with no allocation header. What a heap allocation costs
// beyond its bytes (glibc's chunk header, rounded), for a string's buffer:
constexpr int64_t kAllocation = 16;
// A pointer slot in a repeated field, with what its doubling growth leaves
// behind on an arena (the arrays it outgrew stay until the arena goes).
constexpr int64_t kSlot = 24;
constexpr int kMaxDepth = 32;

int64_t ObjectBytes(const Descriptor* type) {
  const google::protobuf::Message* prototype =
      google::protobuf::MessageFactory::generated_factory()->GetPrototype(type);
  return prototype != nullptr ? static_cast<int64_t>(prototype->SpaceUsedLong()) : 64;
}

// A std::string holding `size` bytes (its buffer on the heap past 15).
int64_t StringBytes(int64_t size) {
  return static_cast<int64_t>(sizeof(std::string)) + (size > 15 ? size + kAllocation : 0);
}

int ScalarBytes(FieldDescriptor::CppType type) {
  switch (type) {
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT64:
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return 8;
    case FieldDescriptor::CPPTYPE_BOOL:
      return 1;
    default:
      return 4;
  }
}

class Scan {
 public:
  Scan(const RequestBudget::Options& options,
       const absl::flat_hash_map<const FieldDescriptor*, int64_t>* maxima, bool enforce)
      : options_(options), maxima_(maxima), enforce_(enforce) {}

  // False when the bytes are not a message or break a limit (status_ says
  // which; an unparsable message leaves it OK and sets malformed_).
  bool Message(CodedInputStream* in, const Descriptor* type, int depth) {
    if (depth > kMaxDepth) return Malformed();
    cost_ += ObjectBytes(type);
    std::vector<int64_t> counts(type->field_count(), 0);
    for (;;) {
      const uint32_t tag = in->ReadTag();
      if (tag == 0) return true;  // The message's end (or its limit's).
      const int number = WireFormatLite::GetTagFieldNumber(tag);
      const WireFormatLite::WireType wire = WireFormatLite::GetTagWireType(tag);
      const FieldDescriptor* field = type->FindFieldByNumber(number);
      if (field == nullptr) {
        // Kept as an unknown field: about its wire size.
        const int before = in->CurrentPosition();
        if (!WireFormatLite::SkipField(in, tag)) return Malformed();
        cost_ += in->CurrentPosition() - before + kAllocation;
        continue;
      }
      if (!Field(in, field, wire, &counts[field->index()], depth)) return false;
    }
  }

  int64_t cost() const { return cost_; }
  bool malformed() const { return malformed_; }
  const absl::Status& status() const { return status_; }

 private:
  bool Malformed() {
    malformed_ = true;
    return false;
  }

  bool Field(CodedInputStream* in, const FieldDescriptor* field, WireFormatLite::WireType wire,
             int64_t* count, int depth) {
    path_.push_back(field);
    const bool ok = FieldBody(in, field, wire, count, depth);
    if (ok) path_.pop_back();
    return ok;
  }

  bool FieldBody(CodedInputStream* in, const FieldDescriptor* field, WireFormatLite::WireType wire,
                 int64_t* count, int depth) {
    const bool repeated = field->is_repeated();
    if (wire != WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
      if (!WireFormatLite::SkipField(in, WireFormatLite::MakeTag(field->number(), wire)))
        return Malformed();
      if (repeated) {
        cost_ += 2 * ScalarBytes(field->cpp_type());
        return Count(field, count, 1);
      }
      return true;
    }
    uint32_t length = 0;
    if (!in->ReadVarint32(&length) || static_cast<int>(length) < 0) return Malformed();
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (repeated) {
        cost_ += kSlot + (field->is_map() ? 3 * kAllocation : 0);
        if (!Count(field, count, 1)) return false;
      }
      const CodedInputStream::Limit limit = in->PushLimit(static_cast<int>(length));
      if (!Message(in, field->message_type(), depth + 1)) return false;
      if (in->BytesUntilLimit() != 0) return Malformed();
      in->PopLimit(limit);
      return true;
    }
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_STRING) {
      if (enforce_ && length > options_.max_string) {
        status_ = absl::InvalidArgumentError(
            absl::StrCat(Path(), ": ", length, " bytes, over the limit of ", options_.max_string,
                         " for a name or string"));
        return false;
      }
      cost_ += StringBytes(length) + (repeated ? kSlot : 0);
      if (!in->Skip(static_cast<int>(length))) return Malformed();
      return !repeated || Count(field, count, 1);
    }
    // Packed repeated scalars: fixed-width ones take their wire size; a
    // varint takes at least one byte on the wire for 4 or 8 in memory.
    if (!repeated) return Malformed();
    const int width = ScalarBytes(field->cpp_type());
    const bool fixed = field->type() == FieldDescriptor::TYPE_DOUBLE ||
                       field->type() == FieldDescriptor::TYPE_FLOAT ||
                       field->type() == FieldDescriptor::TYPE_FIXED32 ||
                       field->type() == FieldDescriptor::TYPE_FIXED64 ||
                       field->type() == FieldDescriptor::TYPE_SFIXED32 ||
                       field->type() == FieldDescriptor::TYPE_SFIXED64;
    const int64_t entries = fixed ? length / width : length;
    cost_ += fixed ? length : static_cast<int64_t>(length) * width;
    if (!in->Skip(static_cast<int>(length))) return Malformed();
    return Count(field, count, entries);
  }

  bool Count(const FieldDescriptor* field, int64_t* count, int64_t more) {
    *count += more;
    if (!enforce_ || maxima_ == nullptr) return true;
    const auto it = maxima_->find(field);
    if (it == maxima_->end() || *count <= it->second) return true;
    over_ = field;
    over_count_ = *count;
    return false;
  }

 public:
  // The path of the field being read: "content.frames".
  std::string Path() const {
    std::vector<std::string> names;
    for (const FieldDescriptor* f : path_) names.push_back(f->name());
    return absl::StrJoin(names, ".");
  }
  const FieldDescriptor* over() const { return over_; }

 private:
  const RequestBudget::Options& options_;
  const absl::flat_hash_map<const FieldDescriptor*, int64_t>* maxima_;
  const bool enforce_;
  int64_t cost_ = 0;
  bool malformed_ = false;
  absl::Status status_;
  std::vector<const FieldDescriptor*> path_;
  const FieldDescriptor* over_ = nullptr;
  int64_t over_count_ = 0;

 public:
  int64_t over_count() const { return over_count_; }
};

}  // namespace

absl::Status RequestBudget::Validate(const Options& options) {
  for (const EntryLimit& e : options.entries) {
    const FieldDescriptor* f =
        google::protobuf::DescriptorPool::generated_pool()->FindFieldByName(e.field);
    if (f == nullptr || !f->is_repeated()) {
      return absl::InvalidArgumentError(
          absl::StrCat("request budget: no repeated field ", e.field));
    }
  }
  return absl::OkStatus();
}

RequestBudget::RequestBudget(Options options) : options_(std::move(options)) {
  for (const EntryLimit& e : options_.entries) {
    const FieldDescriptor* f =
        google::protobuf::DescriptorPool::generated_pool()->FindFieldByName(e.field);
    if (f == nullptr) continue;
    limits_[f] = {e.max, e.flag};
    maxima_[f] = e.max;
  }
}

absl::Status RequestBudget::Check(const grpc::ByteBuffer& bytes, const Descriptor* type,
                                  const std::string& what, int64_t* parse_bytes) const {
  grpc::ByteBuffer copy(bytes);  // The reader consumes its buffer; the copy shares the slices.
  grpc::ProtoBufferReader reader(&copy);
  CodedInputStream in(&reader);
  Scan scan(options_, &maxima_, /*enforce=*/true);
  const bool ok = scan.Message(&in, type, 0);
  if (!ok) {
    if (!scan.status().ok()) {
      return absl::Status(scan.status().code(), absl::StrCat(what, ": ", scan.status().message()));
    }
    if (scan.over() != nullptr) {
      const Limit& limit = limits_.at(scan.over());
      return absl::ResourceExhaustedError(
          absl::StrCat(what, ": ", scan.Path(), ": more than ", limit.max,
                       " entries, over this server's limit (", limit.flag, ")",
                       limit.flag == "--max-clip-frames" ? "; split the clip or stream it" : ""));
    }
    return absl::InvalidArgumentError(absl::StrCat(what, ": its ", bytes.Length(),
                                                   " bytes do not parse as ", type->full_name(),
                                                   " (truncated, or not this message)"));
  }
  const int64_t wire = static_cast<int64_t>(bytes.Length());
  if (parse_bytes != nullptr) *parse_bytes = scan.cost();
  const double allowed = options_.ratio * static_cast<double>(wire) + options_.slack;
  if (static_cast<double>(scan.cost()) > allowed) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": its ", wire, " bytes would take about ", scan.cost(), " bytes to read, over ",
        options_.ratio,
        "x their size: mostly empty or default entries (send values, not empty messages)"));
  }
  return absl::OkStatus();
}

int64_t RequestBudget::EstimateParse(const grpc::ByteBuffer& bytes, const Descriptor* type) const {
  grpc::ByteBuffer copy(bytes);
  grpc::ProtoBufferReader reader(&copy);
  CodedInputStream in(&reader);
  Scan scan(options_, nullptr, /*enforce=*/false);
  if (!scan.Message(&in, type, 0)) return -1;
  return scan.cost();
}

MemoryHold::MemoryHold(MemoryPool* pool, int64_t bytes) {
  if (pool == nullptr) return;
  int64_t used = pool->in_use_.load();
  do {
    if (used + bytes > pool->capacity_) {
      ok_ = false;
      return;
    }
  } while (!pool->in_use_.compare_exchange_weak(used, used + bytes));
  pool_ = pool;
  bytes_ = bytes;
}

MemoryHold& MemoryHold::operator=(MemoryHold&& other) noexcept {
  if (this == &other) return *this;
  if (pool_ != nullptr) pool_->in_use_.fetch_sub(bytes_);
  pool_ = other.pool_;
  bytes_ = other.bytes_;
  ok_ = other.ok_;
  other.pool_ = nullptr;
  other.bytes_ = 0;
  return *this;
}

MemoryHold::~MemoryHold() {
  if (pool_ != nullptr) pool_->in_use_.fetch_sub(bytes_);
}

}  // namespace stylus::server
