#include "bridge/bvh_broadcast.h"

#include <cmath>
#include <cstring>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"

namespace stylus::bridge {
namespace {

constexpr size_t kHeaderBytes = 64;
constexpr uint16_t kStartToken = 0xDDFF;
constexpr uint16_t kEndToken = 0xEEFF;
constexpr size_t kMaxAvatarName = 64;

uint16_t U16(const char* p) {
  return static_cast<uint16_t>(static_cast<unsigned char>(p[0]) |
                               (static_cast<unsigned char>(p[1]) << 8));
}
uint32_t U32(const char* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}
void PutU16(char* p, uint16_t v) {
  p[0] = static_cast<char>(v & 0xff);
  p[1] = static_cast<char>(v >> 8);
}
void PutU32(char* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

// "<index> <name> <values...>" (without the "||"); false when it is not one.
bool ParseTextFrame(absl::string_view text, BroadcastFrame* out) {
  std::vector<absl::string_view> tokens =
      absl::StrSplit(text, absl::ByAnyChar(" \t\r\n"), absl::SkipEmpty());
  if (tokens.size() < 3 || !absl::SimpleAtoi(tokens[0], &out->avatar_index) ||
      out->avatar_index < 0) {
    return false;
  }
  if (tokens[1].size() > kMaxAvatarName) return false;  // The binary form holds 31.
  out->avatar_name = std::string(tokens[1]);
  out->values.resize(tokens.size() - 2);
  for (size_t i = 2; i < tokens.size(); ++i) {
    double v;
    if (!absl::SimpleAtod(tokens[i], &v) || !std::isfinite(v)) return false;
    out->values[i - 2] = v;
  }
  return true;
}

}  // namespace

std::vector<BroadcastFrame> BroadcastTextReader::Feed(absl::string_view bytes) {
  std::vector<BroadcastFrame> frames;
  pending_.append(bytes.data(), bytes.size());
  size_t start = 0;
  for (size_t end; (end = pending_.find("||", start)) != std::string::npos; start = end + 2) {
    BroadcastFrame frame;
    const absl::string_view text(pending_.data() + start, end - start);
    if (absl::StripAsciiWhitespace(text).empty()) continue;
    if (ParseTextFrame(text, &frame)) {
      frames.push_back(std::move(frame));
    } else {
      ++malformed_;
    }
  }
  pending_.erase(0, start);
  if (pending_.size() > kMaxFrameBytes) {  // No "||" in sight: drop it.
    ++malformed_;
    pending_.clear();
  }
  return frames;
}

std::string FormatBroadcastText(const BroadcastFrame& frame) {
  std::string out = absl::StrCat(frame.avatar_index, " ", frame.avatar_name);
  for (double v : frame.values) absl::StrAppendFormat(&out, " %.6f", v);
  out += " ||\n";
  return out;
}

absl::StatusOr<BroadcastFrame> ParseBroadcastBinary(absl::string_view d) {
  if (d.size() < kHeaderBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("a ", d.size(), "-byte datagram: a BVH broadcast frame has a 64-byte header"));
  }
  if (U16(d.data()) != kStartToken || U16(d.data() + 62) != kEndToken) {
    return absl::InvalidArgumentError("not a BVH broadcast frame (no 0xDDFF ... 0xEEFF header)");
  }
  const size_t count = U16(d.data() + 6);
  const bool with_reference = d[9] != 0;
  if (d.size() != kHeaderBytes + 4 * count) {
    return absl::InvalidArgumentError(
        absl::StrCat("the header says ", count, " values (", kHeaderBytes + 4 * count,
                     " bytes) but the datagram has ", d.size(), " bytes"));
  }
  BroadcastFrame f;
  f.avatar_index = static_cast<int>(U32(d.data() + 10) & 0x7fffffff);
  const char* name = d.data() + 14;
  f.avatar_name.assign(name, strnlen(name, 32));
  f.frame_index = U32(d.data() + 46);
  // A reference bone's six values come first when the header says so.
  const size_t skip = with_reference ? 6 : 0;
  if (count < skip)
    return absl::InvalidArgumentError("a frame with a reference bone but fewer than 6 values");
  f.values.resize(count - skip);
  for (size_t i = skip; i < count; ++i) {
    float v;
    const uint32_t bits = U32(d.data() + kHeaderBytes + 4 * i);
    std::memcpy(&v, &bits, 4);
    if (!std::isfinite(v)) {
      return absl::InvalidArgumentError(
          absl::StrCat("value ", i, " of the frame is not a finite number"));
    }
    f.values[i - skip] = v;
  }
  return f;
}

std::string FormatBroadcastBinary(const BroadcastFrame& frame, bool with_displacement) {
  std::string out(kHeaderBytes + 4 * frame.values.size(), '\0');
  char* h = out.data();
  PutU16(h, kStartToken);
  h[2] = 1;  // Data version 1.0.0.0 (build, revision, minor, major).
  h[5] = 1;
  PutU16(h + 6, static_cast<uint16_t>(frame.values.size()));
  h[8] = with_displacement ? 1 : 0;
  h[9] = 0;  // No reference bone.
  PutU32(h + 10, static_cast<uint32_t>(frame.avatar_index));
  std::memcpy(h + 14, frame.avatar_name.data(), std::min<size_t>(31, frame.avatar_name.size()));
  PutU32(h + 46, static_cast<uint32_t>(std::max<int64_t>(0, frame.frame_index)));
  PutU16(h + 62, kEndToken);
  for (size_t i = 0; i < frame.values.size(); ++i) {
    const float v = static_cast<float>(frame.values[i]);
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    PutU32(h + kHeaderBytes + 4 * i, bits);
  }
  return out;
}

absl::StatusOr<std::vector<double>> BroadcastRow(const motion::Skeleton& sk,
                                                 const std::vector<double>& values) {
  const size_t channels = static_cast<size_t>(sk.num_channels());
  if (values.size() == channels) return values;
  const size_t with_displacement = 6 * static_cast<size_t>(sk.num_joints());
  if (values.size() != with_displacement) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "a frame of %d values, but the skeleton file has %d channels (%d joints; with displacement "
        "the stream sends %d): export the skeleton from the capture software with the broadcast's "
        "settings, or check it is this performer's",
        values.size(), channels, sk.num_joints(), with_displacement));
  }
  std::vector<double> row(channels);
  for (int j = 0; j < sk.num_joints(); ++j) {
    const std::vector<motion::Channel>& cs = sk.joint(j).channels;
    int rotation = 0;
    for (size_t c = 0; c < cs.size(); ++c) {
      const size_t from = 6 * static_cast<size_t>(j) +
                          (motion::IsPosition(cs[c]) ? motion::ChannelAxis(cs[c]) : 3 + rotation++);
      row[sk.channel_start(j) + c] = values[from];
    }
  }
  return row;
}

}  // namespace stylus::bridge
