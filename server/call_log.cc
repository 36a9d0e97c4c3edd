#include "server/call_log.h"

#include <grpc/support/log.h>

#include <atomic>
#include <random>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spdlog/pattern_formatter.h"
#include "spdlog/sinks/stdout_color_sinks.h"
#include "spdlog/spdlog.h"

namespace stylus::server {
namespace {

std::atomic<bool> json_logs{false};

// A call's line in JSON starts with this byte: its message is already the
// object's fields (the formatter below writes them as they are).
constexpr char kFieldsMark = '\x1e';

// %* in the JSON pattern: the message as "msg":"...", or a call's fields.
class JsonMessageFlag : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    const std::string text(msg.payload.data(), msg.payload.size());
    const std::string out = !text.empty() && text[0] == kFieldsMark
                                ? text.substr(1)
                                : absl::StrCat("\"msg\":\"", JsonEscape(text), "\"");
    dest.append(out.data(), out.data() + out.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<JsonMessageFlag>();
  }
};

bool UsableRequestId(const std::string& id) {
  if (id.empty() || id.size() > 128) return false;
  for (char c : id) {
    if (c <= ' ' || c > '~') return false;
  }
  return true;
}

std::string MakeRequestId() {
  // Random per process, then counted: unique within a run, unlikely to meet
  // another server's.
  static const uint64_t base = [] {
    std::random_device rd;
    return (static_cast<uint64_t>(rd()) << 32) ^ rd();
  }();
  static std::atomic<uint64_t> next{0};
  return absl::StrFormat("%016x", base + next.fetch_add(1));
}

// gRPC's own messages (handshake failures, transport errors) go through the
// same logger, so a JSON log stays JSON.
void ForwardGrpcLog(gpr_log_func_args* args) {
  const spdlog::level::level_enum level =
      args->severity == GPR_LOG_SEVERITY_ERROR  ? spdlog::level::warn
      : args->severity == GPR_LOG_SEVERITY_INFO ? spdlog::level::info
                                                : spdlog::level::debug;
  spdlog::log(level, "grpc: {} ({}:{})", args->message, args->file, args->line);
}

}  // namespace

absl::StatusOr<LogFormat> ParseLogFormat(const std::string& name) {
  if (name == "text") return LogFormat::kText;
  if (name == "json") return LogFormat::kJson;
  return absl::InvalidArgumentError(absl::StrCat("unknown log format '", name, "' (text or json)"));
}

void SetUpLogging(LogFormat format, std::shared_ptr<spdlog::sinks::sink> sink) {
  if (sink == nullptr) sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>("stylus-server", sink);
  json_logs = format == LogFormat::kJson;
  if (format == LogFormat::kJson) {
    auto formatter = std::make_unique<spdlog::pattern_formatter>(spdlog::pattern_time_type::utc,
                                                                 std::string("\n"));
    formatter->add_flag<JsonMessageFlag>('*').set_pattern(
        R"({"time":"%Y-%m-%dT%H:%M:%S.%fZ","level":"%l",%*})");
    logger->set_formatter(std::move(formatter));
  }
  spdlog::set_default_logger(std::move(logger));
  gpr_set_log_function(ForwardGrpcLog);
}

CallOrigin IdentifyCall(grpc::CallbackServerContext* ctx) {
  CallOrigin origin;
  const auto& metadata = ctx->client_metadata();
  const auto it = metadata.find("x-request-id");
  if (it != metadata.end()) origin.request_id.assign(it->second.data(), it->second.size());
  if (!UsableRequestId(origin.request_id)) origin.request_id = MakeRequestId();
  origin.peer = ctx->peer();
  ctx->AddInitialMetadata("x-request-id", origin.request_id);
  return origin;
}

void LogCall(const std::string& rpc, const CallOrigin& origin, const CallOutcome& outcome,
             double ms) {
  const std::string status =
      outcome.status.ok() ? "OK" : std::string(absl::StatusCodeToString(outcome.status.code()));
  // What a client sent may be in the model id and the message: capped, and
  // (in text) with its control characters escaped, so that it cannot forge
  // or flood a line.
  const std::string model = outcome.model.empty() ? "-" : Capped(outcome.model);
  const std::string message = Capped(std::string(outcome.status.message()));
  const std::string note = Capped(outcome.note);
  const auto level = outcome.status.ok() ? spdlog::level::info : spdlog::level::warn;
  if (json_logs) {
    std::string fields = absl::StrFormat(
        "%c\"rpc\":\"%s\",\"model\":\"%s\",\"frames\":%d,\"ms\":%.1f,\"status\":\"%s\"",
        kFieldsMark, JsonEscape(rpc), JsonEscape(model), outcome.frames, ms, status);
    if (!outcome.status.ok()) {
      absl::StrAppend(&fields, ",\"message\":\"", JsonEscape(message), "\"");
    }
    if (!note.empty()) absl::StrAppend(&fields, ",\"note\":\"", JsonEscape(note), "\"");
    absl::StrAppend(&fields, ",\"request_id\":\"", JsonEscape(origin.request_id), "\",\"peer\":\"",
                    JsonEscape(Capped(origin.peer)), "\"");
    spdlog::log(level, "{}", fields);
    return;
  }
  std::string line = absl::StrFormat("rpc=%s model=%s frames=%d ms=%.1f status=%s", rpc,
                                     TextEscape(model), outcome.frames, ms, status);
  if (!outcome.status.ok()) absl::StrAppend(&line, " message=\"", TextEscape(message), "\"");
  if (!note.empty()) absl::StrAppend(&line, " ", TextEscape(note));
  absl::StrAppend(&line, " request_id=", origin.request_id,
                  " peer=", TextEscape(Capped(origin.peer)));
  spdlog::log(level, "{}", line);
}

std::string Capped(const std::string& text) {
  if (text.size() <= kMaxLoggedField) return text;
  return absl::StrCat(text.substr(0, kMaxLoggedField), "...(", text.size(), " bytes)");
}

std::string TextEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      out += absl::StrFormat("\\x%02x", u);
    } else if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else {
      out += c;
    }
  }
  return out;
}

namespace {

// The length of the valid UTF-8 sequence at `s[i]` (2-4 bytes), or 0.
size_t Utf8Sequence(const std::string& s, size_t i) {
  const auto byte = [&s](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  size_t n = 0;
  uint32_t cp = 0;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2, cp = c & 0x1F;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3, cp = c & 0x0F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4, cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  const bool overlong = (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000);
  if (overlong || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

}  // namespace

std::string JsonEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (static_cast<unsigned char>(c) >= 0x80) {
      // Valid UTF-8 stays; any other byte becomes U+FFFD, so a line always
      // parses.
      const size_t n = Utf8Sequence(text, i);
      if (n == 0) {
        out += "\\ufffd";
      } else {
        out.append(text, i, n);
        i += n - 1;
      }
      continue;
    }
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += absl::StrFormat("\\u%04x", static_cast<unsigned char>(c));
        } else {
          out += c;
        }
    }
  }
  return out;
}

}  // namespace stylus::server
